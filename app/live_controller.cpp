#include "app/live_controller.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <system_error>

#include "app/cli.hpp"
#include "app/progress.hpp"
#include "core/modes/report.hpp"
#include "core/scenario/data_files.hpp"
#include "core/scenario/scenario_toml.hpp"

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

bool is_flying(const LiveFlight& f) { return f.started() && f.runner().running(); }

// Whether the scenario at `path` is flown by a pilot (mixed initiative); false when it cannot
// be read (assembling the flight then says why).
bool has_pilot(const std::string& path) {
  std::string text, error;
  if (!read_text_file(path, text, error)) return false;
  const std::optional<std::string> mode = scenario_mode(text, path, error);
  return mode && *mode == "mixed_initiative";
}

// "from REC.mcap at t = 10.00 s": where a flight flown from here goes on from.
std::string fly_from_text(const FlyFrom& from) {
  char at[48];
  std::snprintf(at, sizeof at, " at t = %.2f s", from.t);
  return "from " + fs::path(from.parent).filename().string() + at;
}

// At most this many of the recorded steps before the moment are shown with a flight flown
// from it: a minute of the trail and the plots at Δt = 15 ms.
constexpr std::size_t kShownBeforeTheMoment = 4096;

}  // namespace

// ---- The flight's assembly ---------------------------------------------------------------
// A live flight is a FlightRig (app/flight_rig.hpp) paced on the control thread, with what the
// screen keeps of it.

std::unique_ptr<LiveFlight> LiveController::make_live(std::string& error, int& status) {
  auto f = std::make_unique<LiveFlight>();
  FlyOptions o = options_;
  o.from = from_;  // fly from here: fly_from() chose a live pilot
  o.replay = !from_ && o.pilot.ends_with(".mcap");  // a recording's pilot: any mode flies it again
  if (from_) o.duration.reset();  // as long as the flight it goes on from
  // The assistance chosen applies to new flights with a pilot: a recording's pilot flies as it
  // was recorded, and the thesis's controllers have no pilot to leave alone.
  if (o.replay || (o.assist == Assistance::off && !has_pilot(o.scenario_path))) o.assist.reset();
  o.input_values = input_.settings();
  std::shared_ptr<input::Gamepad> pad;
  if (o.pilot == "gamepad") {
    // A script's virtual pad must exist before SDL's pads are listed: the flight plugs it.
    if (o.gamepad_script.empty() && !(pad = input_.gamepad(error))) return nullptr;
  }
  // The window never waits for a remote vehicle: update_vehicle_wait() polls it frame by frame.
  f->rig = FlightRig::assemble(o, error, status, pad, VehicleWait::later);
  if (!f->rig) return nullptr;
  f->awaiting_vehicle = f->rig->poll_vehicle(error) == FlightRig::VehicleStatus::waiting;
  const Flight& flight = f->rig->flight();
  if (flight.devices && flight.devices->gamepad) input_.adopt(flight.devices->gamepad);
  if (o.publish && !f->rig->publish(error)) {
    status = kExitError;
    return nullptr;
  }
  if (o.lesson.active()) {
    for (const Lesson& l : lessons_)
      if (l.name == o.lesson.lesson && l.hash == o.lesson.lesson_hash &&
          o.lesson.step < int(l.steps.size()))
        f->rig->judge_as(l.steps[std::size_t(o.lesson.step)]);
  }
  f->rig->pace(8192);
  const Mode& mode = f->rig->mode();
  f->debrief.setup(debrief_settings(mode));
  std::string source = flight.pilot.empty() ? std::string("the thesis's controller")
                                             : "pilot " + flight.pilot;
  if (from_) source += ", " + fly_from_text(*from_);
  f->scene = ui::scene_of(mode, source);
  std::string no_ghost;  // a mode without one: the session panel offers none
  f->ghost_target = ghost_target(flight, no_ghost);
  ++flights_made_;
  f->sample = mode.telemetry();
  // Fly from here: READY at the moment, after the recorded steps that led there.
  for (const Telemetry& s : from_shown_) f->history.push(s);
  return f;
}

void LiveController::update_vehicle_wait(LiveFlight& f) {
  std::string error;
  switch (f.rig->poll_vehicle(error)) {
    case FlightRig::VehicleStatus::waiting: {
      char text[160];
      std::snprintf(text, sizeof text,
                    "waiting for the vehicle in DDS domain %u (mixpilot vehicle): %.0f s left, "
                    "Esc cancels",
                    unsigned(options_.domain), std::ceil(f.rig->vehicle_wait_left()));
      status_line_.say(text);
      return;
    }
    case FlightRig::VehicleStatus::ready:
      f.awaiting_vehicle = false;
      status_line_.say("the vehicle is there: Start (Space) flies it");
      return;
    case FlightRig::VehicleStatus::none:
    case FlightRig::VehicleStatus::failed:
      f.awaiting_vehicle = false;
      f.no_vehicle = true;
      status_line_.say(error + "; Restart (R) waits again", true);
      return;
  }
}

