#pragma once
// Scoring of a session from its telemetry (SPEC §8). With K control steps of Δt, p_k the true
// position, η^r_k the planner reference, r the ball radius, r_v the vehicle radius:
//   duration_s        K Δt
//   progress          fraction of the reference waypoints η^r_k that the vehicle came within r
//                     of at some step j with |j − k| Δt ≤ 1 s (how much of the path was flown),
//                     out of the waypoints of the flight's planned steps from its first scored
//                     step on (a branch flown from step k: those from k on)
//   time_in_ball      fraction of steps with ‖p_k − η^r_k‖ ≤ r
//   max_deviation_m   max_k ‖p_k − η^r_k‖;   rms_deviation_m  √(mean_k ‖p_k − η^r_k‖²)
//   mean_lambda, min_lambda   of the PH index λ_k
//   assistance_dependence     D = (1/T)∫₀ᵀ (1 − λ) dt ∈ [0, 1] (SPEC §10), by the rectangle rule
//                     over the control steps: (1/K) Σ_k (1 − λ_k) with the λ_k applied in step k,
//                     the same samples as mean_lambda, so D = 1 − mean_lambda up to rounding
//                     (the share of the flight the planner flew)
//   collisions        number of times the vehicle sphere (radius r_v) starts touching an
//                     obstacle, a wall or the floor
//   min_clearance_m   min_k min_o (‖p_k − o‖ − r_o − r_v): negative means contact
//   override_rms      √(mean_k ((φ_h − φ*_1)² + (θ_h − θ*_1)²)) [rad]: how far the MPC's
//                     attitude (its stage-1 prediction) departs from the pilot's command
//   stick_smoothness  √(mean_k ‖(Δφ_h, Δθ_h)/Δt‖²) [rad/s]: RMS rate of the pilot's attitude
//                     command (lower is smoother)
//   rti_median_us, rti_p99_us  of the controller's prepare + feedback time per step
//   deadline_misses   steps of a paced run that missed their deadline (kEventDeadlineMiss:
//                     started late or computed too long; 0 when not paced)
//   fallbacks         RTI fallbacks (QP failed or overran)
//   input_lost_s      time the pilot's device was lost (the planner flew)
//   safe_hold_s       time the safe controller flew (the MPC's plan was spent)
//   skill             100 · progress · (0.4 time_in_ball + 0.4 mean_lambda
//                     + 0.2 exp(−override_rms / 0.1 rad)) / (1 + collisions) ∈ [0, 100]
// The three timing fields measure this run on this machine (a replay takes them from the
// recording); every other field is a pure function of the telemetry, so a replay of a
// recording reproduces it bit for bit. A flight taken over from another one's step k (SPEC
// §10, fly from here) is scored on its own steps k, k + 1, ... only (restart()).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/modes/mode.hpp"
#include "core/numerics/reserved_vector.hpp"
#include "core/scenario/scenario.hpp"

namespace mixpilot {

struct Score {
  double duration_s = 0;
  double progress = 0;
  double time_in_ball = 0;
  double max_deviation_m = 0;
  double rms_deviation_m = 0;
  double mean_lambda = 0;
  double min_lambda = 0;
  double assistance_dependence = 0;
  int collisions = 0;
  double min_clearance_m = 0;
  double override_rms = 0;
  double stick_smoothness = 0;
  double rti_median_us = 0;
  double rti_p99_us = 0;
  int deadline_misses = 0;
  std::int64_t fallbacks = 0;
  double skill = 0;
  double input_lost_s = 0;
  double safe_hold_s = 0;
};

// The fields above in this order, as metrics.
Metrics to_metrics(const Score& score);

// Timing fields of a flight: the median and p99 of its per-step controller times [µs] and its
// deadline misses (steps marked kEventDeadlineMiss).
void set_timing(Score& score, std::vector<double> total_us, int deadline_misses);

// The score of a flight, one step at a time. add() allocates nothing for the steps setup()
// sized it for.
class ScoreAccumulator {
 public:
  // What add() has accumulated so far (a snapshot of the flight copies it).
  struct Sums {
    ReservedVector<Eigen::Vector3d> position;   // per step
    ReservedVector<Eigen::Vector3d> reference;  // per step
    ReservedVector<double> lambda;              // per step
    ReservedVector<double> rti_us;              // per step
    double sum_override_sq = 0;
    double sum_stick_sq = 0;
    double prev_roll = 0, prev_pitch = 0;
    double min_clearance = 1e9;
    int collisions = 0;
    bool in_contact = false;
    std::int64_t fallbacks = 0;
    int deadline_misses = 0;
    std::int64_t input_lost_steps = 0;
    std::int64_t safe_hold_steps = 0;
    std::int64_t first_step = 0;  // the step scoring started at (restart())
  };

  ScoreAccumulator() = default;
  explicit ScoreAccumulator(const Scenario& scenario) { setup(scenario); }
  // Starts over for a flight of `scenario` (which must outlive the accumulator).
  void setup(const Scenario& scenario);
  // Adds one step; true when the vehicle sphere started touching something in it.
  bool add(const Telemetry& step);
  // The clearance of the step added last: the vehicle sphere's least distance to an obstacle,
  // a wall or the floor [m] (negative: in contact).
  double clearance() const { return clearance_; }
  Score finish() const;
  // Starts the score afresh at step `first_step` of the same flight (fly from here): nothing
  // added so far counts, and progress is out of the waypoints from that step on. Keeps the
  // logs' capacity: allocates nothing.
  void restart(std::int64_t first_step);

  // The sums so far, and back: restore() takes those of an accumulator set up for the same
  // flight (they then fit its reserved logs: no allocation).
  const Sums& sums() const { return sums_; }
  void restore(const Sums& sums) { sums_ = sums; }

 private:
  const Scenario* scenario_ = nullptr;
  double dt_ = 0.015;
  Sums sums_;
  double clearance_ = 1e9;
};

}  // namespace mixpilot
