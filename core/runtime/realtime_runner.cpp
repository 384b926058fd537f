#include "core/runtime/realtime_runner.hpp"

#include "core/base/realtime_priority.hpp"

#include <algorithm>


namespace mixpilot {

RealtimeRunner::RealtimeRunner(Session& session, std::size_t ring_capacity) : session_(&session) {
  ring_.setup(ring_capacity, session.mode().telemetry());
  // SPEC §4: a solve must end within the control period, else its step falls back.
  session.mode().set_deadline_us(1e6 * session.mode().dt());
}

RealtimeRunner::~RealtimeRunner() { stop(); }

void RealtimeRunner::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  running_.store(true);
  thread_ = std::thread([this] { loop(); });
}

void RealtimeRunner::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

RealtimeStats RealtimeRunner::stats() const {
  RealtimeStats st;
  st.steps = steps_.load();
  st.deadline_misses = misses_.load();
  st.late_starts = late_starts_.load();
  st.safe_hold_steps = safe_.load();
  st.slip_s = slip_s_.load();
  st.worst_lateness_us = worst_lateness_us_.load();
  st.worst_step_us = worst_step_us_.load();
  st.realtime_priority = fifo_.load();
  // The smallest bin edge below which 99 % of the steps fall.
  std::uint64_t total = 0;
  for (const auto& b : step_bins_) total += b.load(std::memory_order_relaxed);
  std::uint64_t below = 0;
  for (int i = 0; i < kBins && total > 0; ++i) {
    below += step_bins_[std::size_t(i)].load(std::memory_order_relaxed);
    if (100 * below >= 99 * total) {
      st.p99_step_us = double(i + 1) * kBinUs;
      break;
    }
  }
  return st;
}

void RealtimeRunner::loop() {
  using clock = std::chrono::steady_clock;
  fifo_.store(ask_realtime_priority(kControlPriority));
  const double dt = session_->mode().dt();
  auto next = clock::now();
  double overshoot_us = 0.0;
  while (!stop_.load(std::memory_order_relaxed)) {
    if (paused_.load(std::memory_order_relaxed)) {
      session_->poll();
      instructor_paused_.store(session_->paused(), std::memory_order_relaxed);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      next = clock::now();  // resume without catching up
      overshoot_us = 0.0;
      continue;
    }
    std::this_thread::sleep_until(next);
    const double speed = std::max(1e-3, speed_.load(std::memory_order_relaxed));
    const double period_us = 1e6 * dt / speed;
    const auto started = clock::now();
    // Late against the schedule, plus how far the previous step overshot its end: its restart
    // of the schedule moved this step's start, not the time its input was due.
    const double late_us =
        std::chrono::duration<double, std::micro>(started - next).count() + overshoot_us;
    overshoot_us = 0.0;
    Mode& mode = session_->mode();
    mode.set_pacing(std::max(0.0, late_us), period_us);
    const bool more = session_->step();
    const auto ended = clock::now();
    instructor_paused_.store(session_->paused(), std::memory_order_relaxed);
    if (!more) break;
    if (!session_->stepped()) {  // the instructor paused it: as the user's pause
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      next = clock::now();
      overshoot_us = 0.0;
      continue;
    }
    ring_.push(mode.telemetry());
    const std::uint32_t events = mode.telemetry().events;
    const double step_us = std::chrono::duration<double, std::micro>(ended - started).count();
    if (events & kEventDeadlineMiss) misses_.fetch_add(1);
    else if (late_us > 0.1 * 1e6 * dt) late_starts_.fetch_add(1);
    if (events & kEventSafeHold) safe_.fetch_add(1);
    if (late_us > worst_lateness_us_.load()) worst_lateness_us_.store(late_us);
    if (step_us > worst_step_us_.load()) worst_step_us_.store(step_us);
    step_bins_[std::size_t(std::min(double(kBins - 1), step_us / kBinUs))].fetch_add(
        1, std::memory_order_relaxed);
    steps_.fetch_add(1);
    const auto period =
        std::chrono::duration_cast<clock::duration>(std::chrono::duration<double, std::micro>(period_us));
    // A step that ends after it is due restarts the schedule from its end: no burst of catch-up
    // steps, and simulated time falls behind the wall clock by the overshoot.
    const auto due = next + period;
    if (ended > due) {
      overshoot_us = std::chrono::duration<double, std::micro>(ended - due).count();
      slip_s_.store(slip_s_.load() + speed * 1e-6 * overshoot_us);
      next = ended + period;
    } else {
      next = due;
    }
  }
  running_.store(false);
}

}  // namespace mixpilot
