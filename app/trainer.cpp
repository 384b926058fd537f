#include "app/trainer.hpp"

#include <algorithm>

#include "ui/first_launch.hpp"

namespace mixpilot::cli {

Trainer::Trainer(FlyOptions o)
    : input_(o.input_settings, status_),
      history_(o.history == "off" ? nullptr : std::make_unique<HistoryWriter>(o.history)),
      live_(o, input_, status_, history_.get()),
      replay_(o.command, o.allow_mismatch, status_, o.replay ? o.ghost : std::string()) {
  std::string note;
  window_settings_ = load_window_settings("", note);
  if (!note.empty()) status_.say(note, true);
  welcome_pending_ = o.first_launch && !o.replay && !window_settings_.welcome_dismissed;
}

void Trainer::update_welcome() {
  if (!welcome_pending_ || replay_.is_open() || !live_.flight()) return;
  // "No flight yet": the history read and it knows no trainee (every flight has one). Without
  // a history (--history off) there is nothing to ask: the welcome shows.
  if (history_) {
    if (!history_view_ || !history_view_->loaded) return;
    if (!history_view_->trainees.empty()) {
      welcome_pending_ = false;
      return;
    }
  }
  welcome_pending_ = false;
  ui::show_welcome(ui_);
}

void Trainer::first_launch(const ui::FirstLaunchChoice& c) {
  switch (c.way) {
    case ui::WayIn::watch:
      live_.handle(ui::FlyWith{"mi_helix", "novice"});
      break;
    case ui::WayIn::fly:
      live_.handle(ui::FlyWith{"mi_helix", ui::found_gamepad(run_).empty() ? "keyboard" : "gamepad"});
      break;
    case ui::WayIn::course:
      if (!c.trainee.empty()) live_.handle(ui::SetTrainee{c.trainee});
      live_.handle(ui::ChooseLesson{"beginner"});
      break;
  }
}

void Trainer::save_window_settings(const char* what) {
  std::string error;
  if (!cli::save_window_settings("", window_settings_, error))
    status_.say(std::string("could not keep ") + what + " for the next start: " + error, true);
}

bool Trainer::open_live(std::string& error, int& status) { return live_.open(error, status); }

bool Trainer::open_replay(const std::string& path, std::string& error) {
  std::unique_ptr<FlightRig> rig = replay_.prepare(path, error);
  if (!rig) return false;
  take_over_.reset();  // of the replay this one replaces
  live_.close();  // its recording is completed before the replay loads
  replay_.open(std::move(rig), path);
  ui_.score_card_closed = false;
  return true;
}

void Trainer::start() {
  if (replay_.is_open()) replay_.play();
  else live_.start();
}

void Trainer::build_frame(double wall_dt) {
  const LiveFlight* f = live_.flight();
  // The settings panel and the welcome name the gamepads SDL sees.
  input_.update(f ? f->flight().devices.get() : nullptr, f && f->waiting,
                ui_.show_settings || ui_.first_launch == ui::FirstLaunch::welcome,
                wizard_.running());
  wizard_.update(input_.started(), input_.info().wizard);
  run_.input = &input_.info();
  poll_history();
  clips_.poll();
  poll_take_over();
  if (replay_.is_open()) replay_.update(wall_dt, run_);
  else if (live_.flight()) live_.update(input_.info().connected, run_);
  update_welcome();
  run_.text_scale = window_settings_.text_scale;
  update_card();
  requests_.clear();
  if (replay_.is_open()) {
    ui::draw_screen(replay_.scene(), replay_.shown(), run_, ui_, requests_);
  } else if (const LiveFlight* live = live_.flight()) {
    ui::draw_screen(live->scene, live->history, run_, ui_, requests_);
  } else {
    static const ui::Scene kEmpty;
    static const ui::History kNothing;
    ui::draw_screen(kEmpty, kNothing, run_, ui_, requests_);
  }
  for (const ui::Request& r : requests_) act(r);
}

void Trainer::act(const ui::Request& r) {
  std::visit(ui::overloaded{
                 // The live flight's requests while it is on screen (a replay is not).
                 [&](const ui::LiveRequest& l) {
                   if (!replay_.is_open()) live_.handle(l);
                 },
                 [&](const ui::ReplayRequest& p) { replay_.handle(p); },
                 [&](const ui::InputRequest& i) {
                   if (input_.handle(i)) live_.settings_changed();
                 },
                 [&](const ui::WizardRequest& w) {
                   // The wizard reads SDL's joysticks through the app's gamepad.
                   if (input::Gamepad* pad = input_.started())
                     wizard_.handle(w, *pad, input_.settings().mode, input_.info().message);
                 },
                 [&](const ui::AppRequest& a) {
                   std::visit(ui::overloaded{
                                  [&](const ui::OpenFile& o) { open_file(o.path); },
                                  [&](const ui::LeaveReplay&) { leave_replay(); },
                                  [&](const ui::ExportClip& c) {
                                    if (const ReplayTape* tape = replay_.tape())
                                      (void)clips_.start(tape->path(), c.from, c.to);
                                  },
                                  [&](const ui::ReplayRecording& p) {
                                    // As File → Open of that recording.
                                    std::string error;
                                    if (open_replay(p.path, error)) ui_.show_progress = false;
                                    else status_.say(error, true);
                                  },
                                  [&](const ui::FlyFromHere&) { fly_from_here(); },
                                  [&](const ui::FirstLaunchChoice& c) { first_launch(c); },
                                  [&](const ui::FirstLaunchDone&) {
                                    welcome_pending_ = false;
                                    if (window_settings_.welcome_dismissed) return;
                                    window_settings_.welcome_dismissed = true;
                                    save_window_settings("that the welcome was seen (it will "
                                                         "show again)");
                                  },
                                  [&](const ui::SetTextScale& t) {
                                    window_settings_.text_scale =
                                        std::clamp(t.scale, kMinTextScale, kMaxTextScale);
                                    save_window_settings("the text size");
                                  },
                              },
                              a);
                 },
             },
             r);
}

void Trainer::open_file(const std::string& path) {
  if (path.ends_with(".mcap")) {
    std::string error;
    if (!open_replay(path, error)) status_.say(error, true);
    return;
  }
  replay_.close();
  live_.open_scenario(path);
}

void Trainer::poll_history() {
  if (!history_) return;
  outcomes_.clear();
  if (history_->poll(outcomes_))
    for (const HistoryWriter::Outcome& o : outcomes_) live_.history_outcome(o);
  history_view_ = history_->view();
  run_.history = history_view_.get();
}

void Trainer::fly_from_here() {
  if (take_over_ || !replay_.is_open()) return;
  const std::int64_t k = replay_.fly_from_here();
  if (k < 0) return;
  take_over_ = std::make_unique<TakeOver>(replay_.tape()->path(), k);
  replay_.set_taking_over(0.0);
}

void Trainer::poll_take_over() {
  if (!take_over_) return;
  if (!take_over_->done()) {
    replay_.set_taking_over(take_over_->progress());
    return;
  }
  replay_.set_taking_over(-1.0);
  const std::unique_ptr<TakeOver> done = std::move(take_over_);
  const std::shared_ptr<const FlyFrom> moment = done->moment();
  if (!moment) {
    status_.say(done->error(), true);
    return;
  }
  // The screen shows the replay's steps up to the moment with the new flight, READY there.
  const ui::History so_far = ui::History::view(replay_.tape()->tape(), std::size_t(done->step()) + 1);
  if (!live_.fly_from(moment, so_far, input_.info().connected)) return;
  replay_.close();
  ui_.score_card_closed = false;
}

void Trainer::leave_replay() {
  if (!replay_.is_open()) return;
  take_over_.reset();
  replay_.close();
  status_.say("");
  live_.reopen();
}

void Trainer::update_card() {
  const LiveFlight* f = replay_.is_open() ? nullptr : live_.flight();
  if (run_.metrics.empty() || (!f && !replay_.is_open())) {
    run_.card = nullptr;
    card_for_ = {};
    return;
  }
  const std::vector<ui::DebriefRow>& events = f ? f->events : run_.replay->events;
  CardKey key;
  key.flight = f ? static_cast<const void*>(f) : static_cast<const void*>(replay_.tape());
  key.metrics = run_.metrics.size();
  key.events = events.data();
  key.event_count = events.size();
  key.events_ready = f ? f->events_ready : run_.replay->events_ready;
  key.history = history_view_.get();
  if (f && f->closing.verdict && run_.session) key.verdict = run_.session->lesson_view.verdict;
  run_.card = &card_;
  if (key == card_for_) return;
  card_for_ = key;
  ui::FlightOutcome o;
  o.metrics = run_.metrics;
  o.events = events;
  o.events_ready = key.events_ready;
  o.history = history_view_.get();
  const ui::Scene& scene = f ? f->scene : replay_.scene();
  o.mode = scene.mode;
  o.probe = scene.probe;
  o.scenario = scene.title;
  if (f) {
    o.trainee = f->rig->trainee().empty() ? history::login_name() : f->rig->trainee();
    o.started_unix_ms = f->rig->started_unix_ms();
    // A lesson step's attempt: the panel's view holds its verdict.
    if (f->closing.verdict && run_.session) o.lesson = &run_.session->lesson_view;
  } else {
    // A replay is compared when its recording is among the flights of the trainee shown.
    o.replay = true;
    o.recording = replay_.tape()->path();
    if (history_view_) o.trainee = history_view_->progress.trainee;
  }
  card_ = ui::score_card_of(o);
}

bool Trainer::over() const { return replay_.is_open() ? replay_.over() : live_.over(); }

double Trainer::shown_time() const {
  return replay_.is_open() ? replay_.shown_time() : live_.shown_time();
}

int Trainer::finish() {
  if (replay_.is_open()) return replay_.finish(live_.status());
  return live_.finish();
}

}  // namespace mixpilot::cli
