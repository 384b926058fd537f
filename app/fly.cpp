// mixpilot fly / demo: one session of any mode, as fast as possible.
#include <charconv>
#include <system_error>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/ghost.hpp"
#include "app/station_settings.hpp"
#include "core/recording/replay.hpp"
#include "app/screenshot.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "app/video_replay.hpp"
#include "app/window.hpp"
#include "core/history/history.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "core/modes/report.hpp"
#include "core/modes/session.hpp"
#include "core/base/output_file.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/data_files.hpp"
#include "core/scenario/scenario_toml.hpp"


namespace mixpilot::cli {

namespace {

constexpr double kMaxDuration = 3600.0;  // [s] --duration: memory and time stay proportionate
// --scale: from half size (a 4K panel at 48 dpi makes no sense below) to 400 %.
constexpr double kMinScale = 0.5, kMaxScale = 4.0;

constexpr const char* kFlyUsage =
    "usage: mixpilot fly --scenario FILE --pilot PILOT [--headless] [options]\n"
    "\n"
    "Flies one session of the scenario in a window, in real time, or with --headless as fast\n"
    "as possible (or paced by the clock with --realtime), and prints a short summary. ^C ends\n"
    "the flight at the next step: the recording and report then hold what was flown.\n"
    "\n"
    "  --scenario FILE    scenario file (TOML, docs/scenario-format.md); optional when PILOT is\n"
    "                     a recording, whose embedded scenario is then used, and in the window\n"
    "                     (default: the shipped mi_helix; while the history has no flight, the\n"
    "                     window then opens on a welcome with three ways in, until it is\n"
    "                     dismissed; F1 shows it again). Its `mode` picks what flies:\n"
    "                     mixed_initiative (with a pilot) or a thesis controller\n"
    "  --pilot PILOT      novice | experienced | reckless | another profile of the scenario |\n"
    "                     gamepad (headless only with --realtime) | keyboard (window) |\n"
    "                     dds[:TOPIC] (sensor_msgs/msg/Joy from the network, default\n"
    "                     topic joy; headless only with --realtime) |\n"
    "                     RECORDING.mcap (replays its pilot commands, checked step by step\n"
    "                     against the recording); default: the scenario's (mixed_initiative only)\n"
    "  --assist on|off    on (default): the planner assists the pilot, their references blended\n"
    "                     by the PH index λ (SPEC §5.4). off: a probe flight (SPEC §10): λ is\n"
    "                     pinned to 1 in the cost, so the planner's reference has no weight and\n"
    "                     the score is the pilot's own skill, while every constraint still keeps\n"
    "                     the vehicle safe (obstacles, arena walls, input bounds, the safe hold;\n"
    "                     a lost device still hands the vehicle to the planner). Marked as a\n"
    "                     probe in the report and the recording, whose replays fly it as one\n"
    "                     (mixed_initiative only)\n"
    "  --floor X, --ceiling X  the instructor's bounds on the authority λ for the whole\n"
    "                     flight (SPEC §10): λ = min(max(λ_PH, floor), ceiling, the input's\n"
    "                     cap); 0 <= floor <= ceiling <= 1, default 0 and 1; recorded, and\n"
    "                     flown again by a replay (mixed_initiative only)\n"
    "  --commands FILE.toml  an instructor's commands at flight times (SPEC §10): bounds,\n"
    "                     gust, extra_delay, input_loss, marker and end, one [[command]] table\n"
    "                     each with `at` in seconds (docs/recording-format.md, \"Instructor\n"
    "                     commands\"); each takes effect at the first step at or after its time,\n"
    "                     is shown on the HUD, recorded with that step and applied there again by\n"
    "                     a replay. Not for a replay, which applies its recorded commands\n"
    "  --gamepad-script FILE.csv  with --pilot gamepad: a virtual gamepad plays the script\n"
    "                     (docs/input-settings.md) through SDL from the start of the flight\n"
    "  --input-settings FILE  stick mode, shaping, input loss, haptic cue (TOML; default: the\n"
    "                     user's $XDG_CONFIG_HOME/mixpilot/input.toml, docs/input-settings.md)\n"
    "  --publish          publish the telemetry over DDS at the control rate (ROS 2 types:\n"
    "                     rt/mixpilot/pose, lambda, predicted_path, reference_path) and\n"
    "                     announce this station to instructors (rt/mixpilot/station, twice\n"
    "                     a second: trainee, scenario, state, t, λ, deviation, the\n"
    "                     commands accepted and refused; SPEC §10)\n"
    "  --station NAME     with --publish: this station's name (default: host name-process id)\n"
    "  --instructor       with --publish: obey an instructor's commands (authority bounds,\n"
    "                     gusts, markers, pause...), checked and counted; only from a\n"
    "                     certified instructor over DDS Security (docs/instructor-security.md).\n"
    "                     $XDG_CONFIG_HOME/mixpilot/station.toml may set name, instructor and\n"
    "                     dds_security for every flight that publishes (the options win)\n"
    "  --dds-security FOLDER  with --publish: authenticate with this identity's DDS Security\n"
    "                     files (identity_ca.pem, cert.pem, key.pem, permissions_ca.pem,\n"
    "                     governance.p7s, permissions.p7s; mixpilot-security-ca DIR)\n"
    "  --allow-unauthenticated-commands  with --instructor: obey commands without DDS\n"
    "                     Security; accepted only while CYCLONEDDS_URI keeps DDS on loopback\n"
    "  --vehicle sim|dds  sim (default): the plant is simulated in this process; dds: the\n"
    "                     vehicle of `mixpilot vehicle` flies over DDS, with the round-trip\n"
    "                     time estimated online (crazyflie_tracking, mixed_initiative;\n"
    "                     headless only with --realtime)\n"
    "  --vehicle-wait S   how long to wait for that vehicle before the flight (default 30)\n"
    "  --domain N         DDS domain of --pilot dds, --publish and --vehicle dds (0-232,\n"
    "                     default 0). DDS stays on this machine unless CYCLONEDDS_URI names\n"
    "                     another configuration (docs/network.md)\n"
    "  --headless         run without a window, as fast as possible (default: a window,\n"
    "                     in real time, where a display exists)\n"
    "  --realtime         with --headless: paced by the wall clock, deadline misses counted\n"
    "  --exit-at-end      window: start at once and close the window when the run ends\n"
    "  --duration S       fly S seconds (at most 3600) instead of the scenario's duration, or\n"
    "                     instead of the recording's length\n"
    "  --record OUT.mcap  record the session (MCAP, ros2 profile; docs/recording-format.md):\n"
    "                     every mode's telemetry, plus the pilot's commands in mixed_initiative\n"
    "  --report OUT.json  write the score (mixed_initiative; fields: README, Scoring) or the\n"
    "                     mode's metrics as JSON, with `lost` and `lost_at_s`; a replay's\n"
    "                     timing fields are the recorded flight's, as in `score`\n"
    "  --screenshot T:FILE.png  write what the window would show at simulated time T (the\n"
    "                     step with t_k <= T < t_k + dt), rendered offscreen with EGL;\n"
    "                     repeatable\n"
    "  --size WxH         screenshot and window size in pixels (default 1280x720)\n"
    "  --scale S          display scale of the UI, 0.5 to 4 (1.5 = 150 %): the fonts and\n"
    "                     sizes the window has on such a display. Default: the window follows\n"
    "                     the desktop (GLFW's content scale, Xft.dpi / 96 on X11); --headless\n"
    "                     renders at 1 (100 %)\n"
    "  --ghost REC.mcap|best|off  a recorded flight of the same scenario flies along as a\n"
    "                     translucent vehicle with its trail, in step by time (at t it is where\n"
    "                     the recording was at t), and the HUD says how far ahead or behind\n"
    "                     along the reference you are. best: the trainee's best recorded flight\n"
    "                     of this scenario in the history whose recording is still on this\n"
    "                     disk (none yet: said, and flown without a ghost). Default: best in\n"
    "                     the window (the session panel picks another), off headless, where a\n"
    "                     ghost shows in --screenshot and the summary gives its figure. A\n"
    "                     recording of another scenario, or of another version of its file, is\n"
    "                     refused (mixed_initiative only)\n"
    "  --trainee NAME     who flies (default: the login name): the history's row and the\n"
    "                     recording's metadata. 1-200 characters of UTF-8, no control characters\n"
    "  --history LOCATION where the flight is remembered (SPEC §10; `mixpilot history` lists\n"
    "                     them): an SQLite file (PATH or sqlite:PATH; default\n"
    "                     $XDG_DATA_HOME/mixpilot/history.sqlite), postgresql://..., or off.\n"
    "                     A history that cannot be written is said on stderr; the flight, its\n"
    "                     recording and its exit status are not affected. A replay (--pilot\n"
    "                     REC.mcap) is no new flight and is not added (see history import)\n"
    "  --force            overwrite existing --record, --report and --screenshot files\n"
    "  --allow-mismatch   fly a recording with a --scenario other than its embedded one, and\n"
    "                     accept a replay that differs from the recording\n"
    "\n"
    "exit status: 0 done, 1 bad input or failure, 2 usage, 3 replay differs from the recording,\n"
    "130 interrupted\n";

// The window: the app (app/trainer.hpp) on the live flight or the replay the options name.
int run_in_window(const FlyOptions& o) {
  std::string error;
  int status = kExitOk;
  // The window reads --ghost's recording off its UI thread once it runs; a file that is not
  // there at all is said now, before the window opens.
  if (const GhostChoice g = GhostChoice::of(o.ghost); g.kind == GhostChoice::Kind::file) {
    std::error_code ec;
    const auto st = std::filesystem::status(g.path, ec);
    if (ec || !std::filesystem::is_regular_file(st)) {
      std::fprintf(stderr, "mixpilot %s: --ghost %s: %s\n", o.command, g.path.c_str(),
                   ec || !std::filesystem::exists(st) ? "no such file"
                                                      : "not a recording file (a folder or a device)");
      return kExitError;
    }
  }
  catch_interrupts();
  Trainer app(o);
  const bool opened = o.replay ? app.open_replay(o.pilot, error) : app.open_live(error, status);
  if (!opened) {
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    return status == kExitOk ? kExitError : status;
  }
  std::vector<std::string> shots;
  const WindowOptions wo{o.width, o.height, o.exit_at_end, o.screenshots, o.force, o.scale};
  const bool shown = run_window(app, wo, shots, error);
  status = app.finish();
  for (const std::string& path : shots) std::printf("  screenshot %s\n", path.c_str());
  if (!shown) {
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    if (status == kExitOk) status = kExitError;
  } else {
    for (const ScreenshotRequest& r : o.screenshots) {
      if (std::find(shots.begin(), shots.end(), r.path) != shots.end()) continue;
      std::fprintf(stderr, "mixpilot %s: --screenshot %s: not written, the window closed before "
                   "t = %s s\n", o.command, r.path.c_str(), seconds_text(r.t).c_str());
      if (status == kExitOk) status = kExitError;
    }
  }
  return interrupted() ? kExitInterrupted : status;
}

// `replay --headless`: the recording flown again into the app's tape, then each --screenshot
// rendered as the window shows the replay at that time (transport bar included).
int run_replay_headless(const FlyOptions& o) {
  std::string error;
  catch_interrupts();
  Trainer app(o);
  if (!app.open_replay(o.pilot, error)) {
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    return kExitError;
  }
  std::optional<Offscreen> screen;
  if (!o.screenshots.empty()) {
    screen.emplace();
    if (!screen->open(o.width, o.height, error, o.scale > 0 ? o.scale : 1.0f)) {
      std::fprintf(stderr, "mixpilot %s: --screenshot: %s\n", o.command, error.c_str());
      return kExitError;
    }
  }
  app.load_replay();
  if (interrupted()) return kExitInterrupted;
  if (!app.replay_ghost_error().empty()) {
    std::fprintf(stderr, "mixpilot %s: --ghost %s\n", o.command, app.replay_ghost_error().c_str());
    (void)app.finish();
    return kExitError;
  }
  const double end = double(app.replay()->steps()) * app.replay()->dt();
  for (const ScreenshotRequest& r : o.screenshots)  // all checked before the first is written
    if (r.t >= end)
      usage_error(o.command, "--screenshot at t = " + seconds_text(r.t) +
                                 " s is beyond the recording's end (" + seconds_text(end) + " s)");
  int status = kExitOk;
  for (const ScreenshotRequest& r : o.screenshots) {
    app.seek(r.t);
    for (int f = 0; f < 2; ++f) screen->frame([&] { app.build_frame(0.0); });
    if (!write_file(r.path, screen->png(), o.force, error)) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      status = kExitError;
    } else {
      std::printf("  screenshot %s\n", r.path.c_str());
    }
  }
  const int finished = app.finish();
  return status != kExitOk ? status : finished;
}

// `fly --headless`'s flight, flown: as fast as possible on this thread, or paced on the control
// thread with the telemetry drained here (where screenshots render: their GL context's thread).
// The wall time [s] it took; the real-time statistics when paced.
double fly_headless(FlightRig& rig, const FlyOptions& o, ScreenshotSink* screenshots,
                    std::optional<RealtimeStats>& realtime) {
  Mode& mode = rig.mode();
  catch_interrupts();
  const auto t0 = std::chrono::steady_clock::now();
  if (o.realtime) {
    rig.pace(1024);
    RealtimeRunner& runner = *rig.runner();
    rig.start();
    Progress progress("fly " + mode.scenario_name() + " (real time)", mode.steps_total());
    Telemetry drained = mode.telemetry();
    const auto drain = [&] {
      while (runner.telemetry().pop(drained))
        if (screenshots) screenshots->on_sample(drained);
    };
    while (runner.running() && !interrupted()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      drain();
      progress.update(mode.steps_done());
    }
    rig.stop();
    drain();
    realtime = runner.stats();
  } else {
    if (screenshots) rig.watch(*screenshots);
    rig.start();
    Progress progress("fly " + mode.scenario_name(), mode.steps_total());
    // Paused by the instructor (a live command): nothing steps until a resume or an end.
    while (!interrupted() && rig.step()) {
      if (!rig.session().stepped()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      progress.update(mode.steps_done());
    }
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// --ghost for a headless flight (its default: off): the ghost it names, or the trainee's best
// recorded flight of the scenario, read now (nothing here is a UI thread). False with the
// reason: a recording that cannot be a ghost of this flight. --ghost best without such a
// flight is no error: it is said, and the flight flies without one.
bool headless_ghost(const FlightRig& rig, const FlyOptions& o,
                    std::shared_ptr<const ui::Ghost>& ghost, std::string& error) {
  const GhostChoice choice = GhostChoice::of(o.ghost.empty() ? "off" : o.ghost);
  if (choice.kind == GhostChoice::Kind::off) return true;
  const std::optional<GhostTarget> target = ghost_target(rig.flight(), error);
  if (!target) {
    error = (choice.kind == GhostChoice::Kind::best ? "best: " : choice.path + ": ") + error;
    return false;
  }
  std::string path = choice.path, label;
  if (choice.kind == GhostChoice::Kind::best) {
    std::string why;
    const std::optional<ui::ProgressFlight> best = best_ghost_flight(o.history, o.trainee, *target, why);
    if (!best) {
      std::fprintf(stderr, "mixpilot %s: --ghost best: %s; flying without a ghost\n", o.command,
                   why.c_str());
      return true;
    }
    path = best->recording;
    label = ghost_label(*best, true);
  }
  ghost = load_ghost(path, *target, label, error);
  return ghost != nullptr;
}

// The ghost's line of the summary: where the flight ended against it.
void print_ghost(const ui::Ghost& ghost, const Mode& mode) {
  std::printf("  ghost %s (%s)", ghost.label.c_str(), ghost.path.c_str());
  const std::optional<ui::GhostGap> gap =
      ui::ghost_gap(ghost, mode.view().reference_at, mode.telemetry());
  if (gap)
    std::printf(": at t = %.3f s you were %s by %.3f s along the reference\n", gap->t,
                gap->ahead >= 0 ? "ahead" : "behind", std::abs(gap->ahead));
  else
    std::printf(": it flew %.3f s to %.3f s\n", double(ghost.first_step) * ghost.dt, ghost.last_t());
}

// The summary on stdout after the flight, the report and the screenshots written; the exit
// status.
int finish_headless(FlightRig& rig, const FlyOptions& o, ScreenshotSink* screenshots,
                    double wall, const std::optional<RealtimeStats>& realtime,
                    HistoryWriter* history, const ui::Ghost* ghost) {
  const Mode& mode = rig.mode();
  const bool stopped = (interrupted() || rig.session().ended_by_instructor()) && !mode.finished();
  int status = kExitOk;
  std::string error;
  const FlightRig::Closed closed = rig.close(stopped);
  if (!closed.error.empty()) {
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, closed.error.c_str());
    status = kExitError;
  }
  std::printf("mixpilot %s: %s", o.command, mode.summary().c_str());
  const double flown = double(mode.steps_done()) * mode.dt();
  std::printf("  %.1f s flown in %.2f s of wall time (%.0fx real time)\n", flown, wall,
              flown / std::max(wall, 1e-9));
  if (realtime) print_realtime(*realtime, mode.dt());
  const Flight& flight = rig.flight();
  if (flight.devices && flight.devices->peer) print_peer(*flight.devices->peer);
  if (flight.vehicle) print_vehicle(*flight.vehicle);
  if (closed.published)
    std::printf("  published %llu steps on rt/mixpilot/* (domain %u; %llu dropped)\n",
                (unsigned long long)closed.published_steps, unsigned(o.domain),
                (unsigned long long)closed.publish_dropped);
  std::fputs(station_summary(closed).c_str(), stdout);
  if (mode.lost()) std::printf("  LOST: the vehicle was lost at t = %.3f s\n", mode.lost_at());
  const CommandInbox& inbox = rig.commands();
  if (inbox.applied() + inbox.refused() + inbox.dropped() > 0) {
    std::printf("  instructor: %lld commands applied, %lld refused, %lld dropped (the inbox was "
                "full)\n",
                (long long)inbox.applied(), (long long)inbox.refused(), (long long)inbox.dropped());
    if (inbox.refused() > 0)
      std::printf("  the last refused: %s\n", to_string(inbox.last_refusal()));
  }
  if (rig.session().ended_by_instructor())
    std::printf("  ended by the instructor at t = %.3f s\n", flown);
  if (ghost) print_ghost(*ghost, mode);
  if (!o.report.empty()) {
    const std::string json = to_json(rig.labels(stopped), rig.metrics()) + "\n";
    if (!write_file(o.report, json, o.force, error)) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      status = kExitError;
    }
  }
  if (screenshots) {
    if (!screenshots->finish(error)) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      status = kExitError;
    }
    for (std::size_t i = 0; i < screenshots->written().size(); ++i)
      std::printf("  screenshot %s%s\n", screenshots->written()[i].c_str(),
                  screenshots->notes()[i].c_str());
  }
  if (!closed.recorded.empty() && status == kExitOk) std::printf("  recorded %s\n", o.record.c_str());
  // The history never changes the exit status: the flight is fine without it. Its row is
  // written on the writer's thread, as in the window; here the command waits for it.
  if (history && closed.remembering) {
    history->wait_idle();
    std::vector<HistoryWriter::Outcome> outcomes;
    (void)history->poll(outcomes);
    for (const HistoryWriter::Outcome& r : outcomes)
      if (!r.remembered)
        std::fprintf(stderr, "mixpilot %s: history: %s; this flight is flown but not remembered\n",
                     o.command, r.error.c_str());
  }
  if (!o.report.empty() && status == kExitOk) std::printf("  report %s\n", o.report.c_str());
  if (stopped && !rig.session().ended_by_instructor()) {
    std::printf("  interrupted at t = %.3f s\n", flown);
    return kExitInterrupted;
  }
  if (flight.recording && status == kExitOk) {
    const std::string diff = rig.replay_difference();
    if (!diff.empty()) {
      std::fprintf(stderr, "mixpilot %s: the replay of %s differs from the recording: %s\n", o.command,
                   o.pilot.c_str(), diff.c_str());
      if (!o.allow_mismatch) return kExitReplayMismatch;
    } else {
      std::printf("  replay exact: every recorded step reproduced bit for bit\n");
    }
  }
  return status;
}

}  // namespace

