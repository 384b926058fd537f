#include "app/flight.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "app/cli.hpp"
#include "core/recording/replay.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/base/output_file.hpp"
#include "core/history/history.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "input/mapping.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"

namespace mixpilot::cli {

namespace {

// "3 stale, 1 bad value" (the non-zero counts).
std::string rejection_counts(const net::JoyPeerStats& s) {
  std::string out;
  const auto add = [&](std::uint64_t n, const char* what) {
    if (n > 0) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(s.bad_value, "bad value");
  add(s.bad_size, "bad size");
  add(s.stale, "stale");
  add(s.other_publisher, "of another publisher");
  return out;
}

// Reads the scenario and, for a replay, the recording; on failure `status` may name a more
// specific exit status than kExitError.
std::optional<Flight> load_flight(const FlyOptions& o, std::string& error, int& status) {
  Flight f;
  if (o.from) {
    // Fly from here: the recorded flight's own scenario, whatever its file says now.
    f.scenario_text = o.from->scenario_text;
    f.scenario_source = o.from->scenario_source;
    f.scenario_file = o.from->scenario_file;
    f.from = o.from;
    return f;
  }
  if (o.replay || o.pilot.ends_with(".mcap")) {
    f.recording = read_recording(o.pilot, error);
    if (!f.recording) return std::nullopt;
    if (!embedded_scenario(*f.recording, o.pilot, error)) return std::nullopt;
  }
  if (!o.scenario_path.empty()) {
    if (!o.scenario_text.empty()) f.scenario_text = o.scenario_text;
    else if (!read_text_file(o.scenario_path, f.scenario_text, error)) return std::nullopt;
    f.scenario_source = o.scenario_path;
    f.scenario_file = std::filesystem::absolute(o.scenario_path).lexically_normal().string();
    if (f.recording && *embedded_scenario(*f.recording, o.pilot, error) != f.scenario_text &&
        !o.allow_mismatch) {
      error = o.scenario_path + " differs from the scenario embedded in " + o.pilot +
              " (--allow-mismatch flies it anyway)";
      status = kExitReplayMismatch;
      return std::nullopt;
    }
  } else if (f.recording) {
    f.scenario_text = *embedded_scenario(*f.recording, o.pilot, error);
    f.scenario_source = embedded_scenario_source(*f.recording, o.pilot);
    f.scenario_file = f.recording->metadata["scenario_path"];
  } else {
    error = usage_message(o.command, "--scenario FILE is required");
    status = kExitUsage;
    return std::nullopt;
  }
  return f;
}

// The person's device of --pilot gamepad | keyboard and the pilot that reads it.
std::shared_ptr<Devices> open_devices(const FlyOptions& o, const std::string& scenario_text,
                                      const std::string& scenario_source,
                                      std::shared_ptr<input::Gamepad> gamepad,
                                      ModeRequest& request, std::string& error) {
  auto d = std::make_shared<Devices>();
  if (o.input_values) {
    d->settings = *o.input_values;
  } else {
    const auto s = command_input_settings(o.command, o.input_settings, error);
    if (!s) return nullptr;
    d->settings = *s;
  }
  const std::optional<Scenario> sc = parse_scenario(scenario_text, scenario_source, error);
  if (!sc) return nullptr;
  input::StickSource* source = nullptr;
  if (o.pilot == "keyboard") {
    d->keyboard = std::make_unique<input::KeyboardSource>(d->settings);
    source = d->keyboard.get();
  } else if (o.pilot.starts_with("dds")) {
    net::use_loopback_unless_configured();
    net::JoyPeer::Options po;
    po.domain = o.domain;
    po.topic = net::dds_topic(o.pilot.size() > 4 ? o.pilot.substr(4) : "joy");
    d->peer = std::make_unique<net::JoyPeer>();
    if (!d->peer->start(po, error)) return nullptr;
    if (o.headless) {
      // A headless flight starts with the peer's first sane sample (or gives up).
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!d->peer->heard() && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (!d->peer->heard()) {
        const net::JoyPeerStats s = d->peer->stats();
        if (s.rejected() > 0) {
          // Samples arrived: the publisher is there, its samples are not fit to fly.
          error = std::to_string(s.rejected()) + " sensor_msgs/msg/Joy samples arrived on " +
                  po.topic + " in DDS domain " + std::to_string(po.domain) +
                  " within 10 s and none was taken (" + rejection_counts(s) + "; the newest as " +
                  s.last_rejection + ")";
        } else {
          error = "no sensor_msgs/msg/Joy on " + po.topic + " in DDS domain " +
                  std::to_string(po.domain) + " within 10 s: start the publisher (e.g. mixpilot "
                  "joy-publish --from REC.mcap --domain " + std::to_string(po.domain) + ")";
        }
        return nullptr;
      }
    }
    source = d->peer.get();
  } else {
    if (!o.gamepad_script.empty()) {
      auto rows = input::load_script(o.gamepad_script, error);
      if (!rows) return nullptr;
      d->script = std::move(*rows);
      d->virtual_pad = std::make_unique<input::VirtualGamepad>();
      if (!d->virtual_pad->plug(error)) return nullptr;
    }
    if (gamepad) {
      d->gamepad = std::move(gamepad);
    } else {
      d->gamepad = std::make_shared<input::Gamepad>();
      input::Gamepad::Options go;
      go.preferred = d->settings.gamepad;
      go.mappings_file = input::user_mappings_path();
      if (!d->gamepad->start(go, error)) return nullptr;
      if (!d->gamepad->mappings_note().empty())
        std::fprintf(stderr, "mixpilot: %s\n", d->gamepad->mappings_note().c_str());
    }
    if (o.headless) {
      // SDL reports the pads present at start-up within its first polls.
      const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1500);
      while (!d->gamepad->connected() && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (!d->gamepad->connected()) {
        std::string seen;
        for (const input::GamepadInfo& g : d->gamepad->devices())
          seen += (seen.empty() ? "" : ", ") + g.name + (g.controller ? "" : " (no mapping)");
        error = "no gamepad connected" +
                (seen.empty() ? std::string() : " (SDL sees " + seen + ")") +
                ": connect one, or fly with --pilot keyboard in the window, or play a script "
                "with --gamepad-script FILE.csv";
        return nullptr;
      }
    }
    source = d->gamepad.get();
  }
  auto pilot = std::make_unique<input::DevicePilot>(*source, d->settings, sc->controller.dt,
                                                    models::MikroKopter().hover_speed());
  d->pilot = pilot.get();
  request.pilot_source = std::move(pilot);
  return d;
}

}  // namespace

bool is_device_pilot(const std::string& pilot) {
  return pilot == "gamepad" || pilot == "keyboard" || pilot == "dds" || pilot.starts_with("dds:");
}

input::InputSettings load_input_settings(const std::string& path, std::string& note) {
  std::string why;
  const std::string file = path.empty() ? input::default_settings_path(&why) : path;
  if (file.empty()) {
    note = "no folder for the user's input settings (" + why +
           "): the default input settings are used";
    return {};
  }
  bool exists = false;
  std::string error;
  if (const auto s = input::load_settings(file, exists, error)) return *s;
  note = error + "\n(the default input settings are used until the file is fixed)";
  return {};
}

void Devices::started() {
  if (virtual_pad && !script.empty()) virtual_pad->play(script, input::steady_ns());
}

void Devices::cue(double lambda) const {
  if (gamepad) gamepad->set_rumble(input::rumble_intensity(lambda, settings.haptic));
}

namespace {

// --vehicle dds: the link to `mixpilot vehicle`, listening (attach_vehicle() waits for it).
bool open_vehicle_link(const FlyOptions& o, Flight& f, std::string& error) {
  net::RemoteVehicle::Options vo;
  vo.domain = o.domain;
  const VehicleStateSpec spec = f.mode->remote_state();
  if (spec.nx == 0) {
    error = std::string("--vehicle dds: mode ") + to_string(f.mode->kind()) +
            " has no remote vehicle (crazyflie_tracking and mixed_initiative have)";
    return false;
  }
  vo.nx = spec.nx;
  vo.max_abs = net::RemoteVehicle::any_state();
  std::copy(spec.max_abs.begin(), spec.max_abs.begin() + spec.nx, vo.max_abs.begin());
  net::use_loopback_unless_configured();
  f.vehicle = std::make_unique<net::RemoteVehicle>();
  if (!f.vehicle->start(vo, error)) {
    error = "--vehicle dds: " + error;
    return false;
  }
  std::printf("mixpilot %s: waiting up to %.0f s for the vehicle in DDS domain %u (mixpilot "
              "vehicle --scenario ...)\n", o.command, o.vehicle_wait_s, unsigned(o.domain));
  std::fflush(stdout);
  return true;
}

}  // namespace

std::string vehicle_not_heard(const FlyOptions& o, const Flight& f) {
  const net::RemoteVehicleStats s = f.vehicle->stats();
  if (s.rejected() > 0)
    return "--vehicle dds: " + std::to_string(s.rejected()) +
           " states arrived on rt/mixpilot/vehicle/state in DDS domain " +
           std::to_string(o.domain) + " within " + seconds_text(o.vehicle_wait_s) +
           " s and none was taken (the newest as " + s.last_rejection + ")";
  return "--vehicle dds: no vehicle heard on rt/mixpilot/vehicle/state in DDS domain " +
         std::to_string(o.domain) + " within " + seconds_text(o.vehicle_wait_s) +
         " s (start `mixpilot vehicle --scenario ...` first)";
}

bool attach_vehicle(Flight& f, std::string& error) {
  if (!f.mode->set_vehicle(f.vehicle.get())) {
    error = "--vehicle dds: this mode cannot fly a remote vehicle";
    return false;
  }
  return true;
}

std::optional<Flight> prepare_flight(const FlyOptions& o, std::string& error, int& status,
                                     std::shared_ptr<input::Gamepad> gamepad, VehicleWait wait) {
  status = kExitError;  // unless said otherwise below
  std::optional<Flight> f = load_flight(o, error, status);
  if (!f) return std::nullopt;
  const auto kind_name = scenario_mode(f->scenario_text, f->scenario_source, error);
  if (!kind_name) {
    if (f->recording && o.scenario_path.empty()) error = in_embedded_scenario(o.pilot, error);
    return std::nullopt;
  }
  if (*kind_name != "mixed_initiative" && !o.pilot.empty() && !o.replay) {
    error = usage_message(o.command, "--pilot is for mixed_initiative scenarios, " +
                                         f->scenario_source + " is " + *kind_name);
    status = kExitUsage;
    return std::nullopt;
  }
  if (o.assist && *o.assist == Assistance::off && *kind_name != "mixed_initiative") {
    error = usage_message(o.command, "--assist is for mixed_initiative scenarios (a pilot shares "
                                     "the authority there), " + f->scenario_source + " is " +
                                         *kind_name);
    status = kExitUsage;
    return std::nullopt;
  }
  if (f->recording && o.assist) {
    const std::optional<Assistance> recorded = recorded_assistance(*f->recording, o.pilot, error);
    if (!recorded) return std::nullopt;
    if (*recorded != *o.assist) {
      error = usage_message(
          o.command, o.pilot + " was flown with assistance " +
                         (*recorded == Assistance::on ? "on" : "off") +
                         ": its replay flies it so (leave out --assist " +
                         (*o.assist == Assistance::on ? "on" : "off") + ")");
      status = kExitUsage;
      return std::nullopt;
    }
  }
  if (f->recording) {
    f->mode = replay_mode(*f->recording, o.pilot, f->scenario_text, f->scenario_source,
                          o.duration, error);
  } else {
    ModeRequest request;
    request.duration = o.duration;
    request.assist = o.assist.value_or(Assistance::on);
    request.bounds = o.bounds;
    if (o.from) {  // as long and as assisted as the flight it goes on from
      request.duration = o.from->duration;
      request.assist = o.from->assist;
    }
    if (is_device_pilot(o.pilot)) {
      f->devices = open_devices(o, f->scenario_text, f->scenario_source, std::move(gamepad),
                                request, error);
      if (!f->devices) return std::nullopt;
    } else {
      request.pilot_name = o.pilot;
    }
    f->mode = make_mode(f->scenario_text, f->scenario_source, std::move(request), error);
  }
  if (!f->mode) return std::nullopt;
  if (o.from) {
    const RestoreStatus r = f->mode->take_over(*o.from->snapshot);
    if (r != RestoreStatus::ok) {
      error = "cannot fly from t = " + seconds_text(o.from->t) + " s of " + o.from->parent +
              ": " + to_string(r);
      return std::nullopt;
    }
  }
  f->pilot = f->mode->identity().pilot;
  if (!f->recording) f->lesson = o.lesson;
  if (o.vehicle == "dds") {
    if (!open_vehicle_link(o, *f, error)) return std::nullopt;
    if (wait == VehicleWait::block) {
      if (!f->vehicle->wait_for_vehicle(o.vehicle_wait_s)) {
        error = vehicle_not_heard(o, *f);
        return std::nullopt;
      }
      if (!attach_vehicle(*f, error)) return std::nullopt;
    }
  }
  status = kExitOk;
  return f;
}

SessionInfo session_info(const Flight& f, const std::string& trainee) {
  SessionInfo info;
  info.trainee = trainee;
  info.mode = to_string(f.mode->kind());
  info.scenario = f.scenario_text;
  info.scenario_path = f.scenario_file;
  info.pilot = f.pilot;
  if (f.vehicle) info.vehicle = "dds";
  if (f.mode->kind() == ModeKind::mixed_initiative)
    info.assist = f.mode->identity().probe ? "off" : "on";
  if (const auto seed = f.mode->identity().seed) info.seed = *seed;
  // A flight flown on from a recording's moment names it (SPEC §10). A branch's replay
  // recorded again is its whole flight from step 0, and names none.
  if (f.from) {
    info.parent_recording = f.from->parent;
    info.parent_sha256 = f.from->parent_sha256;
    info.parent_step = f.from->step;
  }
  if (f.lesson.active()) {
    info.lesson = f.lesson.lesson;
    info.lesson_hash = f.lesson.lesson_hash;
    info.lesson_step = f.lesson.step + 1;
    info.lesson_steps = f.lesson.steps;
    info.lesson_step_title = f.lesson.title;
  }
  return info;
}

Labels report_labels(const Flight& f, bool was_interrupted) {
  Labels labels = {{"mode", to_string(f.mode->kind())}, {"scenario", f.mode->scenario_name()}};
  if (!f.pilot.empty()) labels.emplace_back("pilot", f.pilot);
  if (f.mode->identity().probe) labels.emplace_back("probe", "true");
  if (was_interrupted) labels.emplace_back("interrupted", "true");
  return labels;
}

bool check_outputs(const FlyOptions& o, std::string& error) {
  std::vector<std::pair<std::string, std::string>> inputs = {
      {"--scenario", o.scenario_path},
      {o.replay ? "the recording" : "--pilot", o.pilot.ends_with(".mcap") ? o.pilot : ""},
      {"--gamepad-script", o.gamepad_script},
      {"--input-settings", o.input_settings},
      {"--commands", o.commands},
      {"--ghost", o.ghost == "best" || o.ghost == "off" ? "" : o.ghost}};
  for (const std::string& file : history::sqlite_files(o.history))
    inputs.emplace_back("the history", file);
  if (!o.record.empty()) check_not_an_input(o.command, "--record", o.record, inputs);
  if (!o.report.empty()) check_not_an_input(o.command, "--report", o.report, inputs);
  for (const ScreenshotRequest& shot : o.screenshots)
    check_not_an_input(o.command, "--screenshot", shot.path, inputs);
  if (!o.video.path.empty()) {
    check_not_an_input(o.command, "--video", o.video.path, inputs);
    for (const ScreenshotRequest& shot : o.screenshots)
      if (same_output_path(shot.path, o.video.path))
        usage_error(o.command, "--screenshot and --video name the same file '" + shot.path + "'");
    if (!check_output_path(o.video.path, o.force, error)) return false;
  }
  if (!o.record.empty() && !o.report.empty() && same_output_path(o.record, o.report))
    usage_error(o.command, "--record and --report name the same file '" + o.record + "'");
  for (const std::string* path : {&o.record, &o.report})
    if (!path->empty() && !check_output_path(*path, o.force, error)) return false;
  for (std::size_t i = 0; i < o.screenshots.size(); ++i) {
    const std::string& shot = o.screenshots[i].path;
    for (const std::string* other : {&o.record, &o.report})
      if (!other->empty() && same_output_path(shot, *other))
        usage_error(o.command, "--screenshot and another output name the same file '" + shot + "'");
    for (std::size_t j = 0; j < i; ++j)
      if (same_output_path(shot, o.screenshots[j].path))
        usage_error(o.command, "two --screenshot options name the same file '" + shot + "'");
    if (!check_output_path(shot, o.force, error)) return false;
  }
  return true;
}

void print_peer(const net::JoyPeer& peer) {
  const net::JoyPeerStats s = peer.stats();
  std::printf("  peer %s (domain %u): %llu samples taken; rejected %llu bad values, %llu bad "
              "sizes, %llu stale, %llu of another publisher (%u publishers heard)\n",
              peer.options().topic.c_str(), unsigned(peer.options().domain),
              (unsigned long long)s.accepted, (unsigned long long)s.bad_value,
              (unsigned long long)s.bad_size, (unsigned long long)s.stale,
              (unsigned long long)s.other_publisher, s.publishers);
  if (s.latency_samples > 0)
    std::printf("  peer latency, publisher stamp to the control step's read: p50 %.1f ms, "
                "p99 %.1f ms (%llu samples)\n",
                s.latency_p50_ms, s.latency_p99_ms, (unsigned long long)s.latency_samples);
  if (!s.last_rejection.empty())
    std::printf("  the newest sample rejected: %s\n", s.last_rejection.c_str());
  if (s.publishers > 1)
    std::printf("  WARNING: %u publishers on %s; only the first one heard flew\n", s.publishers,
                peer.options().topic.c_str());
}

void print_vehicle(const net::RemoteVehicle& vehicle) {
  const net::RemoteVehicleStats s = vehicle.stats();
  std::printf("  vehicle over DDS: %llu commands sent, %llu states taken; rejected %llu bad "
              "values, %llu bad sizes, %llu unknown commands, %llu stale, %llu of another "
              "publisher (%u publishers heard)\n",
              (unsigned long long)s.commands_sent, (unsigned long long)s.accepted,
              (unsigned long long)s.bad_value, (unsigned long long)s.bad_size,
              (unsigned long long)s.unknown_command, (unsigned long long)s.stale,
              (unsigned long long)s.other_publisher, s.publishers);
  if (!s.last_rejection.empty())
    std::printf("  the newest state rejected: %s\n", s.last_rejection.c_str());
  if (s.publishers > 1)
    std::printf("  WARNING: %u vehicles publish states; only the first one heard flew\n",
                s.publishers);
}

std::optional<input::InputSettings> command_input_settings(const char* command,
                                                           const std::string& path,
                                                           std::string& error) {
  if (path.empty()) {
    std::string note;
    const input::InputSettings s = load_input_settings("", note);
    if (!note.empty()) std::fprintf(stderr, "mixpilot %s: %s\n", command, note.c_str());
    return s;
  }
  bool exists = false;
  const auto s = input::load_settings(path, exists, error);
  if (s && !exists) {
    error = path + ": no such file (--input-settings)";
    return std::nullopt;
  }
  return s;
}

std::optional<PilotRecording> read_pilot_recording(const std::string& path, std::string& error) {
  auto rec = read_recording(path, error);
  if (!rec) return std::nullopt;
  if (rec->pilot.empty()) {
    error = path + " holds no pilot commands (a mixed_initiative recording has them)";
    return std::nullopt;
  }
  const std::string* text = embedded_scenario(*rec, path, error);
  auto scenario =
      text ? parse_scenario(*text, embedded_scenario_source(*rec, path), error) : std::nullopt;
  if (!scenario) return std::nullopt;
  return PilotRecording{std::move(*rec), std::move(*scenario)};
}

std::array<double, 4> sdl_axes_for(const PilotCommandMsg& m, const input::InputSettings& settings) {
  PilotCommand c;
  c.roll = m.roll;
  c.pitch = m.pitch;
  c.rotor_speed = Eigen::Vector4d(m.rotor_speed[0], m.rotor_speed[1], m.rotor_speed[2],
                                  m.rotor_speed[3]);
  const input::Controls shaped =
      input::controls_for(c, settings, models::MikroKopter().hover_speed());
  const input::Controls raw{input::unshape(shaped.roll, settings.roll),
                            input::unshape(shaped.pitch, settings.pitch),
                            input::unshape(shaped.thrust, settings.thrust), 0.0};
  const input::StickAxes s = input::unassign(raw, settings.mode);
  return {s.left_x, -s.left_y, s.right_x, -s.right_y};
}

std::uint32_t parse_domain(const char* command, const std::string& text) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < 0 || v > 232)
    usage_error(command, "--domain expects a DDS domain id from 0 to 232, got '" + text + "'");
  return std::uint32_t(v);
}

void print_realtime(const RealtimeStats& st, double dt) {
  std::printf("  real time: %lld deadline misses, %lld late starts; worst start lateness %.0f us, "
              "step p99 %.0f us, longest %.0f us (dt %.0f us); control thread %s\n",
              static_cast<long long>(st.deadline_misses), static_cast<long long>(st.late_starts),
              st.worst_lateness_us, st.p99_step_us,
              st.worst_step_us, 1e6 * dt,
              st.realtime_priority ? "SCHED_FIFO" : "at normal priority (no real-time scheduling granted)");
  std::printf("  simulated time fell %.3f s behind the wall clock%s\n", st.slip_s,
              st.slip_s > 0.1 * double(st.steps) * dt ? " (this machine could not keep real time)"
                                                         : "");
}

std::string seconds_text(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", t);
  return buf;
}


}  // namespace mixpilot::cli
