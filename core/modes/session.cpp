#include "core/modes/session.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace mixpilot {

void CommandInbox::schedule(std::vector<ScriptedCommand> script) {
  std::stable_sort(script.begin(), script.end(),
                   [](const ScriptedCommand& a, const ScriptedCommand& b) { return a.at < b.at; });
  script_ = std::move(script);
  next_ = 0;
}

void Session::set_inbox(CommandInbox* inbox) {
  inbox_ = inbox;
  // As many as the ring holds, plus a step's worth.
  queue_.assign(CommandInbox::kDefaultCapacity + std::size_t(kMaxCommandsPerStep), {});
  queued_ = 0;
}

void Session::take_commands() {
  // What arrived, into the queue in order; pause, resume and end act at once.
  InstructorCommand c;
  while (queued_ < queue_.size() && inbox_->pop(mode_->steps_done(), mode_->dt(), c)) {
    if (invalid_reason(c)) {
      inbox_->count(InstructorStatus::bad_value);
      continue;
    }
    if (over_ || ending_ || mode_->finished()) {
      inbox_->count(InstructorStatus::over);
      continue;
    }
    switch (c.kind) {
      case InstructorCommandKind::pause: paused_ = true; break;
      case InstructorCommandKind::resume: paused_ = false; break;
      case InstructorCommandKind::end:
        paused_ = false;  // the flight flies the step that carries the end, and ends
        ending_ = true;
        break;
      default: break;
    }
    queue_[queued_++] = c;
  }
  // Into the mode, oldest first, as long as the next step takes them.
  std::size_t taken = 0;
  for (; taken < queued_; ++taken) {
    const InstructorStatus s = mode_->instruct(queue_[taken]);
    if (s == InstructorStatus::busy) break;
    inbox_->count(s);
  }
  if (taken > 0) {
    std::move(queue_.begin() + std::ptrdiff_t(taken), queue_.begin() + std::ptrdiff_t(queued_),
              queue_.begin());
    queued_ -= taken;
  }
}

bool Session::step() {
  stepped_ = false;
  if (over_) return false;
  if (inbox_) take_commands();
  if (paused_) return true;
  if (!mode_->step()) return false;
  stepped_ = true;
  const Telemetry& s = mode_->telemetry();
  for (TelemetrySink* sink : sinks_) sink->on_sample(s);
  for (int i = 0; i < s.num_commands; ++i)
    if (s.commands[std::size_t(i)].kind == InstructorCommandKind::end) over_ = true;
  return true;
}

void Session::run() {
  while (step()) {
    if (!stepped_) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace mixpilot