int run_fly(const FlyOptions& o) {
  std::string error;
  // ffmpeg is looked for before the outputs: without it nothing else matters.
  if (!o.video.path.empty()) return replay_to_video(o);
  if (!o.headless && !window_available(error)) {  // before any output is opened
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    return kExitError;
  }
  if (!check_outputs(o, error)) {
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    return kExitError;
  }
  if (!o.headless) return run_in_window(o);
  if (o.replay) return run_replay_headless(o);
  int status = kExitOk;
  // Declared before the rig, which hands it its row when it closes.
  std::optional<HistoryWriter> history;
  const std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, error, status);
  if (!rig) {
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    return status;
  }
  // Every check that can fail comes before the recording opens: a run that never flies leaves
  // no file behind.
  if (!check_outputs(o, error)) {  // again: the flight's own inputs (reference files) are known
    std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
    return kExitError;
  }
  const Mode& mode = rig->mode();
  const double end = double(mode.steps_total()) * mode.dt();
  for (const ScreenshotRequest& r : o.screenshots)
    if (r.t >= end)
      usage_error(o.command, "--screenshot at t = " + seconds_text(r.t) +
                                 " s is beyond the flight's end (" + seconds_text(end) + " s)");
  std::shared_ptr<const ui::Ghost> ghost;
  if (!headless_ghost(*rig, o, ghost, error)) {
    std::fprintf(stderr, "mixpilot %s: --ghost %s\n", o.command, error.c_str());
    return kExitError;
  }
  const std::string& pilot = rig->flight().pilot;
  std::optional<ScreenshotSink> screenshots;
  if (!o.screenshots.empty()) {
    ui::Scene scene =
        ui::scene_of(mode, pilot.empty() ? std::string("the thesis's controller") : "pilot " + pilot);
    scene.ghost = ghost;
    screenshots.emplace(std::move(scene), o.screenshots, o.force);
    if (!screenshots->open(o.width, o.height, error, o.scale > 0 ? o.scale : 1.0f)) {
      std::fprintf(stderr, "mixpilot %s: --screenshot: %s\n", o.command, error.c_str());
      return kExitError;
    }
  }
  if (o.publish) {
    if (!rig->publish(error)) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      return kExitError;
    }
    std::printf("mixpilot %s: %s\n", o.command, station_started(*rig->instructor_link()).c_str());
    std::fflush(stdout);
  }
  if (!o.record.empty()) {
    // Real-time runs never wait for the disk: a full ring drops (and counts) steps.
    RecordingSink::Settings rs;
    if (o.realtime) rs.when_full = RecordingSink::FullRing::drop;
    if (!rig->record(o.record, o.trainee, rs, o.force, error)) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      return kExitError;
    }
  }
  // The store is opened on the writer's thread while the flight flies; a failure to open it is
  // said at the end, with the row it cost.
  if (o.history != "off" && !rig->flight().recording) {
    history.emplace(o.history);
    rig->remember(&*history, o.trainee, "fly");
  }
  ScreenshotSink* shots = screenshots ? &*screenshots : nullptr;
  std::optional<RealtimeStats> realtime;
  const double wall = fly_headless(*rig, o, shots, realtime);
  return finish_headless(*rig, o, shots, wall, realtime, history ? &*history : nullptr,
                         ghost.get());
}

