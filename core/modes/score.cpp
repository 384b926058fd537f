#include "core/modes/score.hpp"

#include "core/numerics/stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mixpilot {

void ScoreAccumulator::setup(const Scenario& scenario) {
  *this = ScoreAccumulator{};
  scenario_ = &scenario;
  dt_ = scenario.controller.dt;
  const auto steps = std::size_t(std::lround(scenario.duration / dt_)) + 1;
  Sums& m = sums_;
  m.position.reserve(steps);
  m.reference.reserve(steps);
  m.lambda.reserve(steps);
  m.rti_us.reserve(steps);
}

bool ScoreAccumulator::add(const Telemetry& s) {
  Sums& m = sums_;
  const Eigen::Vector3d p = s.x.head<3>();
  m.position.push_back(p);
  m.reference.push_back(s.reference.head<3>());
  m.lambda.push_back(s.lambda);
  m.rti_us.push_back(s.stats.total_us);
  if (s.stats.status == RtiStatus::fallback) ++m.fallbacks;
  if (s.events & kEventDeadlineMiss) ++m.deadline_misses;
  if (s.events & kEventSafeHold) ++m.safe_hold_steps;
  if (s.pilot.input == InputState::lost) ++m.input_lost_steps;

  const double dr = s.pilot.roll - s.applied.roll, dp = s.pilot.pitch - s.applied.pitch;
  m.sum_override_sq += dr * dr + dp * dp;
  if (!m.position.empty() && m.position.size() > 1) {
    const double vr = (s.pilot.roll - m.prev_roll) / dt_;
    const double vp = (s.pilot.pitch - m.prev_pitch) / dt_;
    m.sum_stick_sq += vr * vr + vp * vp;
  }
  m.prev_roll = s.pilot.roll;
  m.prev_pitch = s.pilot.pitch;

  // Clearance of the vehicle sphere to obstacles, walls and floor.
  const double rv = scenario_->controller.vehicle_radius;
  double clearance = 1e9;
  for (const Obstacle& o : scenario_->arena.obstacles) {
    const double c = (p - o.center).norm() - o.radius - rv;
    m.min_clearance = std::min(m.min_clearance, c);
    clearance = std::min(clearance, c);
  }
  const Arena& a = scenario_->arena;
  for (int i = 0; i < 3; ++i) {
    clearance = std::min({clearance, p(i) - a.min(i) - rv, a.max(i) - p(i) - rv});
  }
  clearance_ = clearance;
  const bool contact = clearance < 0.0;
  const bool started = contact && !m.in_contact;
  if (started) ++m.collisions;
  m.in_contact = contact;
  return started;
}

void ScoreAccumulator::restart(std::int64_t first_step) {
  Sums& m = sums_;
  // The logs moved aside and back keep their buffers; every other sum takes its initial value.
  ReservedVector<Eigen::Vector3d> position = std::move(m.position), reference = std::move(m.reference);
  ReservedVector<double> lambda = std::move(m.lambda), rti_us = std::move(m.rti_us);
  m = Sums{};
  m.position = std::move(position);
  m.reference = std::move(reference);
  m.lambda = std::move(lambda);
  m.rti_us = std::move(rti_us);
  m.position.clear();
  m.reference.clear();
  m.lambda.clear();
  m.rti_us.clear();
  m.first_step = first_step;
}

