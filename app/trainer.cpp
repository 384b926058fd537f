#include "app/trainer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <system_error>

#include <imgui.h>

#include "app/cli.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/report.hpp"
#include "core/scenario/data_files.hpp"


namespace mixpilot::cli {

namespace fs = std::filesystem;

namespace {

std::string absolute_path(const std::string& p) {
  std::error_code ec;
  const fs::path a = fs::absolute(p, ec);
  return (ec ? fs::path(p) : a).lexically_normal().string();
}

// The shipped scenarios, by name.
std::vector<std::string> shipped_scenarios() {
  std::vector<std::string> out;
  std::error_code ec;
  const std::string dir = data_file("scenarios");
  if (dir.empty()) return out;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end;
       it.increment(ec))
    if (it->path().extension() == ".toml") out.push_back(absolute_path(it->path().string()));
  std::sort(out.begin(), out.end());
  return out;
}

// Where the app's recordings go: $XDG_DATA_HOME/mixpilot/recordings (~/.local/share/...);
// "" with `why` when the user has no home folder.
fs::path recordings_folder(std::string* why = nullptr) {
  const std::string base = xdg_dir("XDG_DATA_HOME", ".local/share", why);
  return base.empty() ? fs::path() : fs::path(base) / "mixpilot" / "recordings";
}

// A scenario or pilot name as part of a file name: one name, never a path.
std::string file_name_part(std::string name) {
  for (char& c : name)
    if (c == '/' || c == '\0') c = '_';
  return name == "." || name == ".." ? "_" : name;
}

bool is_flying(const LiveFlight& f) { return f.started && f.runner->running(); }

}  // namespace

Trainer::Trainer(FlyOptions o) : options_(std::move(o)) {
  input_settings_path_ =
      options_.input_settings.empty() ? input::default_settings_path() : options_.input_settings;
  input_settings_ = load_input_settings(input_settings_path_, input_.note);
  if (!input_.note.empty())
    say(input_settings_path_.empty()  // no home folder: the note says so
            ? input_.note
            : input_settings_path_ + " has errors: the default input settings are used (I shows them)",
        true);
  first_record_ = options_.record;
  choices_.record = !options_.record.empty();
  scenario_paths_ = shipped_scenarios();
  for (const std::string& p : scenario_paths_) choices_.scenarios.push_back(fs::path(p).stem().string());
  if (!options_.scenario_path.empty()) {
    const std::string mine = absolute_path(options_.scenario_path);
    const auto it = std::find(scenario_paths_.begin(), scenario_paths_.end(), mine);
    if (it == scenario_paths_.end()) {
      scenario_paths_.push_back(mine);
      choices_.scenarios.push_back(fs::path(mine).filename().string());
      choices_.scenario = int(scenario_paths_.size()) - 1;
    } else {
      choices_.scenario = int(it - scenario_paths_.begin());
    }
  }
}

Trainer::~Trainer() {
  if (live_ && !live_->closed) close_live(*live_);
  if (replay_) replay_->stop();
}

std::string Trainer::next_record_path() const {
  if (!first_record_.empty()) return first_record_;
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  std::string name = live_ ? live_->flight.mode->scenario_name() : "flight";
  if (live_ && !live_->flight.pilot.empty() && !live_->flight.recording)
    name += "-" + live_->flight.pilot;
  const fs::path folder = recordings_folder();
  if (folder.empty()) return "";
  return (folder / file_name_part(name + "-" + stamp + ".mcap")).string();
}

std::shared_ptr<input::Gamepad> Trainer::gamepad(std::string& error) {
  if (gamepad_) return gamepad_;
  auto g = std::make_shared<input::Gamepad>();
  input::Gamepad::Options go;
  go.preferred = input_settings_.gamepad;
  go.mappings_file = input::user_mappings_path();
  if (!g->start(go, error)) return nullptr;
  if (!g->mappings_note().empty()) {
    std::fprintf(stderr, "mixpilot: %s\n", g->mappings_note().c_str());
    say(go.mappings_file + " was left out (see the terminal); SDL's built-in mappings apply", true);
  }
  return gamepad_ = std::move(g);
}