namespace {

// --screenshot, --size, --scale and --exit-at-end, shared by fly and replay: true when `a` is one of them
// (its value taken through `value`).
template <class Value>
bool parse_view_option(std::string_view a, const Value& value, FlyOptions& o) {
  if (a == "--screenshot") {
    const std::string v = value();
    const auto shot = parse_screenshot(v);
    if (!shot)
      usage_error(o.command,
                  "--screenshot expects T:FILE.png with T a time in seconds ≥ 0, got '" + v + "'");
    o.screenshots.push_back(*shot);
  } else if (a == "--size") {
    const std::string v = value();
    if (!parse_size(v, o.width, o.height))
      usage_error(o.command, "--size expects WxH, each from 64 to 8192 pixels, got '" + v + "'");
  } else if (a == "--scale") {
    const std::string v = value();
    const auto scale = parse_seconds(v, kMaxScale);  // a positive number up to the bound
    if (!scale || *scale < kMinScale)
      usage_error(o.command, "--scale expects a display scale from 0.5 to 4 (1.5 is 150 %), got '" +
                                 v + "'");
    o.scale = float(*scale);
  } else if (a == "--exit-at-end") {
    o.exit_at_end = true;
  } else {
    return false;
  }
  return true;
}

}  // namespace

int fly_command(int argc, char** argv) {
  FlyOptions o;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&] { return option_value(o.command, argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kFlyUsage, stdout);
      return kExitOk;
    } else if (a == "--scenario") {
      o.scenario_path = value();
    } else if (a == "--pilot") {
      o.pilot = value();
    } else if (a == "--assist") {
      const std::string v = value();
      if (v == "on") o.assist = Assistance::on;
      else if (v == "off") o.assist = Assistance::off;
      else usage_error(o.command, "--assist expects on or off, got '" + v + "'");
    } else if (a == "--floor" || a == "--ceiling") {
      const std::string v = value();
      double x = 0.0;
      const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
      if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size() || !(x >= 0.0) ||
          !(x <= 1.0))
        usage_error(o.command, std::string(a) + " expects a number from 0 to 1, got '" + v + "'");
      (a == "--floor" ? o.bounds.floor : o.bounds.ceiling) = x;
    } else if (a == "--commands") {
      o.commands = value();
    } else if (a == "--headless") {
      o.headless = true;
    } else if (a == "--duration") {
      const std::string v = value();
      o.duration = parse_seconds(v, kMaxDuration);
      if (!o.duration)
        usage_error(o.command, "--duration expects a positive number of seconds up to 3600, got '" +
                               v + "'");
    } else if (a == "--record") {
      o.record = value();
    } else if (a == "--report") {
      o.report = value();
    } else if (parse_view_option(a, value, o)) {
    } else if (a == "--realtime") {
      o.realtime = true;
    } else if (a == "--gamepad-script") {
      o.gamepad_script = value();
    } else if (a == "--input-settings") {
      o.input_settings = value();
    } else if (a == "--publish") {
      o.publish = true;
    } else if (a == "--station") {
      o.station = value();
      if (const std::string why = net::check_station_name(o.station); !why.empty())
        usage_error(o.command, "--station: " + why);
    } else if (a == "--instructor") {
      o.instructor = true;
    } else if (a == "--dds-security") {
      o.dds_security = value();
    } else if (a == "--allow-unauthenticated-commands") {
      o.allow_unauthenticated_commands = true;
    } else if (a == "--vehicle") {
      o.vehicle = value();
      if (o.vehicle == "sim") o.vehicle.clear();
      else if (o.vehicle != "dds")
        usage_error(o.command, "--vehicle expects sim or dds, got '" + o.vehicle + "'");
    } else if (a == "--vehicle-wait") {
      const std::string v = value();
      const auto s = parse_seconds(v, 3600.0);
      if (!s) usage_error(o.command, "--vehicle-wait expects seconds up to 3600, got '" + v + "'");
      o.vehicle_wait_s = *s;
    } else if (a == "--domain") {
      o.domain = parse_domain(o.command, value());
    } else if (a == "--allow-mismatch") {
      o.allow_mismatch = true;
    } else if (a == "--trainee") {
      o.trainee = value();
      if (const std::string why = history::check_trainee(o.trainee); !why.empty())
        usage_error(o.command, "--trainee: " + why);
    } else if (a == "--history") {
      o.history = value();
    } else if (a == "--ghost") {
      o.ghost = value();
    } else if (a == "--force") {
      o.force = true;
    } else {
      usage_error(o.command, "unknown option '" + std::string(a) + "'");
    }
  }
  if (!o.publish && (o.instructor || !o.station.empty() || !o.dds_security.empty() ||
                     o.allow_unauthenticated_commands))
    usage_error(o.command, std::string(o.instructor ? "--instructor"
                                       : !o.station.empty() ? "--station"
                                       : !o.dds_security.empty() ? "--dds-security"
                                                                 : "--allow-unauthenticated-commands") +
                               " goes with --publish (the station is announced and commanded "
                               "over DDS)");
  if (o.publish) {
    // The station's settings, under what the command line says.
    std::string error;
    const std::optional<StationSettings> st = load_station_settings("", error);
    if (!st) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      return kExitError;
    }
    if (o.station.empty()) o.station = st->name;
    o.instructor = o.instructor || st->instructor;
    if (o.dds_security.empty()) o.dds_security = st->dds_security;
  }
  if (o.allow_unauthenticated_commands && !o.instructor)
    usage_error(o.command, "--allow-unauthenticated-commands goes with --instructor (or "
                           "instructor = true in station.toml)");
  if (o.ghost == "best" && o.history == "off")
    usage_error(o.command, "--ghost best is read from the history: not with --history off "
                           "(name a recording: --ghost REC.mcap)");
  // The first launch's welcome (ui/first_launch.hpp) is for a person opening the window to look
  // around: not when the command line names the scenario (an expert's choice), replays, or runs
  // the window by script.
  o.first_launch = !o.headless && o.scenario_path.empty() && !o.pilot.ends_with(".mcap") &&
                   !o.exit_at_end && o.screenshots.empty() && o.gamepad_script.empty() &&
                   o.commands.empty() && o.vehicle.empty();
  // The window without a scenario (the desktop entry): the shipped mi_helix, changeable there.
  if (o.scenario_path.empty() && !o.headless && !o.pilot.ends_with(".mcap"))
    o.scenario_path = data_file("scenarios/mi_helix.toml");
  if (!o.bounds.valid())
    usage_error(o.command, "--floor " + seconds_text(o.bounds.floor) + " is above --ceiling " +
                               seconds_text(o.bounds.ceiling) + ": expected floor <= ceiling");
  if (o.bounds != AuthorityBounds{} && o.pilot.ends_with(".mcap"))
    usage_error(o.command, "--floor and --ceiling are for a new flight: a replay flies with the "
                           "bounds it was recorded with");
  if (!o.commands.empty() && o.pilot.ends_with(".mcap"))
    usage_error(o.command, "--commands is for a new flight: a replay applies the instructor's "
                           "commands it recorded");
  if (o.realtime && !o.headless) usage_error(o.command, "--realtime is for --headless runs (a window is always real time)");
  if (o.exit_at_end && o.headless) usage_error(o.command, "--exit-at-end is for the window");
  if (!o.gamepad_script.empty() && o.pilot != "gamepad")
    usage_error(o.command, "--gamepad-script plays a virtual gamepad: it goes with --pilot gamepad");
  if (!o.vehicle.empty() && o.headless && !o.realtime)
    usage_error(o.command, "--vehicle dds flies a vehicle on the wall clock: a headless flight "
                           "with it needs --realtime");
  if (!o.vehicle.empty() && o.pilot.ends_with(".mcap"))
    usage_error(o.command, "--vehicle dds cannot replay a recording (its pilot commands were "
                           "checked against a simulated plant); fly another pilot");
  if (o.pilot == "keyboard" && o.headless)
    usage_error(o.command, "--pilot keyboard takes its keys from the window: fly without --headless");
  if (is_device_pilot(o.pilot) && o.headless && !o.realtime)
    usage_error(o.command, "--pilot " + o.pilot + " is a person: a headless flight with it needs "
                           "--realtime (or fly in the window)");
  return run_fly(o);
}

