#include "app/replay_controller.hpp"

#include <algorithm>
#include <cstdio>

#include "app/cli.hpp"

namespace mixpilot::cli {

ReplayController::ReplayController(const char* command, bool allow_mismatch, StatusLine& status,
                                   std::string ghost)
    : command_(command), allow_mismatch_(allow_mismatch), status_(status),
      ghost_path_(std::move(ghost)) {}

ReplayController::~ReplayController() {
  if (tape_) tape_->stop();
}

std::unique_ptr<FlightRig> ReplayController::prepare(const std::string& path,
                                                     std::string& error) const {
  FlyOptions o;
  o.pilot = path;
  o.replay = true;
  o.command = command_;
  int status = 0;
  return FlightRig::assemble(o, error, status);
}

void ReplayController::open(std::unique_ptr<FlightRig> rig, const std::string& path) {
  if (ghost_loader_) ghost_retired_.push_back(std::move(ghost_loader_));  // the last replay's
  ghost_error_.clear();
  if (!ghost_path_.empty()) {
    // The target before the tape's loader steps the mode.
    if (std::optional<GhostTarget> target = ghost_target(rig->flight(), ghost_error_))
      ghost_loader_ = std::make_unique<GhostLoader>(ghost_path_, std::move(*target), "");
    else
      status_.say("ghost " + ghost_path_ + ": " + ghost_error_, true);
  }
  tape_ = std::make_unique<ReplayTape>(std::move(rig), path);
  tape_->start();
  info_ = ui::ReplayInfo{};
  info_.duration = double(tape_->steps()) * tape_->dt();
  events_final_ = false;
}

void ReplayController::close() { tape_.reset(); }

void ReplayController::load() {
  if (tape_) tape_->fly();
  if (ghost_loader_) ghost_loader_->wait();
  poll_ghost();
}

void ReplayController::poll_ghost() {
  std::erase_if(ghost_retired_, [](const auto& l) { return l->done(); });
  if (!ghost_loader_ || !ghost_loader_->done() || !tape_) return;
  const std::unique_ptr<GhostLoader> done = std::move(ghost_loader_);
  if (std::shared_ptr<const ui::Ghost> g = done->ghost()) {
    tape_->set_ghost(std::move(g));
  } else {
    ghost_error_ = done->error();
    status_.say("ghost " + ghost_error_, true);
  }
}

void ReplayController::handle(const ui::ReplayRequest& r) {
  if (!tape_) return;
  ui::ReplayInfo& info = info_;
  // The playhead stays on a step that is ready: the last one is at (ready − 1) Δt.
  const auto last = [&] { return tape_->ready() ? double(tape_->ready() - 1) * tape_->dt() : 0.0; };
  std::visit(ui::overloaded{
                 [&](const ui::TogglePlay&) {
                   if (!info.playing && tape_->done() && info.t >= last())
                     info.t = 0.0;  // played to the end: Play starts it again
                   info.playing = !info.playing;
                 },
                 [&](const ui::SetPlaySpeed& s) { speed_ = std::clamp(s.speed, 0.25, 8.0); },
                 [&](const ui::Seek& s) { info.t = std::clamp(s.t, 0.0, last()); },
                 // The debrief's events: [ / ] select the previous / next one from the
                 // playhead, a click in the list that one; the playhead goes to its start.
                 [&](const ui::JumpToEvent& j) {
                   const int i = ui::event_after(info.events, info.t, j.direction);
                   if (i >= 0) {
                     info.selected = i;
                     info.t = std::min(info.events[std::size_t(i)].t, last());
                   }
                 },
                 [&](const ui::SelectEvent& e) {
                   if (e.index < 0 || std::size_t(e.index) >= info.events.size()) return;
                   info.selected = e.index;
                   info.t = std::min(info.events[std::size_t(e.index)].t, last());
                 },
                 [&](const ui::SetLambdaThreshold& l) {
                   info.lambda_threshold = l.lambda;
                   events_final_ = false;  // the takeovers found again on the next frame
                 },
             },
             r);
}

void ReplayController::update(double wall_dt, ui::RunInfo& run) {
  poll_ghost();
  ReplayTape& r = *tape_;
  ui::ReplayInfo& info = info_;
  const std::size_t ready = r.ready();
  info.duration = double(r.steps()) * r.dt();
  info.loaded = r.steps() ? double(ready) / double(r.steps()) : 1.0;
  if (r.done()) info.loaded = 1.0;
  const double last = ready ? double(ready - 1) * r.dt() : 0.0;
  if (info.playing) {
    info.t += wall_dt * speed_;
    if (info.t >= last) {
      info.t = last;
      if (r.done()) info.playing = false;  // at the end
    }
  }
  if (r.done() && !events_final_) {
    // The debrief of the replayed flight (SPEC §10): the builder the recorder ran, over the
    // tape, with the transport's λ_T for the takeovers.
    DebriefSettings settings = r.debrief();
    settings.takeover_lambda = info.lambda_threshold;
    info.events = ui::debrief_rows(debrief_of(r.tape(), ready, settings), settings.ball_radius);
    info.events_ready = true;
    info.selected = -1;
    events_final_ = true;
    if (!r.mismatch().empty() && r.mismatch() != "interrupted")
      status_.say("the replay differs from the recording: " + r.mismatch(), true);
  }
  run.state = r.done() ? ui::RunState::replay : ui::RunState::loading;
  run.speed = speed_;
  run.deadline_misses = 0;
  run.fallbacks = 0;
  const std::size_t k = tape_index(r, info.t);
  // The replay marks the recorded flight's overruns and deadline misses (Mode::replay_timing):
  // the tape counts what the flight counted.
  for (std::size_t i = 0; i < ready && i <= k; ++i) ui::count_step(r.tape()[i], run);
  // Fly from here (SPEC §10): where a pilot shares the authority, from any loaded step.
  info.can_fly_from_here = r.scene().shared_authority && ready > 0;
  run.recording = false;
  run.can_restart = false;
  run.metrics = r.done() && ready > 0 && k + 1 >= ready ? r.metrics() : Metrics{};
  run.replay = &info;
  run.session = nullptr;
}

ui::History ReplayController::shown() const {
  const std::size_t n = tape_->ready();
  return ui::History::view(tape_->tape(), n ? tape_index(*tape_, info_.t) + 1 : 0);
}

std::int64_t ReplayController::fly_from_here() {
  if (!tape_ || !tape_->scene().shared_authority || tape_->ready() == 0) return -1;
  info_.playing = false;
  return std::int64_t(tape_index(*tape_, info_.t));
}

bool ReplayController::over() const {
  const std::size_t n = tape_->ready();
  return tape_->done() && (n == 0 || tape_index(*tape_, info_.t) + 1 >= n);
}

double ReplayController::shown_time() const { return tape_->ready() ? info_.t : -1.0; }

int ReplayController::finish(int status) {
  tape_->stop();
  std::printf("mixpilot %s: %s", command_, tape_->mode().summary().c_str());
  const std::string& diff = tape_->mismatch();
  if (diff.empty()) {
    std::printf("  replay exact: every recorded step reproduced bit for bit\n");
  } else if (diff != "interrupted") {
    std::fprintf(stderr, "mixpilot %s: the replay of %s differs from the recording: %s\n",
                 command_, tape_->path().c_str(), diff.c_str());
    if (!allow_mismatch_ && status == kExitOk) status = kExitReplayMismatch;
  }
  return status;
}

}  // namespace mixpilot::cli