std::unique_ptr<LiveFlight> Trainer::make_live(std::string& error, int& status) {
  auto f = std::make_unique<LiveFlight>();
  FlyOptions o = options_;
  o.replay = o.pilot.ends_with(".mcap");  // a recording's pilot: any mode flies it again
  o.input_values = input_settings_;
  std::shared_ptr<input::Gamepad> pad;
  if (o.pilot == "gamepad") {
    // A script's virtual pad must exist before SDL's pads are listed: the flight plugs it.
    if (o.gamepad_script.empty() && !(pad = gamepad(error))) return nullptr;
  }
  // The window never waits for a remote vehicle: update_vehicle_wait() listens frame by frame.
  std::optional<Flight> flight = prepare_flight(o, error, status, pad, VehicleWait::later);
  if (!flight) return nullptr;
  f->flight = std::move(*flight);
  if (f->flight.vehicle) {
    f->awaiting_vehicle = true;
    f->vehicle_deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(o.vehicle_wait_s));
  }
  if (f->flight.devices && f->flight.devices->gamepad) gamepad_ = f->flight.devices->gamepad;
  Mode& mode = *f->flight.mode;
  f->session = std::make_unique<Session>(mode);
  if (f->flight.devices) {
    f->haptic.emplace(*f->flight.devices);
    f->session->add_sink(&*f->haptic);
  }
  if (f->flight.recording) {
    f->check.emplace(*f->flight.recording);
    f->session->add_sink(&*f->check);
  }
  if (o.publish) {
    f->publisher.emplace();
    if (!f->publisher->start(o.domain, mode.telemetry(), error)) {
      error = "--publish: " + error;
      status = kExitError;
      return nullptr;
    }
    f->session->add_sink(&*f->publisher);
  }
  f->runner = std::make_unique<RealtimeRunner>(*f->session, 8192);
  const std::string source =
      f->flight.pilot.empty() ? std::string("the thesis's controller") : "pilot " + f->flight.pilot;
  f->scene = ui::scene_of(mode, source);
  f->sample = mode.telemetry();
  return f;
}

bool Trainer::open_live(std::string& error, int& status) {
  live_ = make_live(error, status);
  refresh_choices();
  return live_ != nullptr;
}

bool Trainer::replace_live(std::string& error) {
  int status = 0;
  auto next = make_live(error, status);
  if (!next) return false;
  if (live_ && !live_->closed) close_live(*live_);
  live_ = std::move(next);
  refresh_choices();
  return true;
}

void Trainer::refresh_choices() {
  choices_.pilots.clear();
  choices_.pilot = -1;
  if (!live_) return;
  if (ModeIdentity id = live_->flight.mode->identity(); !id.pilot.empty()) {
    choices_.pilots = std::move(id.pilots);
    choices_.pilots.push_back("gamepad");
    choices_.pilots.push_back("keyboard");
    if (options_.pilot.ends_with(".mcap")) choices_.pilots.push_back(options_.pilot);
    const auto it = std::find(choices_.pilots.begin(), choices_.pilots.end(),
                              options_.pilot.empty() ? live_->flight.pilot : options_.pilot);
    choices_.pilot = it == choices_.pilots.end() ? -1 : int(it - choices_.pilots.begin());
  }
  choices_.record_to = choices_.record ? next_record_path() : "";
}