constexpr const char* kReplayUsage =
    "usage: mixpilot replay FILE.mcap [--headless] [options]\n"
    "\n"
    "Shows a recording of any mode: its session is flown again from the embedded scenario with\n"
    "the recorded pilot commands, which reproduces every recorded step bit for bit (checked;\n"
    "a difference exits 3), in the window in real time or headless as fast as possible.\n"
    "\n"
    "  --headless         no window (with --screenshot: what the window shows at time T)\n"
    "  --screenshot T:FILE.png  as for fly; repeatable\n"
    "  --video OUT.mp4    a video of the replay, without a window: every frame rendered\n"
    "                     offscreen as --screenshot renders it (frame i shows time\n"
    "                     FROM + i/FPS) and encoded by ffmpeg (H.264, yuv420p; Debian's\n"
    "                     package ffmpeg), with a progress bar on a terminal\n"
    "  --from T           the video's first frame at T seconds (default 0)\n"
    "  --to T             the video ends before T seconds (default: the recording's end)\n"
    "  --fps F            video frames per second, 1 to 120 (default 30)\n"
    "  --size WxH         screenshot, video or window size (default 1280x720; even for a\n"
    "                     video)\n"
    "  --scale S          display scale of the UI, 0.5 to 4 (as for fly; headless default 1)\n"
    "  --exit-at-end      window: start at once and close the window at the end\n"
    "  --ghost REC.mcap   another recording of the same scenario flies along the replay as a\n"
    "                     translucent vehicle with its trail, in step by time, with how far\n"
    "                     ahead or behind along the reference the replayed flight is (window,\n"
    "                     --screenshot and --video; a recording of another scenario is\n"
    "                     refused)\n"
    "  --force            overwrite existing screenshot and video files\n"
    "  -h, --help         show this help\n"
    "\n"
    "A video is written to a temporary beside OUT and moved into place when complete: a\n"
    "failure or ^C leaves no file.\n"
    "\n"
    "exit status: 0 done, 1 unreadable recording or a failure (no ffmpeg, ffmpeg failed),\n"
    "2 usage, 3 the replay differs, 130 interrupted\n";

