// The score's formulas (README, "Scoring"; core/modes/score.hpp) against values worked out by
// hand on a made-up five-step flight: the weights of the skill, the progress window, a
// collision counted once per contact, the override and the stick's smoothness, the times with
// the input lost and under the safe controller.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/modes/score.hpp"

namespace mixpilot {
namespace {

struct StepSpec {
  Eigen::Vector3d p, ref;
  double lambda;
  double roll_h, pitch_h, roll_mpc, pitch_mpc;
  std::uint32_t events = 0;
  RtiStatus status = RtiStatus::success;
  InputState input = InputState::ok;
};

// Δt = 0.5 s, a 3 s flight (6 steps planned, 5 flown), r = 0.2 m, r_v = 0.1 m, one obstacle of
// radius 0.5 m at (4, 1.55, 1) in a 10 m box. The reference walks 1 m per step along x.
Scenario scenario() {
  Scenario sc;
  sc.controller.dt = 0.5;
  sc.duration = 3.0;
  sc.controller.ph.r = 0.2;
  sc.controller.vehicle_radius = 0.1;
  sc.arena.min = Eigen::Vector3d(0, 0, 0);
  sc.arena.max = Eigen::Vector3d(10, 10, 10);
  sc.arena.obstacles = {Obstacle{Eigen::Vector3d(4, 1.55, 1), 0.5}};
  return sc;
}

std::vector<StepSpec> flight() {
  using V = Eigen::Vector3d;
  return {
      {V(1, 1, 1), V(1, 1, 1), 0.9, 0.1, 0.0, 0.1, 0.0},
      // On the floor (z = 0.05 < r_v): a contact starts; 0.95 m from the reference.
      {V(2, 1, 0.05), V(2, 1, 1), 0.5, 0.2, 0.0, 0.1, 0.0, kEventDeadlineMiss},
      {V(3, 1.1, 1), V(3, 1, 1), 0.1, 0.2, 0.1, 0.2, 0.0, 0, RtiStatus::fallback},
      // Into the obstacle (clearance −0.05 m): a second contact starts ...
      {V(4, 1, 1), V(4, 1, 1), 0.7, 0.0, 0.1, 0.0, 0.0, 0, RtiStatus::success, InputState::lost},
      // ... and goes on (−0.1076 m): still the second collision.
      {V(4.2, 1.1, 1), V(5, 1, 1), 0.3, 0.0, 0.0, 0.1, 0.0, kEventSafeHold},
  };
}

TEST(ScoreFormula, EveryFieldAsWorkedOutByHand) {
  const Scenario sc = scenario();
  ScoreAccumulator acc(sc);
  int contacts_started = 0;
  for (const StepSpec& f : flight()) {
    Telemetry s;
    s.x = Eigen::VectorXd::Zero(16);
    s.x.head<3>() = f.p;
    s.reference = f.ref;
    s.lambda = f.lambda;
    s.pilot.roll = f.roll_h;
    s.pilot.pitch = f.pitch_h;
    s.pilot.input = f.input;
    s.applied.roll = f.roll_mpc;
    s.applied.pitch = f.pitch_mpc;
    s.stats.status = f.status;
    s.stats.total_us = 100.0;
    s.events = f.events;
    contacts_started += acc.add(s) ? 1 : 0;
  }
  const Score s = acc.finish();
  EXPECT_EQ(contacts_started, 2);
  EXPECT_DOUBLE_EQ(s.duration_s, 2.5);  // 5 steps of 0.5 s
  // Deviations 0, 0.95, 0.1, 0, 0.8062: three inside r = 0.2.
  EXPECT_DOUBLE_EQ(s.time_in_ball, 0.6);
  EXPECT_DOUBLE_EQ(s.max_deviation_m, 0.95);
  EXPECT_NEAR(s.rms_deviation_m, std::sqrt((0.95 * 0.95 + 0.01 + 0.65) / 5), 1e-12);
  // Waypoints reached within ±1 s (±2 steps) by some position: 0, 2 and 3 of the 6 planned.
  EXPECT_DOUBLE_EQ(s.progress, 0.5);
  EXPECT_DOUBLE_EQ(s.mean_lambda, 0.5);
  EXPECT_DOUBLE_EQ(s.min_lambda, 0.1);
  // The floor, then the obstacle over two steps: two collisions, not three.
  EXPECT_EQ(s.collisions, 2);
  EXPECT_NEAR(s.min_clearance_m, std::hypot(0.2, 0.45) - 0.6, 1e-12);
  // Four steps whose pilot attitude differs from the MPC's by 0.1 rad.
  EXPECT_NEAR(s.override_rms, std::sqrt(4 * 0.01 / 5), 1e-12);
  // Changes of the pilot's attitude: 0.1, 0.1, 0.2, 0.1 rad per 0.5 s.
  EXPECT_NEAR(s.stick_smoothness, std::sqrt((0.04 + 0.04 + 0.16 + 0.04) / 4), 1e-12);
  EXPECT_EQ(s.fallbacks, 1);
  EXPECT_EQ(s.deadline_misses, 1);
  EXPECT_DOUBLE_EQ(s.input_lost_s, 0.5);
  EXPECT_DOUBLE_EQ(s.safe_hold_s, 0.5);
  // 100 · progress · (0.4 time_in_ball + 0.4 mean_lambda + 0.2 exp(−override / 0.1)) /
  // (1 + collisions) = 100 · 0.5 · (0.24 + 0.2 + 0.2 · exp(−0.894427)) / 3.
  EXPECT_NEAR(s.skill, 8.69613906599268, 1e-9);
}

// Progress counts a waypoint as flown when the vehicle came within r of it at most 1 s before
// or after (README): a vehicle that trails the reference by exactly 1 s flies every waypoint
// but the last one's second, one that trails by 1.5 s none but the first.
TEST(ScoreFormula, ProgressForgivesALagOfOneSecondAndNoMore) {
  Scenario sc = scenario();
  sc.arena.obstacles.clear();
  sc.duration = 5.0;  // 10 steps of 0.5 s
  const auto progress_with_lag = [&](int lag_steps) {
    ScoreAccumulator acc(sc);
    for (int k = 0; k < 10; ++k) {
      Telemetry s;
      s.x = Eigen::VectorXd::Zero(16);
      s.reference = Eigen::Vector3d(1 + k, 1, 1);
      s.x.head<3>() = Eigen::Vector3d(1 + std::max(0, k - lag_steps), 1, 1);
      s.stats.total_us = 1.0;
      (void)acc.add(s);
    }
    return acc.finish().progress;
  };
  // Lag 2 steps (1 s): waypoints 0..7 are reached within the window (8 of 10).
  EXPECT_DOUBLE_EQ(progress_with_lag(2), 0.8);
  // Lag 3 steps (1.5 s): only waypoint 0, where the vehicle waits, is reached.
  EXPECT_DOUBLE_EQ(progress_with_lag(3), 0.1);
}

// The skill's weights one at a time, on a flight that is perfect but for one quantity.
TEST(ScoreFormula, TheSkillWeighsEachQuantityAsDocumented) {
  const auto skill = [](double in_ball, double lambda, double override_rad, int collisions,
                        double progress) {
    return 100.0 * progress *
           (0.4 * in_ball + 0.4 * lambda + 0.2 * std::exp(-override_rad / 0.1)) /
           (1.0 + collisions);
  };
  Scenario sc = scenario();
  sc.arena.obstacles.clear();
  sc.duration = 2.0;  // 4 steps: every waypoint flown
  for (const double lambda : {0.25, 1.0}) {
    ScoreAccumulator acc(sc);
    for (int k = 0; k < 4; ++k) {
      Telemetry s;
      s.x = Eigen::VectorXd::Zero(16);
      s.x.head<3>() = Eigen::Vector3d(1 + k, 1, 1);
      s.reference = s.x.head<3>();
      s.lambda = lambda;
      s.stats.total_us = 1.0;
      (void)acc.add(s);
    }
    const Score s = acc.finish();
    EXPECT_DOUBLE_EQ(s.progress, 1.0);
    EXPECT_DOUBLE_EQ(s.time_in_ball, 1.0);
    EXPECT_NEAR(s.skill, skill(1.0, lambda, 0.0, 0, 1.0), 1e-12) << lambda;
  }
}


// D = (1/T)∫(1 − λ) dt over the flown steps, by the rectangle rule of Δt per step (README,
// Scoring): the made-up flight's λ are 0.9, 0.5, 0.1, 0.7, 0.3 over 5 steps of 0.5 s, so
// ∫(1 − λ) dt = 0.5 · (0.1 + 0.5 + 0.9 + 0.3 + 0.7) = 1.25 s of T = 2.5 s.
TEST(AssistanceDependence, IsTheShareOfTheFlightThePlannerFlewWorkedOutByHand) {
  const Scenario sc = scenario();
  ScoreAccumulator acc(sc);
  for (const StepSpec& f : flight()) {
    Telemetry s;
    s.x = Eigen::VectorXd::Zero(16);
    s.x.head<3>() = f.p;
    s.reference = f.ref;
    s.lambda = f.lambda;
    (void)acc.add(s);
  }
  const Score s = acc.finish();
  EXPECT_DOUBLE_EQ(s.assistance_dependence, 1.25 / 2.5);
  // Between mean_lambda and the rest of the report, in every report's metrics.
  const Metrics m = to_metrics(s);
  const auto at = std::find_if(m.begin(), m.end(),
                               [](const auto& kv) { return kv.first == "assistance_dependence"; });
  ASSERT_NE(at, m.end());
  EXPECT_EQ((at - 1)->first, "min_lambda");
  EXPECT_EQ(at->second, s.assistance_dependence);
}

// λ ≡ 1 (the pilot flew it all): D is exactly 0. Any other λ: D = 1 − mean_lambda to rounding,
// and weighted by the time each λ lasted (a λ held longer counts more).
TEST(AssistanceDependence, IsZeroWhenThePilotFlewItAllAndOneMinusTheMeanLambda) {
  Scenario sc = scenario();
  sc.arena.obstacles.clear();
  sc.duration = 50.0;  // 100 steps of 0.5 s
  const auto fly = [&](auto lambda_of) {
    ScoreAccumulator acc(sc);
    for (int k = 0; k < 100; ++k) {
      Telemetry s;
      s.x = Eigen::VectorXd::Zero(16);
      s.x.head<3>() = Eigen::Vector3d(1, 1, 1);
      s.reference = Eigen::Vector3d(1, 1, 1);
      s.lambda = lambda_of(k);
      (void)acc.add(s);
    }
    return acc.finish();
  };
  const Score pilot = fly([](int) { return 1.0; });
  EXPECT_EQ(pilot.assistance_dependence, 0.0);
  EXPECT_EQ(pilot.mean_lambda, 1.0);

  const Score mixed = fly([](int k) { return 0.5 + 0.45 * std::sin(0.37 * k); });
  double by_hand = 0;
  for (int k = 0; k < 100; ++k) by_hand += 0.5 * (1.0 - (0.5 + 0.45 * std::sin(0.37 * k)));
  EXPECT_NEAR(mixed.assistance_dependence, by_hand / 50.0, 1e-15);
  EXPECT_NEAR(mixed.assistance_dependence, 1.0 - mixed.mean_lambda, 1e-15);
  EXPECT_GT(mixed.assistance_dependence, 0.0);

  // Three quarters of the time at λ = 0.2, one quarter at λ = 1: D = 0.75 · 0.8 = 0.6.
  const Score planner = fly([](int k) { return k < 75 ? 0.2 : 1.0; });
  EXPECT_NEAR(planner.assistance_dependence, 0.6, 1e-15);
}

}  // namespace
}  // namespace mixpilot