void Trainer::close_live(LiveFlight& f) {
  f.runner->stop();
  while (f.runner->telemetry().pop(f.sample)) f.history.push(f.sample);
  if (f.publisher) {
    f.publisher->stop();
    if (f.started)
      say("published " + std::to_string(f.publisher->published()) + " steps on rt/mixpilot/* (domain " +
              std::to_string(options_.domain) + "; " + std::to_string(f.publisher->dropped()) + " dropped)",
          f.publisher->dropped() > 0);
  }
  if (!f.record_path.empty()) {
    std::string error;
    if (f.recorder.close(error, !f.flight.mode->finished())) {
      if (f.record_path == first_record_) first_record_.clear();
      const std::int64_t dropped = f.recorder.dropped();
      const std::string what =
          f.record_path +
          (dropped ? " (" + std::to_string(dropped) + " steps lost: the disk was too slow)" : "");
      recorded_.push_back(what);
      say("recorded " + what, dropped > 0);
    } else {
      say(error, true);
      status_ = kExitError;
    }
  }
  f.closed = true;
}

void Trainer::start() {
  if (replay_) {
    replay_info_.playing = true;
    return;
  }
  if (!live_ || live_->started) return;
  if (live_->awaiting_vehicle || live_->no_vehicle) return;  // the status line says why
  // A gamepad pilot starts once a pad is connected (the banner asks for one meanwhile).
  if (live_->flight.devices && live_->flight.devices->gamepad &&
      !live_->flight.devices->gamepad->connected()) {
    live_->waiting = true;
    return;
  }
  live_->waiting = false;
  if (choices_.record) {
    const std::string path = next_record_path();
    if (path.empty()) {
      std::string why;
      recordings_folder(&why);
      say("cannot record: no folder for recordings (" + why + "); set XDG_DATA_HOME or fly "
          "without recording", true);
      return;
    }
    std::error_code ec;
    if (path != options_.record) fs::create_directories(fs::path(path).parent_path(), ec);
    RecordingSink::Settings rs;
    rs.when_full = RecordingSink::FullRing::drop;  // the control thread never waits on the disk
    rs.slots = 4096;
    std::string error;
    if (!live_->recorder.open(path, *live_->flight.mode,
                              session_info(live_->flight, choices_.trainee), error, rs,
                              path == options_.record && options_.force)) {
      say(error, true);
      return;
    }
    live_->record_path = path;
    live_->session->add_sink(&live_->recorder);
  }
  live_->history.clear();  // the initial state shown while ready
  if (live_->flight.devices) live_->flight.devices->started();
  live_->runner->start();
  live_->started = true;
  say("");
}

void Trainer::say(std::string message, bool error) {
  run_.message = std::move(message);
  run_.message_is_error = error;
}

bool Trainer::open_replay(const std::string& path, std::string& error) {
  FlyOptions o;
  o.pilot = path;
  o.replay = true;
  o.command = options_.command;
  int status = 0;
  std::optional<Flight> flight = prepare_flight(o, error, status);
  if (!flight) return false;
  if (live_ && !live_->closed) close_live(*live_);
  replay_ = std::make_unique<ReplayTape>(std::move(*flight), path);
  replay_->start();
  replay_info_ = ui::ReplayInfo{};
  replay_info_.duration = double(replay_->steps()) * replay_->dt();
  replay_events_final_ = false;
  ui_.score_card_closed = false;
  return true;
}

void Trainer::update_vehicle_wait(LiveFlight& f) {
  const auto now = std::chrono::steady_clock::now();
  std::string error;
  if (f.flight.vehicle->heard()) {
    f.awaiting_vehicle = false;
    if (attach_vehicle(f.flight, error)) {
      say("the vehicle is there: Start (Space) flies it");
    } else {
      f.no_vehicle = true;
      say(error, true);
    }
  } else if (now >= f.vehicle_deadline) {
    f.awaiting_vehicle = false;
    f.no_vehicle = true;
    say(vehicle_not_heard(options_, f.flight) + "; Restart (R) waits again", true);
  } else {
    char text[160];
    std::snprintf(text, sizeof text,
                  "waiting for the vehicle in DDS domain %u (mixpilot vehicle): %.0f s left, Esc "
                  "cancels",
                  unsigned(options_.domain),
                  std::ceil(std::chrono::duration<double>(f.vehicle_deadline - now).count()));
    say(text);
  }
}