Score ScoreAccumulator::finish() const {
  const Sums& m = sums_;
  Score sc;
  const std::size_t K = m.position.size();
  if (K == 0) return sc;
  const double r = scenario_->controller.ph.r;
  sc.duration_s = double(K) * dt_;

  double sum_sq = 0, max_dev = 0;
  std::size_t in_ball = 0;
  for (std::size_t k = 0; k < K; ++k) {
    const double d = (m.position[k] - m.reference[k]).norm();
    sum_sq += d * d;
    max_dev = std::max(max_dev, d);
    if (d <= r) ++in_ball;
  }
  sc.max_deviation_m = max_dev;
  sc.rms_deviation_m = std::sqrt(sum_sq / double(K));
  sc.time_in_ball = double(in_ball) / double(K);

  // Waypoint k counts as flown if the vehicle came within r of it within ±1 s; the reference
  // is the whole scenario's, so a session cut short (end of a recording) makes less progress.
  const auto window = std::int64_t(std::lround(1.0 / dt_));
  const auto total = std::int64_t(std::lround(scenario_->duration / dt_)) - m.first_step;
  std::int64_t reached = 0;
  for (std::int64_t k = 0; k < std::int64_t(K); ++k) {
    const std::int64_t lo = std::max<std::int64_t>(0, k - window);
    const std::int64_t hi = std::min<std::int64_t>(std::int64_t(K) - 1, k + window);
    for (std::int64_t j = lo; j <= hi; ++j) {
      if ((m.position[std::size_t(j)] - m.reference[std::size_t(k)]).norm() <= r) {
        ++reached;
        break;
      }
    }
  }
  sc.progress = double(reached) / double(std::max<std::int64_t>(total, std::int64_t(K)));

  // D = (1/T)∫(1 − λ) dt by the rectangle rule over the steps, T = K Δt: (1/K) Σ (1 − λ_k),
  // over the same λ_k as mean_lambda (the λ the step applied: 0 while the safe controller
  // flew, capped by the pilot's authority). Summed as its own terms rather than taken as
  // 1 − mean_lambda, so a flight whose λ is 1 throughout gives exactly 0; the two agree to
  // rounding.
  double sum_l = 0, sum_planner = 0, min_l = 1.0;
  for (double l : m.lambda) {
    sum_l += l;
    sum_planner += 1.0 - l;
    min_l = std::min(min_l, l);
  }
  sc.mean_lambda = sum_l / double(K);
  sc.min_lambda = min_l;
  sc.assistance_dependence = sum_planner / double(K);
  sc.collisions = m.collisions;
  sc.min_clearance_m = scenario_->arena.obstacles.empty() ? 0.0 : m.min_clearance;
  sc.override_rms = std::sqrt(m.sum_override_sq / double(K));
  sc.stick_smoothness = K > 1 ? std::sqrt(m.sum_stick_sq / double(K - 1)) : 0.0;

  set_timing(sc, m.rti_us, m.deadline_misses);
  sc.fallbacks = m.fallbacks;
  sc.input_lost_s = double(m.input_lost_steps) * dt_;
  sc.safe_hold_s = double(m.safe_hold_steps) * dt_;

  const double quality = 0.4 * sc.time_in_ball + 0.4 * sc.mean_lambda +
                         0.2 * std::exp(-sc.override_rms / 0.1);
  sc.skill = 100.0 * sc.progress * quality / (1.0 + sc.collisions);
  return sc;
}

void set_timing(Score& sc, std::vector<double> t, int deadline_misses) {
  sc.rti_median_us = sc.rti_p99_us = 0.0;
  sc.deadline_misses = deadline_misses;
  if (t.empty()) return;
  sc.rti_median_us = percentile(t, 0.5);
  sc.rti_p99_us = percentile(t, 0.99);
}

Metrics to_metrics(const Score& s) {
  return {
      {"duration_s", s.duration_s},
      {"progress", s.progress},
      {"time_in_ball", s.time_in_ball},
      {"max_deviation_m", s.max_deviation_m},
      {"rms_deviation_m", s.rms_deviation_m},
      {"mean_lambda", s.mean_lambda},
      {"min_lambda", s.min_lambda},
      {"assistance_dependence", s.assistance_dependence},
      {"collisions", double(s.collisions)},
      {"min_clearance_m", s.min_clearance_m},
      {"override_rms", s.override_rms},
      {"stick_smoothness", s.stick_smoothness},
      {"rti_median_us", s.rti_median_us},
      {"rti_p99_us", s.rti_p99_us},
      {"deadline_misses", double(s.deadline_misses)},
      {"fallbacks", double(s.fallbacks)},
      {"skill", s.skill},
      {"input_lost_s", s.input_lost_s},
      {"safe_hold_s", s.safe_hold_s},
  };
}

}  // namespace mixpilot
