#pragma once
// The real-time runner (SPEC §8 "Threads"): its own thread steps a session once per control
// period Δt of the mode, paced by the wall clock (slowed down by `speed`), and hands each step's
// telemetry to the UI through a ring that never blocks it. Pause, resume, speed and stop come
// from any thread through atomics; the control thread never waits on them. The instructor's
// commands reach it through the session's inbox (core/modes/session.hpp), taken before each
// step and while paused; the instructor's pause holds the steps as the user's does.
//
// Deadlines: step k is scheduled at s_k = s_0 + k T (T = Δt / speed of wall time) and is due at
// the end of its period, s_k + T. The runner tells the mode how late each step starts; the mode
// marks a step whose control input is ready after it is due, or took longer than Δt to compute,
// as a deadline miss (kEventDeadlineMiss), so the recording, the score, the HUD and this
// runner's count are one count. A step that ends after it is due restarts the schedule from its
// end (no burst of catch-up steps): simulated time then falls behind the wall clock, by the
// amount reported as `slip_s`. Starts later than 10 % of Δt that still met the deadline are
// counted too (late starts), and the schedule keeps its grid.
//
// The control thread asks for real-time scheduling (SCHED_FIFO) so that a busy UI or renderer
// (Mesa's software rasterizer runs a thread per core) cannot delay its steps; where the system
// does not grant it (no CAP_SYS_NICE, no rtprio limit) it runs at normal priority and says so.
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "core/modes/session.hpp"
#include "core/base/spsc_ring.hpp"

namespace mixpilot {

struct RealtimeStats {
  std::int64_t steps = 0;
  std::int64_t deadline_misses = 0;  // steps the mode marked kEventDeadlineMiss
  std::int64_t late_starts = 0;    // started more than 10 % of Δt late, yet met the deadline
  std::int64_t safe_hold_steps = 0;  // flown by the mode's safe controller (kEventSafeHold)
  double slip_s = 0.0;             // how far simulated time fell behind the wall clock [s]
  double worst_lateness_us = 0.0;  // the latest start after its schedule
  double worst_step_us = 0.0;      // the longest step
  double p99_step_us = 0.0;        // 99th percentile of the step times (to 20 us)
  bool realtime_priority = false;  // the control thread runs under SCHED_FIFO
};

class RealtimeRunner {
 public:
  // The session and its mode must outlive the runner. `ring_capacity` telemetry slots for the
  // UI (sized here with a copy of the mode's current telemetry).
  RealtimeRunner(Session& session, std::size_t ring_capacity);
  ~RealtimeRunner();
  RealtimeRunner(const RealtimeRunner&) = delete;
  RealtimeRunner& operator=(const RealtimeRunner&) = delete;

  void start();   // starts the thread (paused runs wait for resume())
  void stop();    // ends the run at the next step and joins the thread
  void set_paused(bool paused) { paused_.store(paused); }
  bool paused() const { return paused_.load(); }
  void set_speed(double speed) { speed_.store(speed); }  // 1: real time; 0.5: half speed
  double speed() const { return speed_.load(); }
  bool running() const { return running_.load(); }  // false once the mode's run is over
  // The instructor paused the flight (SPEC §10; Session::paused): no step flies until a
  // resume or an end, as if set_paused(true).
  bool instructor_paused() const { return instructor_paused_.load(); }

  // The UI's side: telemetry of the steps flown since the last call, oldest first.
  SpscRing<Telemetry>& telemetry() { return ring_; }
  RealtimeStats stats() const;

 private:
  void loop();

  Session* session_;
  SpscRing<Telemetry> ring_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, paused_{false}, running_{false}, fifo_{false};
  std::atomic<bool> instructor_paused_{false};
  std::atomic<double> speed_{1.0};
  std::atomic<std::int64_t> steps_{0}, misses_{0}, late_starts_{0}, safe_{0};
  std::atomic<double> slip_s_{0.0};
  std::atomic<double> worst_lateness_us_{0.0}, worst_step_us_{0.0};
  // Step times in 20 us bins (the last bin holds every longer step): percentiles without
  // keeping the samples.
  static constexpr int kBins = 2500;
  static constexpr double kBinUs = 20.0;
  std::array<std::atomic<std::uint32_t>, kBins> step_bins_{};
};

}  // namespace mixpilot