int replay_command(int argc, char** argv) {
  FlyOptions o;
  o.replay = true;
  o.command = "replay";
  bool from_given = false, to_given = false, fps_given = false;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&] { return option_value("replay", argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kReplayUsage, stdout);
      return kExitOk;
    } else if (a == "--headless") {
      o.headless = true;
    } else if (a == "--video") {
      o.video.path = value();
    } else if (a == "--from" || a == "--to") {
      const std::string v = value();
      const auto t = parse_time(v);
      if (!t)
        usage_error("replay", std::string(a) + " expects a time in seconds >= 0, got '" + v + "'");
      (a == "--from" ? from_given : to_given) = true;
      if (a == "--from") o.video.from = *t;
      else o.video.to = *t;
    } else if (a == "--fps") {
      const std::string v = value();
      const auto fps = parse_fps(v);
      if (!fps)
        usage_error("replay", "--fps expects frames per second from 1 to 120, got '" + v + "'");
      o.video.fps = *fps;
      fps_given = true;
    } else if (parse_view_option(a, value, o)) {
    } else if (a == "--ghost") {
      o.ghost = value();
      if (o.ghost == "best")
        usage_error("replay", "--ghost best is for a flight of your own (fly): a replay races "
                              "a recording, --ghost REC.mcap");
      if (o.ghost == "off") o.ghost.clear();
    } else if (a == "--force") {
      o.force = true;
    } else if (!a.empty() && a[0] == '-') {
      usage_error("replay", "unknown option '" + std::string(a) + "'");
    } else if (o.pilot.empty()) {
      o.pilot = file_argument("replay", "a recording", a);
    } else {
      usage_error("replay", "one recording at a time (got '" + o.pilot + "' and '" +
                                std::string(a) + "')");
    }
  }
  if (o.pilot.empty()) usage_error("replay", "which recording? (mixpilot replay FILE.mcap)");
  if (!o.pilot.ends_with(".mcap"))
    usage_error("replay", "'" + o.pilot + "' is not a recording (FILE.mcap)");
  if (o.video.path.empty() && (from_given || to_given || fps_given))
    usage_error("replay", std::string(from_given ? "--from" : to_given ? "--to" : "--fps") +
                              " goes with --video OUT.mp4");
  if (!o.video.path.empty()) {
    if (o.exit_at_end) usage_error("replay", "--exit-at-end is for the window; --video renders without one");
    if (o.width % 2 != 0 || o.height % 2 != 0)
      usage_error("replay", "--size for --video expects an even width and height (H.264 in "
                            "4:2:0 halves both for colour), got " + std::to_string(o.width) +
                            "x" + std::to_string(o.height));
    if (o.video.to && *o.video.to <= o.video.from)
      usage_error("replay", range_problem(o.video.from, *o.video.to, true, 1e300));
    o.headless = true;  // a video renders offscreen
  }
  if (o.exit_at_end && o.headless) usage_error("replay", "--exit-at-end is for the window");
  return run_fly(o);
}

int demo_command() {
  FlyOptions o;
  std::string why;
  const std::string dir = data_dir(&why);
  if (dir.empty()) {
    std::fprintf(stderr, "mixpilot demo: %s\n", why.c_str());
    return kExitError;
  }
  o.scenario_path = dir + "/scenarios/mi_helix.toml";
  o.pilot = "novice";
  o.headless = true;
  o.command = "demo";
  return run_fly(o);
}

}  // namespace mixpilot::cli