void LiveController::close_live(LiveFlight& f) {
  f.rig->stop();
  while (f.runner().telemetry().pop(f.sample)) {
    f.history.push(f.sample);
    f.debrief.add(f.sample);
  }
  const bool flown = f.started();
  const FlightRig::Closed& c = f.closing = f.rig->close(!f.mode().finished());
  if (flown && f.rig->session().ended_by_instructor())
    status_line_.say("the instructor ended the flight", false);
  if (c.verdict && c.attempt) {
    // The lesson's verdict: said, shown in the panel, and the progress moved on at once (the
    // history's snapshot, reloaded once the attempt is written, says the same).
    verdict_ = *c.verdict;
    verdict_step_ = c.attempt->step;
    ++lesson_attempts_known_;
    if (lesson() && lesson()->hash == c.attempt->lesson_hash && lesson_step_ == c.attempt->step) {
      if (c.verdict->passed) {
        ++lesson_step_;
        lesson_failed_ = 0;
      } else {
        ++lesson_failed_;
      }
    }
    status_line_.say("step " + std::to_string(c.attempt->step + 1) +
                         (c.verdict->passed ? " passed" : " not passed: " + c.verdict->detail),
                     !c.verdict->passed);
  }
  if (c.published && flown)
    status_line_.say("published " + std::to_string(c.published_steps) +
                         " steps on rt/mixpilot/* (domain " + std::to_string(options_.domain) +
                         "; " + std::to_string(c.publish_dropped) + " dropped)",
                     c.publish_dropped > 0);
  if (!c.recorded.empty()) {
    if (c.recorded == first_record_) first_record_.clear();
    const std::string what =
        c.recorded +
        (c.dropped ? " (" + std::to_string(c.dropped) + " steps lost: the disk was too slow)" : "");
    recorded_.push_back(what);
    status_line_.say("recorded " + what, c.dropped > 0);
  } else if (!c.error.empty()) {
    status_line_.say(c.error, true);
    status_ = kExitError;
  }
}

void LiveController::history_outcome(const HistoryWriter::Outcome& o) {
  if (!o.remembered) {
    history_problem(o.error);
    return;
  }
  history_said_.clear();  // it works again: a new failure is news
  status_line_.add("remembered in the history (" + o.trainee + ", " + o.scenario + ")");
}

void LiveController::show_progress() {
  if (!history_ || !live_) return;
  std::string trainee = choices_.trainee.empty() ? history::login_name() : choices_.trainee;
  std::string scenario = live_->mode().scenario_name();
  if (trainee == shown_trainee_ && scenario == shown_scenario_) return;
  shown_trainee_ = trainee;
  shown_scenario_ = scenario;
  history_->show(std::move(trainee), std::move(scenario));
}

void LiveController::history_problem(const std::string& why) {
  if (why == history_said_) return;
  history_said_ = why;
  status_line_.say("history: " + why + "; flights are flown but not remembered", true);
}

int LiveController::finish() {
  int status = status_;
  if (!live_) return status;
  LiveFlight& f = *live_;
  if (!f.closed()) close_live(f);
  while (f.runner().telemetry().pop(f.sample)) f.history.push(f.sample);
  const Mode& mode = f.mode();
  if (!f.started() || mode.steps_done() == 0) {
    // The window closed before Start: no flight, so no score (a 0.0 s flight is not one).
    std::printf("mixpilot %s: %s: not flown (the window was closed before Start)%s\n",
                options_.command, mode.scenario_name().c_str(),
                options_.report.empty() ? "" : "; no report written");
    for (const std::string& path : recorded_) std::printf("  recorded %s\n", path.c_str());
    return status;
  }
  std::printf("mixpilot %s: %s", options_.command, mode.summary().c_str());
  const RealtimeStats st = f.runner().stats();
  // The runner's steps: a flight flown from a recording's moment starts there.
  std::printf("  %.1f s flown in the window%s\n", double(st.steps) * mode.dt(),
              f.flight().from ? (", " + fly_from_text(*f.flight().from)).c_str() : "");
  print_realtime(st, mode.dt());
  if (mode.lost()) std::printf("  LOST: the vehicle was lost at t = %.3f s\n", mode.lost_at());
  for (const std::string& path : recorded_) std::printf("  recorded %s\n", path.c_str());
  if (f.closing.published)
    std::printf("  published %llu steps on rt/mixpilot/* (domain %u; %llu dropped)\n",
                (unsigned long long)f.closing.published_steps, unsigned(options_.domain),
                (unsigned long long)f.closing.publish_dropped);
  std::fputs(station_summary(f.closing).c_str(), stdout);
  if (!options_.report.empty()) {
    const std::string json = to_json(f.rig->labels(!mode.finished()), f.rig->metrics()) + "\n";
    std::string error;
    if (write_file(options_.report, json, options_.force, error)) {
      std::printf("  report %s\n", options_.report.c_str());
    } else {
      std::fprintf(stderr, "mixpilot %s: %s\n", options_.command, error.c_str());
      status = kExitError;
    }
  }
  if (f.flight().recording && mode.finished()) {
    const std::string diff = f.rig->replay_difference();
    if (!diff.empty()) {
      std::fprintf(stderr, "mixpilot %s: the replay of %s differs from the recording: %s\n",
                   options_.command, options_.pilot.c_str(), diff.c_str());
      if (!options_.allow_mismatch && status == kExitOk) status = kExitReplayMismatch;
    }
  }
  return status;
}