void Trainer::update_live() {
  LiveFlight& f = *live_;
  if (f.awaiting_vehicle) update_vehicle_wait(f);
  if (!f.closed) {
    while (f.runner->telemetry().pop(f.sample)) {
      f.history.push(f.sample);
      ui::count_step(f.sample, f.counts);
    }
  }
  const Mode& mode = *f.flight.mode;
  // Before the start the screen shows the initial state: the arena, the vehicle, the reference.
  if (!f.started && f.history.empty()) f.history.push(mode.telemetry());
  const bool over = f.started && !f.runner->running();
  // The run is over: its recording is completed at once, and the score card shows.
  if (over && !f.closed) close_live(f);
  if (over && f.metrics.empty())
    f.metrics = f.flight.recording ? replay_metrics(mode, *f.flight.recording)
                                   : with_lost_fields(mode.metrics(), mode);
  run_.state = f.awaiting_vehicle ? ui::RunState::waiting
               : !f.started ? ui::RunState::ready
               : mode.lost() ? ui::RunState::lost
               : over ? ui::RunState::finished
               : f.runner->paused() ? ui::RunState::paused
                                    : ui::RunState::flying;
  run_.speed = f.runner->speed();
  run_.deadline_misses = f.counts.deadline_misses;
  run_.fallbacks = f.counts.fallbacks;
  run_.recording = !f.record_path.empty() && !f.closed;
  run_.can_restart = true;
  run_.metrics = f.metrics;
  run_.replay = nullptr;
  run_.session = &choices_;
}

void Trainer::update_replay(double wall_dt) {
  ReplayTape& r = *replay_;
  ui::ReplayInfo& info = replay_info_;
  const std::size_t ready = r.ready();
  info.duration = double(r.steps()) * r.dt();
  info.loaded = r.steps() ? double(ready) / double(r.steps()) : 1.0;
  if (r.done()) info.loaded = 1.0;
  const double last = ready ? double(ready - 1) * r.dt() : 0.0;
  if (info.playing) {
    info.t += wall_dt * replay_speed_;
    if (info.t >= last) {
      info.t = last;
      if (r.done()) info.playing = false;  // at the end
    }
  }
  if (r.done() && !replay_events_final_) {
    info.events = ui::timeline_events(ui::History::view(r.tape(), ready), info.lambda_threshold);
    replay_events_final_ = true;
    if (!r.mismatch().empty() && r.mismatch() != "interrupted")
      say("the replay differs from the recording: " + r.mismatch(), true);
  }
  run_.state = r.done() ? ui::RunState::replay : ui::RunState::loading;
  run_.speed = replay_speed_;
  run_.deadline_misses = 0;
  run_.fallbacks = 0;
  const std::size_t k = tape_index(r, info.t);
  // The replay marks the recorded flight's overruns and deadline misses (Mode::replay_timing):
  // the tape counts what the flight counted.
  for (std::size_t i = 0; i < ready && i <= k; ++i) ui::count_step(r.tape()[i], run_);
  run_.recording = false;
  run_.can_restart = false;
  run_.metrics = r.done() && ready > 0 && k + 1 >= ready ? r.metrics() : Metrics{};
  run_.replay = &info;
  run_.session = nullptr;
}

