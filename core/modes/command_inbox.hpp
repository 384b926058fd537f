#pragma once
// The instructor's commands on their way into a flight (SPEC §10): a ring of InstructorCommand
// sized at setup, which another thread (the station's network link, a test) fills and the
// thread that steps the session drains before each step (Session::step); and a script's
// commands at flight times (`mixpilot fly --commands`), taken at the first step at or after
// their time, before the ring's. The control thread never waits on it and allocates nothing;
// what became of each command is counted here for any thread to read.
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/spsc_ring.hpp"
#include "core/modes/instructor.hpp"

namespace mixpilot {

// A script's command at a flight time [s] (core/modes/command_script.hpp).
struct ScriptedCommand {
  double at = 0.0;
  InstructorCommand command;
  int line = 0;  // in its file, for messages
};

class CommandInbox {
 public:
  static constexpr std::size_t kDefaultCapacity = 64;

  CommandInbox() { setup(kDefaultCapacity); }
  // Sizes the ring (allocates) and forgets everything.
  void setup(std::size_t capacity) {
    ring_.setup(capacity, InstructorCommand{});
    script_.clear();
    next_ = 0;
    applied_.store(0);
    refused_.store(0);
    last_refusal_.store(InstructorStatus::applied);
  }

  // The producer's side: one thread pushes (the station's network link). False, counted in
  // dropped(), when the ring is full.
  bool push(const InstructorCommand& c) { return ring_.push(c); }
  SpscRing<InstructorCommand>& ring() { return ring_; }

  // A script's commands (in the order of their times: a stable sort keeps the file's order at
  // equal times), before the flight starts.
  void schedule(std::vector<ScriptedCommand> script);
  const std::vector<ScriptedCommand>& script() const { return script_; }

  // The control thread: the next command for step k (period dt): a scripted one due at t_k,
  // else the ring's oldest. False when none is waiting.
  bool pop(std::int64_t k, double dt, InstructorCommand& out) {
    if (next_ < script_.size() && step_of(script_[next_].at, dt) <= k) {
      out = script_[next_++].command;
      return true;
    }
    return ring_.pop(out);
  }
  // The step a command at time `at` takes effect at: the first k with k·dt ≥ at (to 1e-9 of a
  // step, so 2.0 s at 15 ms is step 134, t = 2.01 s, and 0.3 s at 15 ms is step 20 exactly).
  static std::int64_t step_of(double at, double dt) {
    return std::int64_t(std::ceil(at / dt - 1e-9));
  }

  // The control thread counts each command taken: applied or refused (and why).
  void count(InstructorStatus s) {
    if (s == InstructorStatus::applied) {
      applied_.fetch_add(1, std::memory_order_relaxed);
    } else {
      refused_.fetch_add(1, std::memory_order_relaxed);
      last_refusal_.store(s, std::memory_order_relaxed);
    }
  }
  std::int64_t applied() const { return applied_.load(std::memory_order_relaxed); }
  std::int64_t refused() const { return refused_.load(std::memory_order_relaxed); }
  InstructorStatus last_refusal() const { return last_refusal_.load(std::memory_order_relaxed); }
  std::int64_t dropped() const { return ring_.dropped(); }  // the ring was full

 private:
  SpscRing<InstructorCommand> ring_;
  std::vector<ScriptedCommand> script_;
  std::size_t next_ = 0;
  std::atomic<std::int64_t> applied_{0}, refused_{0};
  std::atomic<InstructorStatus> last_refusal_{InstructorStatus::applied};
};

}  // namespace mixpilot