// ---- The session: which flight, its start, its choices -----------------------------------

LiveController::LiveController(FlyOptions o, InputController& input, StatusLine& status,
                               HistoryWriter* history)
    : options_(std::move(o)), history_(history), input_(input), status_line_(status) {
  choices_.trainee = options_.trainee;  // --trainee: who flies (the session panel may change it)
  load_lessons();
  ghost_choice_ = GhostChoice::of(options_.ghost);
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

LiveController::~LiveController() { close(); }

// ---- Lessons (SPEC §10) --------------------------------------------------------------------

void LiveController::load_lessons() {
  // Their progress lives in the history: without one, no lessons.
  if (!history_) return;
  std::vector<std::string> files = shipped_lessons();
  const std::string mine =
      options_.lesson_file.empty() ? std::string() : absolute_path(options_.lesson_file);
  if (!mine.empty() && std::find(files.begin(), files.end(), mine) == files.end())
    files.push_back(mine);
  for (const std::string& file : files) {
    std::string error;
    std::optional<Lesson> l = load_lesson(file, error);
    if (!l) {
      status_line_.say("lesson " + error, true);
      continue;
    }
    if (file == mine) lesson_ = int(lessons_.size());
    lessons_.push_back(std::move(*l));
  }
  if (lessons_.empty()) return;
  choices_.lessons.push_back("none");
  for (const Lesson& l : lessons_) choices_.lessons.push_back(l.name);
}

void LiveController::show_lesson() {
  if (!history_ || !lesson()) return;
  const std::string trainee = choices_.trainee.empty() ? history::login_name() : choices_.trainee;
  history_->show_lesson(trainee, lesson()->name, lesson()->hash);
  lesson_for_ = trainee + '\n' + lesson()->name + '\n' + lesson()->hash;
  lesson_step_ = -1;  // until the snapshot says
  lesson_failed_ = 0;
  lesson_attempts_known_ = 0;
  lesson_seen_ = nullptr;
  lesson_made_for_ = -2;
  verdict_.reset();
  last_attempt_.reset();
}

void LiveController::pick_lesson(int index) {
  if (index < 0 || index >= int(choices_.lessons.size())) return;
  if (live_ && is_flying(*live_)) return;
  lesson_ = index - 1;
  choices_.lesson = index;
  if (lesson()) {
    show_lesson();  // the step's flight is made once the history says which step
    return;
  }
  // No lesson: the flights are the session panel's again, from the scenario chosen.
  const FlyOptions before = options_;
  options_.lesson = {};
  options_.bounds = {};
  options_.assist.reset();
  verdict_.reset();
  std::string error;
  if (!replace_live(error)) {
    options_ = before;
    status_line_.say(error, true);
  }
}

bool LiveController::fly_lesson_step(std::string& error) {
  const FlyOptions before = options_;
  if (options_.pilot.ends_with(".mcap")) options_.pilot.clear();
  options_ = lesson_flight(*lesson(), lesson_step_, options_);
  from_.reset();
  from_shown_.clear();
  if (replace_live(error)) {
    // The scenario the step flies, among the choices.
    const std::string file = absolute_path(options_.scenario_path);
    auto it = std::find(scenario_paths_.begin(), scenario_paths_.end(), file);
    if (it == scenario_paths_.end()) {
      scenario_paths_.push_back(file);
      choices_.scenarios.push_back(fs::path(file).filename().string());
      it = scenario_paths_.end() - 1;
    }
    choices_.scenario = int(it - scenario_paths_.begin());
    return true;
  }
  options_ = before;
  return false;
}

void LiveController::update_lesson(const ui::HistoryView* h) {
  choices_.lesson = lesson_ + 1;
  if (!lesson()) return;
  const Lesson& l = *lesson();
  // The snapshot's progress, when it is of this trainee and lesson and knows every attempt
  // this window made (an older snapshot must not move the trainee back).
  if (h && h != lesson_seen_ && h->lesson.loaded &&
      h->lesson.trainee + '\n' + h->lesson.lesson + '\n' + h->lesson.lesson_hash == lesson_for_ &&
      int(h->lesson.attempts.size()) >= lesson_attempts_known_) {
    lesson_seen_ = h;
    lesson_step_ = h->lesson.step;
    lesson_failed_ = h->lesson.failed_attempts;
    lesson_attempts_known_ = int(h->lesson.attempts.size());
    last_attempt_.reset();
    if (!h->lesson.attempts.empty()) last_attempt_ = h->lesson.attempts.back();
  }
  // A flight READY for the trainee's step (never in place of one that flew: its score card and
  // verdict stay until R).
  const int steps = int(l.steps.size());
  if (live_ && !live_->started() && lesson_step_ >= 0 && lesson_step_ < steps &&
      lesson_made_for_ != lesson_step_) {
    const LessonTag& tag = live_->flight().lesson;
    if (!(tag.active() && tag.lesson_hash == l.hash && tag.step == lesson_step_)) {
      std::string error;
      if (!fly_lesson_step(error)) status_line_.say(error, true);
    }
    lesson_made_for_ = lesson_step_;
  }
  lesson_view(h);
}

void LiveController::lesson_view(const ui::HistoryView* h) {
  ui::LessonChoice& v = choices_.lesson_view;
  const Lesson& l = *lesson();
  v = ui::LessonChoice{};
  v.description = l.description;
  for (const LessonStep& s : l.steps) v.steps.push_back(s.title);
  if (h && h->lesson.loaded && !h->lesson.error.empty()) v.error = "history: " + h->lesson.error;
  v.step = lesson_step_;
  const int steps = int(l.steps.size());
  if (lesson_step_ >= 0 && lesson_step_ < steps) {
    const LessonStep& s = l.steps[std::size_t(lesson_step_)];
    v.heading = step_heading(l, lesson_step_);
    v.rule = step_rule(s);
    v.conditions = step_conditions(s);
    v.criteria = criteria_text(s.pass);
    v.attempts = attempts_text(s, lesson_failed_);
    v.closed = out_of_attempts(s, lesson_failed_);
  }
  if (!verdict_ && last_attempt_) {
    // The last attempt the history holds (a trainee coming back sees where they left off).
    v.verdict_passed = last_attempt_->passed;
    v.verdict = "step " + std::to_string(last_attempt_->step + 1) +
                (last_attempt_->passed ? " PASSED" : " NOT PASSED: " + last_attempt_->detail);
  }
  if (verdict_) {
    v.verdict_passed = verdict_->passed;
    v.verdict = "step " + std::to_string(verdict_step_ + 1) +
                (verdict_->passed ? " PASSED" : " NOT PASSED: " + verdict_->detail);
    for (const CriterionResult& r : verdict_->results)
      v.verdict_lines.push_back(std::string(r.passed ? "pass  " : "FAIL  ") + r.text);
  }
  if (lesson_step_ >= 0 && lesson_step_ < steps && !v.closed)
    v.next = verdict_ && verdict_->passed && verdict_step_ + 1 == lesson_step_
                 ? "Next: step " + std::to_string(lesson_step_ + 1) + " (R)"
             : verdict_ && verdict_step_ == lesson_step_
                 ? "Try step " + std::to_string(lesson_step_ + 1) + " again (R)"
                 : "Fly step " + std::to_string(lesson_step_ + 1) + " (R)";
}

// ---- The ghost (SPEC §10) ------------------------------------------------------------------

void LiveController::ghost_options(const LiveFlight& f, const ui::HistoryView* h) {
  ghost_options_of_ = h;
  ghost_options_for_ = flights_made_;
  choices_.ghosts.clear();
  ghost_options_.clear();
  if (!f.ghost_target) return;
  const auto add = [&](std::string label, GhostChoice c) {
    choices_.ghosts.push_back(std::move(label));
    ghost_options_.push_back(std::move(c));
  };
  add("none", {GhostChoice::Kind::off, ""});
  // The trainee's recorded flights of this scenario (this very text), best first.
  const ui::ProgressView* v = h && h->loaded && h->progress.scenario == f.ghost_target->scenario_name
                                  ? &h->progress
                                  : nullptr;
  std::vector<const ui::ProgressFlight*> recorded;
  if (v)
    for (const ui::ProgressFlight& pf : v->flights)
      if (!pf.recording.empty() && pf.scenario_hash == f.ghost_target->scenario_hash &&
          std::isfinite(pf.skill))
        recorded.push_back(&pf);
  std::stable_sort(recorded.begin(), recorded.end(),
                   [](const auto* a, const auto* b) { return a->skill > b->skill; });
  if (!history_)
    add("your best (no history: --history off)", {GhostChoice::Kind::best, ""});
  else if (!v)
    add("your best (reading the history...)", {GhostChoice::Kind::best, ""});
  else if (recorded.empty())
    add("your best (none recorded yet)", {GhostChoice::Kind::best, ""});
  else
    add(ghost_label(*recorded.front(), true), {GhostChoice::Kind::best, ""});
  // A few more to race, the next best.
  constexpr std::size_t kOthers = 8;
  for (std::size_t i = 1; i < recorded.size() && i <= kOthers; ++i)
    add(ghost_label(*recorded[i], false) + ", " + recorded[i]->when,
        {GhostChoice::Kind::file, recorded[i]->recording});
  // --ghost's recording, and a recording chosen before that is not among them.
  if (ghost_choice_.kind == GhostChoice::Kind::file &&
      std::none_of(ghost_options_.begin(), ghost_options_.end(),
                   [&](const GhostChoice& c) { return c.path == ghost_choice_.path; }))
    add(fs::path(ghost_choice_.path).filename().string(), ghost_choice_);
  choices_.ghost = -1;
  for (std::size_t i = 0; i < ghost_options_.size(); ++i)
    if (ghost_options_[i].kind == ghost_choice_.kind && ghost_options_[i].path == ghost_choice_.path)
      choices_.ghost = int(i);
}

void LiveController::update_ghost(LiveFlight& f, const ui::HistoryView* h) {
  // Loaders no longer wanted go once they are done (their threads joined without waiting).
  std::erase_if(ghost_retired_, [](const auto& l) { return l->done(); });
  if (h != ghost_options_of_ || ghost_options_for_ != flights_made_) ghost_options(f, h);
  if (!f.ghost_target) {
    f.scene.ghost.reset();
    choices_.ghost_note.clear();
    return;
  }
  const GhostTarget& target = *f.ghost_target;
  // The recording the choice names now: a file, or the best of the snapshot.
  std::string wanted, label;
  if (ghost_choice_.kind == GhostChoice::Kind::file) {
    wanted = ghost_choice_.path;
    if (choices_.ghost >= 0 && std::size_t(choices_.ghost) < choices_.ghosts.size())
      label = choices_.ghosts[std::size_t(choices_.ghost)];  // as the session panel names it
  } else if (ghost_choice_.kind == GhostChoice::Kind::best && h && h->loaded &&
             h->progress.scenario == target.scenario_name) {
    if (const int best = best_recorded(h->progress, target.scenario_hash); best >= 0) {
      const ui::ProgressFlight& b = h->progress.flights[std::size_t(best)];
      wanted = b.recording;
      label = ghost_label(b, true);
    }
  }
  if (ghost_loader_ && ghost_loader_->done()) {
    const std::unique_ptr<GhostLoader> done = std::move(ghost_loader_);
    if (std::shared_ptr<const ui::Ghost> g = done->ghost()) {
      ghost_ = std::move(g);
      ghost_refused_.clear();
      status_line_.add("ghost: " + ghost_->label + " flies along");
    } else {
      ghost_.reset();
      ghost_refused_ = done->path();
      choices_.ghost_note = "ghost refused: " + done->error();
      choices_.ghost_note_is_error = true;
      status_line_.say("ghost " + done->error(), true);
    }
  }
  // A flight that flies keeps its ghost; one started before its ghost was ready (Restart
  // starts at once) gets it when it is, while it flies (after the flight the best may be
  // itself).
  if (f.started() && (f.scene.ghost || !is_flying(f))) return;
  const bool fits = ghost_ && ghost_->path == wanted && ghost_->scenario_hash == target.scenario_hash;
  f.scene.ghost = fits ? ghost_ : nullptr;
  const bool loading = ghost_loader_ && ghost_loader_->path() == wanted &&
                       ghost_loader_->target().scenario_hash == target.scenario_hash;
  if (!fits && !loading && !wanted.empty() && wanted != ghost_refused_) {
    if (ghost_loader_) ghost_retired_.push_back(std::move(ghost_loader_));
    ghost_loader_ = std::make_unique<GhostLoader>(wanted, target, label);
  }
  if (wanted != ghost_refused_ || wanted.empty()) {
    choices_.ghost_note_is_error = false;
    choices_.ghost_note = ghost_loader_ && ghost_loader_->path() == wanted && !wanted.empty()
                              ? "loading the ghost..."
                          : ghost_choice_.kind == GhostChoice::Kind::best && wanted.empty() &&
                                  history_
                              ? "your best recorded flight of this scenario will fly along"
                              : "";
  }
}

std::string LiveController::next_record_path() const {
  if (!first_record_.empty()) return first_record_;
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  std::string name = live_ ? live_->mode().scenario_name() : "flight";
  if (live_ && !live_->flight().pilot.empty() && !live_->flight().recording)
    name += "-" + live_->flight().pilot;
  if (from_) {  // a branch: the moment it was taken over at
    char at[40];
    std::snprintf(at, sizeof at, "-from-%.2fs", from_->t);
    name += at;
  }
  const fs::path folder = recordings_folder();
  if (folder.empty()) return "";
  return (folder / file_name_part(name + "-" + stamp + ".mcap")).string();
}

bool LiveController::fly_from(std::shared_ptr<const FlyFrom> from, const ui::History& so_far,
                              bool pad_connected) {
  const FlyOptions before = options_;
  auto from_before = std::move(from_);
  auto shown_before = std::move(from_shown_);
  from_ = std::move(from);
  from_shown_.clear();
  const std::size_t n = std::min(so_far.size(), kShownBeforeTheMoment);
  for (std::size_t i = so_far.size() - n; i < so_far.size(); ++i) from_shown_.push_back(so_far[i]);
  // The pilot who takes over: the live flights' choice, else a device of the person's.
  if (options_.pilot.empty() || options_.pilot.ends_with(".mcap"))
    options_.pilot = pad_connected ? "gamepad" : "keyboard";
  std::string error;
  bool made = replace_live(error);
  if (!made && options_.pilot != "keyboard") {  // a profile another scenario has, say
    options_.pilot = "keyboard";
    made = replace_live(error);
  }
  if (made) {
    status_line_.say("READY " + fly_from_text(*from_) +
                     ": the session panel picks who flies on, Space starts");
    return true;
  }
  options_ = before;
  from_ = std::move(from_before);
  from_shown_ = std::move(shown_before);
  status_line_.say(error, true);
  return false;
}

bool LiveController::open(std::string& error, int& status) {
  live_ = make_live(error, status);
  refresh_choices();
  return live_ != nullptr;
}

bool LiveController::replace_live(std::string& error) {
  int status = 0;
  auto next = make_live(error, status);
  if (!next) return false;
  close();
  live_ = std::move(next);
  refresh_choices();
  return true;
}

void LiveController::close() {
  if (live_ && !live_->closed()) close_live(*live_);
}

void LiveController::refresh_choices() {
  choices_.pilots.clear();
  choices_.pilot = -1;
  choices_.assist_choosable = false;
  if (!live_) return;
  if (ModeIdentity id = live_->mode().identity(); !id.pilot.empty()) {
    choices_.pilots = std::move(id.pilots);
    choices_.pilots.push_back("gamepad");
    choices_.pilots.push_back("keyboard");
    if (options_.pilot.ends_with(".mcap") && !from_) choices_.pilots.push_back(options_.pilot);
    const auto it = std::find(choices_.pilots.begin(), choices_.pilots.end(),
                              options_.pilot.empty() ? live_->flight().pilot : options_.pilot);
    choices_.pilot = it == choices_.pilots.end() ? -1 : int(it - choices_.pilots.begin());
  }
  choices_.record_to = choices_.record ? next_record_path() : "";
  const ModeIdentity id = live_->mode().identity();
  // A flight flown from here is as assisted as the one it goes on from.
  choices_.assist_choosable = !id.pilot.empty() && !live_->flight().recording && !from_;
  choices_.assist = !id.probe;
  choices_.fly_from = from_ ? fly_from_text(*from_) : "";
  if (from_ && !from_->scenario_file.empty()) {
    // The scenario it flies: its file among the choices (joining them, as an opened file does).
    const std::string file = absolute_path(from_->scenario_file);
    auto it = std::find(scenario_paths_.begin(), scenario_paths_.end(), file);
    if (it == scenario_paths_.end()) {
      scenario_paths_.push_back(file);
      choices_.scenarios.push_back(fs::path(file).filename().string());
      it = scenario_paths_.end() - 1;
    }
    choices_.scenario = int(it - scenario_paths_.begin());
  }
  show_progress();
  if (lesson() && lesson_for_.empty()) show_lesson();
}

void LiveController::fly_scenario(std::size_t index) {
  const FlyOptions before = options_;
  options_.scenario_path = scenario_paths_[index];
  if (!options_.pilot.ends_with(".mcap")) options_.pilot.clear();
  // Another scenario flies from its start.
  auto from_before = std::move(from_);
  auto shown_before = std::move(from_shown_);
  from_.reset();
  from_shown_.clear();
  std::string error;
  if (replace_live(error)) {
    choices_.scenario = int(index);
  } else {
    options_ = before;
    from_ = std::move(from_before);
    from_shown_ = std::move(shown_before);
    status_line_.say(error, true);
  }
}

void LiveController::open_scenario(const std::string& path) {
  const std::string p = absolute_path(path);
  auto it = std::find(scenario_paths_.begin(), scenario_paths_.end(), p);
  if (it == scenario_paths_.end()) {
    scenario_paths_.push_back(p);
    choices_.scenarios.push_back(fs::path(p).filename().string());
    it = scenario_paths_.end() - 1;
  }
  fly_scenario(std::size_t(it - scenario_paths_.begin()));
}

void LiveController::reopen() {
  if (live_ && !live_->closed()) return;
  if (options_.scenario_path.empty() && !options_.pilot.ends_with(".mcap")) {
    live_.reset();
    return;
  }
  std::string error;
  if (!replace_live(error)) status_line_.say(error, true);
}

void LiveController::settings_changed() {
  options_.input_settings.clear();  // the app's settings from now on, not the file's
  std::string error;
  if (live_ && !is_flying(*live_) && live_->flight().devices && !replace_live(error))
    status_line_.say(error, true);
}

void LiveController::start() {
  if (!live_ || live_->started()) return;
  if (const Lesson* l = lesson()) {
    const LessonTag& tag = live_->flight().lesson;
    if (lesson_step_ < 0 || lesson_step_ >= int(l->steps.size()) ||
        out_of_attempts(l->steps[std::size_t(lesson_step_)], lesson_failed_) ||
        !tag.active() || tag.step != lesson_step_ || tag.lesson_hash != l->hash) {
      status_line_.say(lesson_step_ < 0 ? "the lesson's progress is still being read"
                       : lesson_step_ >= int(l->steps.size()) ? "every step of the lesson is passed"
                                                               : "this step is closed (its attempts are used up)",
                       true);
      return;
    }
  }
  if (live_->awaiting_vehicle || live_->no_vehicle) return;  // the status line says why
  // A gamepad pilot starts once a pad is connected (the banner asks for one meanwhile).
  if (live_->flight().devices && live_->flight().devices->gamepad &&
      !live_->flight().devices->gamepad->connected()) {
    live_->waiting = true;
    return;
  }
  live_->waiting = false;
  if (choices_.record) {
    const std::string path = next_record_path();
    if (path.empty()) {
      std::string why;
      recordings_folder(&why);
      status_line_.say("cannot record: no folder for recordings (" + why +
                           "); set XDG_DATA_HOME or fly without recording",
                       true);
      return;
    }
    std::error_code ec;
    if (path != options_.record) fs::create_directories(fs::path(path).parent_path(), ec);
    std::string error;
    RecordingSink::Settings rs;
    rs.when_full = RecordingSink::FullRing::drop;  // the control thread never waits on the disk
    rs.slots = 4096;
    if (!live_->rig->record(path, choices_.trainee, rs, path == options_.record && options_.force,
                            error)) {
      status_line_.say(error, true);
      return;
    }
  }
  // The initial state shown while ready goes; a flight flown from here keeps the recorded
  // steps that led to its moment, all but the moment itself, which its own first step is.
  if (from_ && !live_->history.empty())
    live_->history.pop_newest();
  else
    live_->history.clear();
  live_->rig->start();
  status_line_.say("");
  if (history_) live_->rig->remember(history_, choices_.trainee, "window");
}

void LiveController::handle(const ui::LiveRequest& r) {
  if (!live_) return;
  // A request may replace the flight: each handler reads live_ afresh.
  std::string error;
  std::visit(
      ui::overloaded{
          [&](const ui::StartFlight&) { start(); },
          [&](const ui::TogglePause&) {
            if (is_flying(*live_)) live_->runner().set_paused(!live_->runner().paused());
          },
          [&](const ui::SetFlightSpeed& s) {
            live_->runner().set_speed(std::clamp(s.speed, 0.25, 1.0));
          },
          [&](const ui::RestartFlight&) {
            const double speed = live_->runner().speed();
            // A lesson flies the trainee's step now (the next one after a pass).
            const Lesson* l = lesson();
            if (l && (lesson_step_ < 0 || lesson_step_ >= int(l->steps.size()))) return;
            if (l ? !fly_lesson_step(error) : !replace_live(error)) {
              status_line_.say(error, true);
              return;
            }
            live_->runner().set_speed(speed);
            start();
          },
          [&](const ui::CancelVehicleWait&) {
            if (!live_->awaiting_vehicle) return;
            live_->rig->cancel_vehicle_wait();
            live_->awaiting_vehicle = false;
            live_->no_vehicle = true;
            status_line_.say("no vehicle: the wait was cancelled; Restart (R) waits again");
          },
          [&](const ui::HeldFlightKeys& k) {
            const Devices* d = live_->flight().devices.get();
            if (!d || !d->keyboard) return;
            for (int i = 0; i < int(input::Key::count); ++i)
              d->keyboard->set_key(input::Key(i), (k.keys >> i) & 1u);
          },
          [&](const ui::PickScenario& p) {
            if (lesson()) return;  // the lesson's step sets the scenario
            if (p.index >= 0 && p.index < int(scenario_paths_.size()) && !is_flying(*live_))
              fly_scenario(std::size_t(p.index));
          },
          [&](const ui::PickPilot& p) {
            if (p.index < 0 || p.index >= int(choices_.pilots.size()) || is_flying(*live_)) return;
            const FlyOptions before = options_;
            options_.pilot = choices_.pilots[std::size_t(p.index)];
            if (!replace_live(error)) {
              options_ = before;
              status_line_.say(error, true);
            }
          },
          [&](const ui::SetRecord& s) {
            if (is_flying(*live_)) return;
            choices_.record = s.on;
            choices_.record_to = choices_.record ? next_record_path() : "";
          },
          [&](const ui::SetTrainee& t) {
            choices_.trainee = t.name;
            show_progress();
            if (lesson()) show_lesson();
          },
          [&](const ui::PickLesson& p) { pick_lesson(p.index); },
          [&](const ui::ChooseLesson& c) {
            for (std::size_t i = 0; i < lessons_.size(); ++i)
              if (lessons_[i].name == c.name) return pick_lesson(int(i) + 1);
            status_line_.say("no lesson named " + c.name +
                                 (history_ ? "" : " (lessons need the history: --history is off)"),
                             true);
          },
          [&](const ui::FlyWith& w) {
            // The first launch's ways in: a shipped scenario by name, a pilot by theirs.
            if (is_flying(*live_)) return;
            if (lesson()) pick_lesson(0);
            const FlyOptions before = options_;
            if (!w.scenario.empty()) {
              const auto it = std::find_if(scenario_paths_.begin(), scenario_paths_.end(),
                                           [&](const std::string& p) {
                                             return fs::path(p).stem().string() == w.scenario;
                                           });
              if (it == scenario_paths_.end()) {
                status_line_.say("no shipped scenario named " + w.scenario, true);
                return;
              }
              options_.scenario_path = *it;
            }
            options_.pilot = w.pilot;
            from_.reset();
            from_shown_.clear();
            if (!replace_live(error)) {
              options_ = before;
              status_line_.say(error, true);
              return;
            }
            const auto at = std::find(scenario_paths_.begin(), scenario_paths_.end(),
                                      options_.scenario_path);
            if (at != scenario_paths_.end()) choices_.scenario = int(at - scenario_paths_.begin());
          },
          [&](const ui::FlyFromStart&) {
            if (!from_ || is_flying(*live_)) return;
            const FlyOptions before = options_;
            if (options_.scenario_path.empty()) options_.scenario_path = from_->scenario_file;
            auto from_before = std::move(from_);
            auto shown_before = std::move(from_shown_);
            from_.reset();
            from_shown_.clear();
            if (!replace_live(error)) {
              options_ = before;
              from_ = std::move(from_before);
              from_shown_ = std::move(shown_before);
              status_line_.say(error, true);
            }
          },
          [&](const ui::PickGhost& g) {
            if (g.index < 0 || g.index >= int(ghost_options_.size()) || is_flying(*live_)) return;
            ghost_choice_ = ghost_options_[std::size_t(g.index)];
            choices_.ghost = g.index;
            ghost_refused_.clear();  // chosen again: read again
          },
          [&](const ui::SetAssist& a) {
            // The unstarted flight is made again with the choice, as for a pilot.
            if (is_flying(*live_) || !choices_.assist_choosable || lesson()) return;
            const FlyOptions before = options_;
            options_.assist = a.on ? Assistance::on : Assistance::off;
            if (!replace_live(error)) {
              options_ = before;
              status_line_.say(error, true);
            }
          },
      },
      r);
}

void LiveController::update(bool pad_connected, ui::RunInfo& run) {
  update_lesson(run.history);  // first: it may make the step's flight anew
  LiveFlight& f = *live_;
  if (f.waiting && pad_connected) start();  // the gamepad it waited for has come
  if (f.awaiting_vehicle) update_vehicle_wait(f);
  if (!f.closed()) {
    while (f.runner().telemetry().pop(f.sample)) {
      f.history.push(f.sample);
      f.debrief.add(f.sample);
      ui::count_step(f.sample, f.counts);
    }
  }
  update_ghost(f, run.history);
  const Mode& mode = f.mode();
  // Before the start the screen shows the initial state: the arena, the vehicle, the reference.
  if (!f.started() && f.history.empty()) f.history.push(mode.telemetry());
  const bool over = f.started() && !f.runner().running();
  // The run is over: its recording is completed at once, and the score card shows.
  if (over && !f.closed()) close_live(f);
  if (over && f.metrics.empty()) {
    f.metrics = f.rig->metrics();
    f.debrief.finish();
    f.events = ui::debrief_rows(f.debrief.events(), f.debrief.settings().ball_radius);
    f.events_ready = true;
  }
  run.state = f.awaiting_vehicle ? ui::RunState::waiting
              : !f.started() ? ui::RunState::ready
              : mode.lost() ? ui::RunState::lost
              : over ? ui::RunState::finished
              : f.runner().paused() ? ui::RunState::paused
                                   : ui::RunState::flying;
  run.speed = f.runner().speed();
  run.instructor_paused = f.started() && !over && f.runner().instructor_paused();
  run.deadline_misses = f.counts.deadline_misses;
  run.fallbacks = f.counts.fallbacks;
  run.recording = !f.rig->recording_path().empty() && !f.closed();
  run.can_restart = true;
  run.metrics = f.metrics;
  run.replay = nullptr;
  run.session = &choices_;
}

bool LiveController::over() const {
  if (!live_) return true;
  return live_->started() && !live_->runner().running() && live_->closed();
}

double LiveController::shown_time() const {
  if (live_ && !live_->history.empty()) return live_->history.newest().t;
  return -1.0;
}

}  // namespace mixpilot::cli