void Trainer::update_input() {
  const Devices* d = live_ ? live_->flight.devices.get() : nullptr;
  input_.pilot = d ? (d->keyboard ? "keyboard" : "gamepad") : "";
  input_.waiting = live_ && live_->waiting;
  input_.settings = &input_settings_;
  input_.settings_path = input_settings_path_;
  if (d && d->keyboard) {
    input_.connected = true;
    input_.device = "keyboard";
  }
  // The settings panel lists SDL's joysticks, whatever flies.
  if (!gamepad_ && ui_.show_settings && !gamepad_failed_) {
    std::string error;
    if (!gamepad(error)) {  // said once; SDL is not asked again every frame
      input_.message = error;
      gamepad_failed_ = true;
    }
  }
  if (gamepad_) {
    if (!d || !d->keyboard) {
      input_.connected = gamepad_->connected();
      input_.device = gamepad_->active_name();
      input_.live = gamepad_->latest_for_ui().sticks;
    }
    input_.devices.clear();
    input_.active = -1;
    for (const input::GamepadInfo& g : gamepad_->devices()) {
      input_.devices.push_back({g.instance, g.name, g.controller});
      if (g.controller && g.name == gamepad_->active_name()) input_.active = g.instance;
    }
  }
  if (wizard_ && gamepad_) {
    wizard_raw_ = gamepad_->raw();
    wizard_->feed(wizard_raw_);
    ui::WizardView& w = input_.wizard.emplace();
    w.device = wizard_device_;
    w.step = wizard_->current();
    w.steps = wizard_->steps().size();
    w.done = wizard_->done();
    if (!w.done) {
      w.prompt = wizard_->steps()[w.step].prompt;
      w.optional = wizard_->steps()[w.step].optional;
    }
    w.hint = wizard_->hint();
    w.bindings = wizard_->bindings();
    w.mapping = wizard_->mapping();
    w.raw = &wizard_raw_;
  } else {
    input_.wizard.reset();
  }
  if (gamepad_ && !wizard_) {
    std::string error;
    const int added = gamepad_->mapping_status(error);
    if (added < 0) input_.message = error;
  }
  run_.input = &input_;
  // A flight waiting for its gamepad starts when one arrives.
  if (live_ && live_->waiting && input_.connected) start();
}

void Trainer::build_frame(double wall_dt) {
  update_input();
  if (replay_) update_replay(wall_dt);
  else if (live_) update_live();
  static const ui::Scene kEmpty;
  static const ui::History kNothing;
  ui::UiRequest req;
  if (replay_) {
    const std::size_t n = replay_->ready();
    const ui::History view =
        ui::History::view(replay_->tape(), n ? tape_index(*replay_, replay_info_.t) + 1 : 0);
    req = ui::draw_screen(replay_->scene(), view, run_, ui_);
  } else if (live_) {
    req = ui::draw_screen(live_->scene, live_->history, run_, ui_);
  } else {
    req = ui::draw_screen(kEmpty, kNothing, run_, ui_);
  }
  act(req);
}

