#pragma once
// A session drives one mode (core/modes/mode.hpp) step by step and hands each step's telemetry
// to its sinks (recorder, replay check, later the UI's hand-over buffer). The same code serves
// as-fast-as-possible runs (run(): deterministic, no clock involved) and real-time runs, whose
// runner calls step() once per control period.
//
// The instructor (SPEC §10): with a command inbox (core/modes/command_inbox.hpp), step() first
// takes what arrived, on the stepping thread and without allocating: each command goes to the
// mode (Mode::instruct), which applies it from this step on and carries it in the step's
// telemetry; pause and resume act at once (no step is flown while paused), end ends the flight
// after the step that carries it. A step takes kMaxCommandsPerStep commands; the rest wait in
// the session's queue, in order, for the steps after.
#include <cstddef>
#include <vector>

#include "core/modes/command_inbox.hpp"
#include "core/modes/mode.hpp"

namespace mixpilot {

class TelemetrySink {
 public:
  virtual ~TelemetrySink() = default;
  // Called on the stepping thread right after each step; must not block it for long.
  virtual void on_sample(const Telemetry& sample) = 0;
};

class Session {
 public:
  explicit Session(Mode& mode) : mode_(&mode) {}

  void add_sink(TelemetrySink* sink) { sinks_.push_back(sink); }
  // The instructor's commands come from `inbox` (which outlives the session). Sizes the
  // session's queue (allocates): before the first step.
  void set_inbox(CommandInbox* inbox);
  CommandInbox* inbox() { return inbox_; }

  // The commands that arrived, then one control step of the mode (unless paused), then every
  // sink sees its telemetry. false once the run is over (nothing happened then); true while
  // paused without a step (stepped() says which). Allocates nothing beyond what the mode and
  // sinks do.
  bool step();
  bool stepped() const { return stepped_; }
  // Steps until the run is over (waiting while paused, for a resume or an end).
  void run();

  // Takes the commands that arrived without stepping (step() does it first): a runner paused
  // by its own user keeps obeying the instructor's pause and resume.
  void poll() {
    if (inbox_ && !over_) take_commands();
  }
  bool paused() const { return paused_; }
  // The instructor ended the flight (its end command was flown).
  bool ended_by_instructor() const { return over_; }

  Mode& mode() { return *mode_; }
  const Mode& mode() const { return *mode_; }

 private:
  void take_commands();

  Mode* mode_;
  std::vector<TelemetrySink*> sinks_;
  CommandInbox* inbox_ = nullptr;
  std::vector<InstructorCommand> queue_;  // sized by set_inbox(); queued_ in use, oldest first
  std::size_t queued_ = 0;
  bool stepped_ = false;
  bool paused_ = false;
  bool ending_ = false;  // an end was taken: the flight ends after the step that carries it
  bool over_ = false;
};

}  // namespace mixpilot
