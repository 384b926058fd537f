// Pendubot swing-up (core/modes/pendubot_swingup.hpp, SPEC §5.1, issue 6): the shipped scenarios reach
// and hold up-up with |u| ≤ 0.4 (exact state and encoders), velocity-bound violations are
// reported, the LQR stabilizes the linearization, the committed Ipopt reference satisfies the
// dynamics and bounds, and scenario errors name file:line:col: key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "core/modes/mode.hpp"
#include "core/modes/pendubot_mode.hpp"
#include "core/nlp/trajectory_io.hpp"

#ifndef MIXPILOT_SOURCE_DIR
#error "MIXPILOT_SOURCE_DIR must point to the repository root"
#endif

namespace mixpilot {
namespace {

const std::string kDir = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/";

PendubotScenario load(const std::string& file) {
  std::string error;
  const auto sc = load_pendubot_scenario(kDir + file, error);
  EXPECT_TRUE(sc) << error;
  return sc ? *sc : PendubotScenario{};
}

void expect_swings_up_and_holds(const PendubotScenario& sc) {
  const PendubotRun run = simulate_pendubot_swingup(sc, true);
  ASSERT_TRUE(run.swingup_time) << "final |angles| " << run.final_angle_norm;
  EXPECT_LE(*run.swingup_time, sc.duration - 5.0);  // then held ≥ 5 s
  EXPECT_LE(run.final_angle_norm, sc.angle_tolerance);
  EXPECT_LE(run.max_abs_u, 0.4);
  for (std::size_t k = 0; k < run.u.size(); ++k) {
    ASSERT_LE(std::abs(run.u[k]), 0.4) << "t = " << run.t[k];
    if (run.t[k] >= *run.swingup_time) {
      ASSERT_LE(std::hypot(wrap_angle(run.x[k](0)), wrap_angle(run.x[k](1))), 0.05)
          << "t = " << run.t[k];
    }
  }
  EXPECT_EQ(run.fallbacks, 0);
  EXPECT_GT(run.nmpc_steps, 100);
  EXPECT_GT(run.lqr_time, 5.0);
  EXPECT_EQ(run.velocity_violations, 0);  // the reference keeps 10 % margin
}

TEST(Pendubot, ShippedScenarioSwingsUpAndHolds) {
  const PendubotScenario sc = load("pendubot_swingup.toml");
  EXPECT_FALSE(sc.sensor.quantization);
  EXPECT_EQ(sc.controller.N, 10);
  EXPECT_EQ(sc.controller.dt, 0.002);
  EXPECT_EQ(sc.controller.qp_solver, QpSolverKind::condensed_active_set);
  expect_swings_up_and_holds(sc);
}

TEST(Pendubot, EncoderScenarioSwingsUpAndHolds) {
  const PendubotScenario sc = load("pendubot_swingup_encoders.toml");
  EXPECT_TRUE(sc.sensor.quantization);
  EXPECT_EQ(sc.sensor.counts_q1, 8192);
  EXPECT_EQ(sc.sensor.counts_q2, 4096);
  expect_swings_up_and_holds(sc);
}

TEST(Pendubot, VelocityViolationsAreReported) {
  // Soft bounds below the reference's velocities (7, 4.5 rad/s): the NMPC trades slack.
  PendubotScenario sc = load("pendubot_swingup.toml");
  sc.controller.velocity_bound = Eigen::Vector2d(5.0, 3.0);
  sc.duration = 1.0;
  const PendubotRun run = simulate_pendubot_swingup(sc, true);
  EXPECT_GT(run.velocity_violations, 0);
  EXPECT_GT(run.worst_velocity_violation, 0.0);
  double worst_logged = 0.0;
  int logged = 0;
  for (const auto& x : run.x) {
    const double e = std::max(std::abs(x(2)) - 5.0, std::abs(x(3)) - 3.0);
    worst_logged = std::max(worst_logged, e);
    logged += e > 0;
  }
  // Substeps are checked too, so the report bounds the control-rate samples from above.
  EXPECT_GE(run.worst_velocity_violation, worst_logged);
  EXPECT_GE(run.velocity_violations, logged - 1);
}

TEST(Pendubot, LqrStabilizesTheLinearization) {
  const PendubotScenario sc = load("pendubot_swingup.toml");
  const models::Pendubot model;
  const PendubotLqr l = pendubot_lqr(model, 0.002, sc.lqr.q, sc.lqr.r);
  ASSERT_TRUE(l.converged);
  const Eigen::EigenSolver<Eigen::Matrix4d> open(l.A);
  EXPECT_GT(open.eigenvalues().cwiseAbs().maxCoeff(), 1.0);  // up-up is unstable
  const Eigen::Matrix4d Acl = l.A - l.B * l.K;
  const double rho = Eigen::EigenSolver<Eigen::Matrix4d>(Acl).eigenvalues().cwiseAbs().maxCoeff();
  EXPECT_LT(rho, 1.0);
  EXPECT_NEAR(rho, l.spectral_radius, 1e-12);
  // DARE residual.
  const Eigen::Matrix4d Q = sc.lqr.q.asDiagonal();
  const Eigen::Matrix4d P = l.P;
  const double s = sc.lqr.r + l.B.dot(P * l.B);
  const Eigen::RowVector4d BtPA = l.B.transpose() * P * l.A;
  const Eigen::Matrix4d res = Q + l.A.transpose() * P * l.A - BtPA.transpose() * BtPA / s - P;
  EXPECT_LT(res.cwiseAbs().maxCoeff(), 1e-9 * P.cwiseAbs().maxCoeff());
}

TEST(Pendubot, ReferenceSatisfiesDynamicsAndBounds) {
  std::string error;
  const auto ref = read_trajectory_csv(kDir + "references/pendubot_swingup.csv", error);
  ASSERT_TRUE(ref) << error;
  EXPECT_NEAR(ref->dt, 0.002, 1e-15);
  const auto& t = ref->trajectory;
  ASSERT_GE(t.u.size(), 1000u);  // T ≥ 2 s
  EXPECT_LT((t.x[0] - models::Pendubot::down_down()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(t.x.back().cwiseAbs().maxCoeff(), 1e-3);  // ends at up-up
  const IntegratorErk4<models::Pendubot> erk4;
  double residual = 0.0;
  for (std::size_t i = 0; i < t.u.size(); ++i) {
    EXPECT_LE(std::abs(t.u[i](0)), 0.4);
    models::Pendubot::State xn;
    erk4.step<double>(models::Pendubot::State(t.x[i]), models::Pendubot::Input(t.u[i]), ref->dt,
                      xn);
    residual = std::max(residual, (xn - t.x[i + 1]).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(residual, 1e-8);
  for (const auto& x : t.x) {
    EXPECT_LE(std::abs(x(2)), 7.8);
    EXPECT_LE(std::abs(x(3)), 5.0);
  }
}

TEST(Pendubot, ModeRunnerReportsMetrics) {
  const ModeRunner runner = find_mode_runner("pendubot_swingup");
  ASSERT_NE(runner, nullptr);
  ModeOptions o;
  o.duration = 3.0;
  const ModeResult r = runner(kDir + "pendubot_swingup.toml", o);
  ASSERT_TRUE(r.ok) << r.error;
  auto metric = [&](const std::string& name) {
    for (const auto& [n, v] : r.metrics)
      if (n == name) return v;
    ADD_FAILURE() << "no metric " << name;
    return std::nan("");
  };
  EXPECT_EQ(metric("duration_s"), 3.0);
  EXPECT_GT(metric("swingup_time_s"), 0.5);
  EXPECT_LE(metric("max_abs_u"), 0.4);
  EXPECT_EQ(metric("velocity_violations"), 0.0);
  EXPECT_GE(metric("worst_velocity_violation"), 0.0);
  EXPECT_GE(metric("tracking_rms"), 0.0);
  EXPECT_GT(metric("rti_median_us"), 0.0);
  EXPECT_GE(metric("rti_p99_us"), metric("rti_median_us"));
  EXPECT_EQ(metric("fallbacks"), 0.0);
  EXPECT_GT(metric("lqr_time_s"), 1.0);
}

// The error for a scenario text (source named tests.toml in scenarios/, so the reference path
// resolves); empty when it parses.
std::string error_of(const std::string& text) {
  std::string error;
  const auto sc = parse_pendubot_scenario(text, kDir + "t.toml", error);
  EXPECT_EQ(sc.has_value(), error.empty());
  return error;
}

constexpr const char* kHead =
    "name = \"t\"\n"
    "mode = \"pendubot_swingup\"\n"
    "model = \"pendubot\"\n"
    "[controller]\n"
    "reference = \"references/pendubot_swingup.csv\"\n";

TEST(Pendubot, MinimalScenarioTakesDefaults) {
  std::string error;
  const auto sc = parse_pendubot_scenario(kHead, kDir + "t.toml", error);
  ASSERT_TRUE(sc) << error;
  EXPECT_EQ(sc->controller.weights, (Eigen::Matrix<double, 5, 1>(3, 3, 1, 1, 5)));
  EXPECT_EQ(sc->controller.terminal_weights, Eigen::Vector4d(3, 3, 1, 1));
  EXPECT_EQ(sc->controller.u_max, 0.4);
  EXPECT_EQ(sc->controller.velocity_bound, Eigen::Vector2d(7.8, 5.0));
  EXPECT_EQ(sc->controller.slack_weight, 40.0);
  EXPECT_EQ(sc->plant.rate_hz, 4000.0);
  EXPECT_EQ(sc->plant.initial_state, models::Pendubot::down_down());
  EXPECT_GT(sc->reference.trajectory.u.size(), 0u);
}

TEST(Pendubot, ScenarioErrorsNameFileLineKey) {
  const std::string f = kDir + "t.toml:";
  EXPECT_EQ(error_of(std::string(kHead) + "N = 10.5\n"),
            f + "6:5: controller.N: expected an integer, got 10.5");
  EXPECT_EQ(error_of(std::string(kHead) + "velocity_bnd = [1.0, 2.0]\n"),
            f + "6:1: controller.velocity_bnd: unknown key (did you mean \"velocity_bound\"?)");
  EXPECT_EQ(error_of(std::string(kHead) + "weights = [3.0, 3.0, 1.0, 1.0]\n"),
            f + "6:11: controller.weights: expected an array of 5 numbers, got an array of 4");
  EXPECT_EQ(error_of(std::string(kHead) + "[lqr]\nenter_angle = 0.5\nexit_angle = 0.3\n"),
            f + "8:14: lqr.exit_angle: expected more than lqr.enter_angle = 0.5 (hysteresis), "
                "got 0.3");
  EXPECT_EQ(error_of(std::string(kHead) + "[plant]\nrate_hz = 3300\n"),
            f + "7:11: plant.rate_hz: expected a rate giving a whole number of substeps per "
                "control step, got controller.dt * rate_hz = 6.6000000000000005");
  EXPECT_EQ(error_of(std::string(kHead) + "[sensor]\nestimator = \"kalman\"\n"),
            f + "7:13: sensor.estimator: expected one of \"difference\", \"observer\", got the "
                "string \"kalman\"");
  const std::string wrong_dt = error_of(std::string(kHead) + "dt = 0.004\n");
  EXPECT_EQ(wrong_dt.rfind(f + "5:13: controller.reference: expected a trajectory sampled at "
                               "controller.dt = 0.004 s, got dt = 0.002 s", 0), 0u) << wrong_dt;
  const std::string missing = error_of(
      "name = \"t\"\nmode = \"pendubot_swingup\"\nmodel = \"pendubot\"\n[controller]\n"
      "reference = \"references/nope.csv\"\n");
  EXPECT_EQ(missing.rfind(f + "5:13: controller.reference: expected a readable trajectory CSV", 0),
            0u) << missing;
  EXPECT_EQ(error_of("name = \"t\"\nmode = \"pendubot_swingup\"\nmodel = \"crazyflie\"\n[controller]\n"
                     "reference = \"references/pendubot_swingup.csv\"\n"),
            f + "3:9: model: expected one of \"pendubot\", got the string \"crazyflie\"");
  EXPECT_EQ(error_of("name = \"t\"\nmode = \"pendubot_swingup\"\nmodel = \"pendubot\"\n"),
            f + "1:1: controller.reference: missing required key (expected a string)");
}

}  // namespace
}  // namespace mixpilot