void Trainer::act(const ui::UiRequest& req) {
  std::string error;
  if (req.cancel_wait && live_ && live_->awaiting_vehicle) {
    live_->awaiting_vehicle = false;
    live_->no_vehicle = true;
    say("no vehicle: the wait was cancelled; Restart (R) waits again");
  }
  if (!req.open.empty()) {
    if (req.open.ends_with(".mcap")) {
      if (!open_replay(req.open, error)) say(error, true);
    } else {
      const std::string p = absolute_path(req.open);
      auto it = std::find(scenario_paths_.begin(), scenario_paths_.end(), p);
      if (it == scenario_paths_.end()) {
        scenario_paths_.push_back(p);
        choices_.scenarios.push_back(fs::path(p).filename().string());
        it = scenario_paths_.end() - 1;
      }
      replay_.reset();
      const FlyOptions before = options_;
      options_.scenario_path = p;
      if (!options_.pilot.ends_with(".mcap")) options_.pilot.clear();
      if (replace_live(error)) choices_.scenario = int(it - scenario_paths_.begin());
      else { options_ = before; say(error, true); }
    }
    return;
  }
  if (replay_) {
    ui::ReplayInfo& info = replay_info_;
    if (req.start) start();
    if (req.toggle_pause) {
      if (!info.playing && replay_->done() && info.t >= double(replay_->ready() - 1) * replay_->dt())
        info.t = 0.0;  // played to the end: Play starts it again
      info.playing = !info.playing;
    }
    if (req.speed > 0) replay_speed_ = std::clamp(req.speed, 0.25, 8.0);
    // The playhead stays on a step that is ready: the last one is at (ready − 1) Δt.
    const double last = replay_->ready() ? double(replay_->ready() - 1) * replay_->dt() : 0.0;
    if (req.seek >= 0) info.t = std::min(req.seek, last);
    if (req.jump != 0) {
      const double t = ui::event_after(info.events, info.t, req.jump);
      if (t >= 0) info.t = t;
    }
    if (req.lambda_threshold >= 0) {
      info.lambda_threshold = req.lambda_threshold;
      replay_events_final_ = false;
    }
    if (req.leave_replay) {
      replay_.reset();
      say("");
      if (!live_ || live_->closed) {
        if (!options_.scenario_path.empty() || options_.pilot.ends_with(".mcap")) {
          if (!replace_live(error)) say(error, true);
        } else {
          live_.reset();
        }
      }
    }
    return;
  }
  act_on_input(req);
  if (req.apply_settings) {
    input_settings_ = ui_.draft;
    if (req.save_settings) {
      if (input::save_settings(input_settings_path_, input_settings_, error)) {
        input_.note.clear();
        say("input settings saved to " + input_settings_path_);
      } else {
        say(error, true);
      }
    }
    options_.input_settings.clear();
    if (live_ && !is_flying(*live_) && live_->flight.devices && !replace_live(error)) say(error, true);
  }
  if (!live_) return;
  if (live_->flight.devices && live_->flight.devices->keyboard) {
    input::KeyboardSource& k = *live_->flight.devices->keyboard;
    for (int i = 0; i < int(input::Key::count); ++i)
      k.set_key(input::Key(i), (req.flight_keys >> i) & 1u);
  }
  if (req.trainee_changed) choices_.trainee = req.trainee;
  if (req.record >= 0 && !is_flying(*live_)) {
    choices_.record = req.record == 1;
    choices_.record_to = choices_.record ? next_record_path() : "";
  }
  if (req.scenario >= 0 && req.scenario < int(scenario_paths_.size()) && !is_flying(*live_)) {
    const FlyOptions before = options_;
    options_.scenario_path = scenario_paths_[std::size_t(req.scenario)];
    if (!options_.pilot.ends_with(".mcap")) options_.pilot.clear();
    if (replace_live(error)) choices_.scenario = req.scenario;
    else { options_ = before; say(error, true); }
  }
  if (req.pilot >= 0 && req.pilot < int(choices_.pilots.size()) && !is_flying(*live_)) {
    const FlyOptions before = options_;
    options_.pilot = choices_.pilots[std::size_t(req.pilot)];
    if (!replace_live(error)) { options_ = before; say(error, true); }
  }
  if (req.start) start();
  if (req.toggle_pause && is_flying(*live_)) live_->runner->set_paused(!live_->runner->paused());
  if (req.speed > 0) live_->runner->set_speed(std::clamp(req.speed, 0.25, 1.0));
  if (req.restart) {
    const double speed = live_->runner->speed();
    if (replace_live(error)) {
      live_->runner->set_speed(speed);
      start();
    } else {
      say(error, true);
    }
  }
}

void Trainer::act_on_input(const ui::UiRequest& req) {
  if (!gamepad_) return;
  if (req.use_gamepad >= -1) gamepad_->choose(req.use_gamepad);
  if (req.map_gamepad >= 0) {
    for (const input::GamepadInfo& g : gamepad_->devices()) {
      if (g.instance != req.map_gamepad) continue;
      wizard_.emplace(input_settings_.mode, g.guid, g.name);
      wizard_device_ = g.name;
      gamepad_->watch(g.instance);
      input_.message.clear();
    }
  }
  if (!wizard_) return;
  if (req.wizard_skip) (void)wizard_->skip();
  if (req.wizard_back) wizard_->back();
  if (req.wizard_save) {
    const std::string line = wizard_->mapping();
    const std::string path = input::user_mappings_path();
    std::string error;
    if (line.empty()) return;
    if (input::save_mapping(path, line, error)) {
      gamepad_->add_mapping(line);
      input_.message = wizard_device_ + " is mapped (saved in " + path + ").";
    } else {
      input_.message = error;
    }
  }
  if (req.wizard_save || req.wizard_cancel) {
    gamepad_->watch(-1);
    wizard_.reset();
    input_.wizard.reset();
  }
}

bool Trainer::over() const {
  if (replay_) {
    const std::size_t n = replay_->ready();
    return replay_->done() && (n == 0 || tape_index(*replay_, replay_info_.t) + 1 >= n);
  }
  if (!live_) return true;
  return live_->started && !live_->runner->running() && live_->closed;
}

double Trainer::shown_time() const {
  if (replay_) return replay_->ready() ? replay_info_.t : -1.0;
  if (live_ && !live_->history.empty()) return live_->history.newest().t;
  return -1.0;
}

void Trainer::seek(double t) { replay_info_.t = std::max(0.0, t); }

void Trainer::load_replay() {
  if (replay_) replay_->fly();
}

int Trainer::finish() {
  int status = status_;
  if (replay_) {
    replay_->stop();
    std::printf("mixpilot %s: %s", options_.command, replay_->mode().summary().c_str());
    const std::string& diff = replay_->mismatch();
    if (diff.empty()) {
      std::printf("  replay exact: every recorded step reproduced bit for bit\n");
    } else if (diff != "interrupted") {
      std::fprintf(stderr, "mixpilot %s: the replay of %s differs from the recording: %s\n",
                   options_.command, replay_->path().c_str(), diff.c_str());
      if (!options_.allow_mismatch && status == kExitOk) status = kExitReplayMismatch;
    }
    return status;
  }
  if (!live_) return status;
  LiveFlight& f = *live_;
  if (!f.closed) close_live(f);
  while (f.runner->telemetry().pop(f.sample)) f.history.push(f.sample);
  const Mode& mode = *f.flight.mode;
  if (!f.started || mode.steps_done() == 0) {
    // The window closed before Start: no flight, so no score (a 0.0 s flight is not one).
    std::printf("mixpilot %s: %s: not flown (the window was closed before Start)%s\n",
                options_.command, mode.scenario_name().c_str(),
                options_.report.empty() ? "" : "; no report written");
    for (const std::string& path : recorded_) std::printf("  recorded %s\n", path.c_str());
    return status;
  }
  std::printf("mixpilot %s: %s", options_.command, mode.summary().c_str());
  const RealtimeStats st = f.runner->stats();
  std::printf("  %.1f s flown in the window\n", double(mode.steps_done()) * mode.dt());
  print_realtime(st, mode.dt());
  if (mode.lost()) std::printf("  LOST: the vehicle was lost at t = %.3f s\n", mode.lost_at());
  for (const std::string& path : recorded_) std::printf("  recorded %s\n", path.c_str());
  if (f.publisher)
    std::printf("  published %llu steps on rt/mixpilot/* (domain %u; %llu dropped)\n",
                (unsigned long long)f.publisher->published(), unsigned(options_.domain),
                (unsigned long long)f.publisher->dropped());
  if (!options_.report.empty()) {
    const Metrics metrics = f.flight.recording ? replay_metrics(mode, *f.flight.recording)
                                               : with_lost_fields(mode.metrics(), mode);
    const std::string json =
        to_json(report_labels(f.flight, !mode.finished()), metrics) + "\n";
    std::string error;
    if (write_file(options_.report, json, options_.force, error)) {
      std::printf("  report %s\n", options_.report.c_str());
    } else {
      std::fprintf(stderr, "mixpilot %s: %s\n", options_.command, error.c_str());
      status = kExitError;
    }
  }
  if (f.check && mode.finished()) {
    const std::string diff = f.check->first_difference(mode.steps_done());
    if (!diff.empty()) {
      std::fprintf(stderr, "mixpilot %s: the replay of %s differs from the recording: %s\n",
                   options_.command, options_.pilot.c_str(), diff.c_str());
      if (!options_.allow_mismatch && status == kExitOk) status = kExitReplayMismatch;
    }
  }
  return status;
}

}  // namespace mixpilot::cli
