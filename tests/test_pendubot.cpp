// Pendubot swing-up (core/modes/pendubot_mode.hpp, SPEC §5.1, thesis ch. 4): the shipped
// scenarios reach up-up and balance there (exact state and encoders), the LQR law is applied
// unsaturated once it holds the arm, velocity-bound violations match a replay of the plant, the
// LQR is the optimal one of its linearization, the committed Ipopt reference satisfies the
// dynamics and bounds, the telemetry describes each step, setup fails with the reason on invalid
// settings, and scenario errors name file:line:col: key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/control/pendubot.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/pendubot_mode.hpp"
#include "core/nlp/trajectory_io.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/scenario/pendubot_scenario.hpp"
#include "fly_scenario.hpp"

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

// One run of PendubotMode: the telemetry of every step and the true state before it.
struct Trace {
  std::vector<Telemetry> steps;
  std::vector<Eigen::Vector4d> x_before;  // mode.state() before step k: x_k
  Eigen::Vector4d x_final = Eigen::Vector4d::Zero();
  PendubotRun result;
  Eigen::RowVector4d K = Eigen::RowVector4d::Zero();
};

Trace trace(const PendubotScenario& sc) {
  Trace tr;
  PendubotMode mode;
  const SetupResult r = mode.setup(sc);
  EXPECT_TRUE(r.ok()) << r.reason();
  tr.steps.reserve(std::size_t(mode.steps_total()));
  for (;;) {
    const Eigen::Vector4d x = mode.state();
    if (!mode.step()) break;
    tr.x_before.push_back(x);
    tr.steps.push_back(mode.telemetry());
  }
  tr.x_final = mode.state();
  tr.result = mode.result();
  tr.K = mode.lqr().K;
  return tr;
}

Eigen::Vector4d wrapped(const Eigen::Vector4d& x) {
  return Eigen::Vector4d(wrap_angle(x(0)), wrap_angle(x(1)), x(2), x(3));
}

double angle_norm(const Eigen::Vector4d& x) {
  return std::hypot(wrap_angle(x(0)), wrap_angle(x(1)));
}

// Up-up reached and held for ≥ 5 s; over the last second the balance keeps ‖wrap(q)‖ at RMS
// ≤ balance_rms (far inside the 0.05 rad success tolerance, which only defines the swing-up
// time); the LQR holds the arm with its unsaturated law on the estimate.
void expect_swings_up_and_holds(const PendubotScenario& sc, double balance_rms) {
  const Trace tr = trace(sc);
  const PendubotRun& run = tr.result;
  ASSERT_TRUE(run.swingup_time) << "final |angles| " << run.final_angle_norm;
  EXPECT_LE(*run.swingup_time, sc.duration - 5.0);
  double sum2 = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < tr.steps.size(); ++k) {
    const Telemetry& s = tr.steps[k];
    if (s.t >= sc.duration - 1.0) {
      sum2 += std::pow(angle_norm(s.x), 2);
      ++n;
    }
    if (s.solved) continue;
    // LQR step: u = −K wrap(x̂), inside |u| ≤ u_max without the clamp (the hand-over admits
    // the LQR only in its linear region, and the balance must keep it there).
    const double u_lqr = -tr.K.dot(wrapped(s.x_measured));
    ASSERT_LE(std::abs(u_lqr), sc.controller.u_max) << "t = " << s.t;
    ASSERT_NEAR(s.u(0), u_lqr, 1e-15) << "t = " << s.t;  // |u| < 0.4: to rounding
  }
  ASSERT_GT(n, 0);
  EXPECT_LE(std::sqrt(sum2 / n), balance_rms);
  EXPECT_EQ(run.fallbacks, 0);
  EXPECT_GT(run.nmpc_steps, 100);
  EXPECT_GT(run.lqr_time, 5.0);
  EXPECT_EQ(run.lqr_entries, 1);
  EXPECT_EQ(run.velocity_violations, 0);  // the reference keeps 10 % margin
}

TEST(Pendubot, ShippedScenarioSwingsUpAndHolds) {
  const PendubotScenario sc = load("pendubot_swingup.toml");
  EXPECT_FALSE(sc.sensor.quantization);
  EXPECT_EQ(sc.controller.N, 10);
  EXPECT_EQ(sc.controller.dt, 0.002);
  EXPECT_EQ(sc.controller.qp_solver, QpSolverKind::condensed_active_set);
  // Exact state: the LQR drives the linearization to the equilibrium; 1e-4 rad leaves a wide
  // margin over the ~3e-6 rad the decaying slow mode still has in the last second.
  expect_swings_up_and_holds(sc, 1e-4);
}

TEST(Pendubot, EncoderScenarioSwingsUpAndHolds) {
  const PendubotScenario sc = load("pendubot_swingup_encoders.toml");
  EXPECT_TRUE(sc.sensor.quantization);
  EXPECT_EQ(sc.sensor.counts_q1, 8192);
  EXPECT_EQ(sc.sensor.counts_q2, 4096);
  // Encoders: the balance dithers at the quantization level; two counts of q2 (2 · 2π/4096 ≈
  // 3.1e-3 rad) bound it.
  expect_swings_up_and_holds(sc, 2.0 * 2.0 * std::numbers::pi / 4096);
}

// The metrics against the run's own telemetry, recomputed here: the swing-up time, the final
// norm, max |u|, the NMPC step count and the LQR time and entries.
TEST(Pendubot, MetricsMatchTheTelemetry) {
  const PendubotScenario sc = load("pendubot_swingup_encoders.toml");
  const Trace tr = trace(sc);
  const PendubotRun& run = tr.result;
  const double dt = sc.controller.dt;
  std::vector<double> norms;
  for (const Eigen::Vector4d& x : tr.x_before) norms.push_back(angle_norm(x));
  norms.push_back(angle_norm(tr.x_final));
  std::size_t first_held = norms.size();
  while (first_held > 0 && norms[first_held - 1] <= sc.angle_tolerance) --first_held;
  ASSERT_LT(first_held, norms.size());
  ASSERT_TRUE(run.swingup_time);
  EXPECT_EQ(*run.swingup_time, double(first_held) * dt);
  EXPECT_EQ(run.final_angle_norm, norms.back());
  double max_u = 0.0;
  int nmpc = 0, entries = 0;
  double lqr_time = 0.0, entry_time = -1.0;
  bool lqr_before = false;
  for (const Telemetry& s : tr.steps) {
    max_u = std::max(max_u, std::abs(s.u(0)));
    nmpc += s.solved;
    if (!s.solved) lqr_time += dt;
    if (!s.solved && !lqr_before) {
      ++entries;
      if (entry_time < 0) entry_time = s.t;
    }
    lqr_before = !s.solved;
  }
  EXPECT_EQ(run.max_abs_u, max_u);
  EXPECT_EQ(run.nmpc_steps, nmpc);
  EXPECT_EQ(run.lqr_entries, entries);
  EXPECT_EQ(run.lqr_entry_time, entry_time);
  EXPECT_NEAR(run.lqr_time, lqr_time, 1e-9);
  EXPECT_EQ(run.steps, int(tr.steps.size()));
}

// Soft bounds below the reference's velocities (7, 4.5 rad/s): the NMPC trades slack and the
// plant exceeds them. The count and the worst excess must be those of a replay of the plant
// from the telemetry (x_k, u_k held over Δt, RK4 substeps at rate_hz), substeps included.
TEST(Pendubot, VelocityViolationsMatchAReplayOfThePlant) {
  PendubotScenario sc = load("pendubot_swingup.toml");
  const Eigen::Vector2d bound(5.0, 3.0);
  sc.controller.velocity_bound = bound;
  sc.duration = 1.0;
  const Trace tr = trace(sc);
  const IntegratorErk4<models::Pendubot> erk4;
  const int substeps = int(std::lround(sc.controller.dt * sc.plant.rate_hz));
  const double h = sc.controller.dt / substeps;
  int violations = 0;
  double worst = 0.0;
  for (std::size_t k = 0; k < tr.steps.size(); ++k) {
    const Telemetry& s = tr.steps[k];
    models::Pendubot::State x = s.x, xn;
    double step_worst = 0.0;
    for (int j = 0; j < substeps; ++j) {
      erk4.step<double>(x, models::Pendubot::Input(s.u(0)), h, xn);
      x = xn;
      step_worst = std::max({step_worst, std::abs(x(2)) - bound(0), std::abs(x(3)) - bound(1)});
    }
    const Eigen::Vector4d next = k + 1 < tr.steps.size() ? tr.x_before[k + 1] : tr.x_final;
    ASSERT_LT((x - next).cwiseAbs().maxCoeff(), 1e-12) << "k = " << k;
    violations += step_worst > 0;
    worst = std::max(worst, step_worst);
    EXPECT_EQ((s.events & kEventViolation) != 0, step_worst > 0) << "k = " << k;
  }
  EXPECT_GT(violations, 0);
  EXPECT_EQ(tr.result.velocity_violations, violations);
  EXPECT_NEAR(tr.result.worst_velocity_violation, worst, 1e-12);
}

TEST(Pendubot, LqrIsTheOptimalLawOfTheLinearization) {
  const PendubotScenario sc = load("pendubot_swingup.toml");
  const models::Pendubot model;
  const PendubotLqr l = pendubot_lqr(model, 0.002, sc.lqr.q, sc.lqr.r);
  ASSERT_TRUE(l.converged);
  const Eigen::EigenSolver<Eigen::Matrix4d> open(l.A);
  EXPECT_GT(open.eigenvalues().cwiseAbs().maxCoeff(), 1.0);  // up-up is unstable
  const Eigen::Matrix4d Acl = l.A - l.B * l.K;
  const double rho = Eigen::EigenSolver<Eigen::Matrix4d>(Acl).eigenvalues().cwiseAbs().maxCoeff();
  EXPECT_LT(rho, 1.0);
  // DARE residual.
  const Eigen::Matrix4d Q = sc.lqr.q.asDiagonal();
  const Eigen::Matrix4d P = l.P;
  const double s = sc.lqr.r + l.B.dot(P * l.B);
  const Eigen::RowVector4d BtPA = l.B.transpose() * P * l.A;
  const Eigen::Matrix4d res = Q + l.A.transpose() * P * l.A - BtPA.transpose() * BtPA / s - P;
  EXPECT_LT(res.cwiseAbs().maxCoeff(), 1e-9 * P.cwiseAbs().maxCoeff());
  // P is the cost to go of u = −K x: Σ_j x_jᵀQx_j + r u_j² from x_0 = e_i equals P_ii. The
  // sum is rounded over ~1e4 terms (≈ 1e-12 relative), the tolerance is 1e-9.
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector4d x = Eigen::Vector4d::Unit(i);
    double cost = 0.0;
    for (int j = 0; j < 1000000 && x.norm() > 1e-13; ++j) {
      const double u = -l.K.dot(x);
      cost += x.dot(Q * x) + sc.lqr.r * u * u;
      x = l.A * x + l.B * u;
    }
    EXPECT_NEAR(cost, P(i, i), 1e-9 * P(i, i)) << "i = " << i;
  }
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

// Step k reports x_k (the state before its plant substeps), x̂_k, u_k, the reference node k (up-up
// past the last node), the active controller and the channels a view plots.
TEST(Pendubot, TelemetryDescribesEachStep) {
  PendubotScenario sc = load("pendubot_swingup.toml");
  sc.duration = 3.0;  // past the reference's 2.5 s
  const OcpTrajectory& ref = sc.reference.trajectory;
  PendubotMode mode;
  ASSERT_TRUE(mode.setup(sc).ok());
  EXPECT_EQ(mode.kind(), ModeKind::pendubot_swingup);
  EXPECT_EQ(mode.steps_total(), 1500);
  const Telemetry& s = mode.telemetry();
  EXPECT_EQ(s.step, 0);
  EXPECT_EQ(s.t, 0.0);
  EXPECT_EQ(Eigen::Vector4d(s.x), sc.plant.initial_state);
  EXPECT_EQ(s.u(0), 0.0);
  EXPECT_FALSE(s.solved);
  EXPECT_EQ(s.events, 0u);
  EXPECT_EQ(s.num_channels, int(kPendubotChannels));

  const char* const names[] = {"q1",           "q2",           "dq1",           "dq2",
                               "q1 reference", "q2 reference", "dq1 reference", "dq2 reference",
                               "torque",       "LQR active",   "angle norm",    "dq1 bound",
                               "dq2 bound",    "torque bound"};
  const char* const units[] = {"rad", "rad", "rad/s", "rad/s", "rad", "rad", "rad/s", "rad/s",
                               "N m", "",    "rad",   "rad/s", "rad/s", "N m"};
  bool lqr_before = false;
  int switches = 0, past_reference = 0;
  for (std::int64_t k = 0;; ++k) {
    const Eigen::Vector4d x_k = mode.state();
    if (!mode.step()) break;
    ASSERT_EQ(s.step, k);
    ASSERT_EQ(s.t, double(k) * sc.controller.dt);
    ASSERT_EQ(Eigen::Vector4d(s.x), x_k) << "k = " << k;
    ASSERT_EQ(Eigen::Vector4d(s.x_measured), x_k);  // exact state: x̂ = x
    if (std::size_t(k) < ref.x.size()) {
      ASSERT_EQ(Eigen::Vector4d(s.reference), Eigen::Vector4d(ref.x[std::size_t(k)]));
    } else {
      ASSERT_EQ(Eigen::Vector4d(s.reference), Eigen::Vector4d::Zero());
      ++past_reference;
    }
    const bool lqr = !s.solved;
    ASSERT_EQ((s.events & kEventSwitch) != 0, lqr != lqr_before) << "k = " << k;
    switches += lqr != lqr_before;
    lqr_before = lqr;
    if (s.solved) {
      ASSERT_GT(s.stats.total_us, 0.0);
    }
    ASSERT_EQ(s.events & (kEventFallback | kEventViolation | kEventLost), 0u);
    ASSERT_EQ(s.num_channels, int(kPendubotChannels));
    for (int c = 0; c < kPendubotChannels; ++c) {
      ASSERT_STREQ(s.channels[std::size_t(c)].name, names[c]);
      ASSERT_STREQ(s.channels[std::size_t(c)].unit, units[c]);
    }
    auto channel = [&](int c) { return s.channels[std::size_t(c)].value; };
    const Eigen::Vector4d xw = wrapped(x_k), rw = wrapped(s.reference);
    for (int i = 0; i < 4; ++i) {
      ASSERT_EQ(channel(kPendubotQ1 + i), xw(i));
      ASSERT_EQ(channel(kPendubotQ1Reference + i), rw(i));
    }
    ASSERT_EQ(channel(kPendubotTorque), s.u(0));
    ASSERT_EQ(channel(kPendubotLqrActive), lqr ? 1.0 : 0.0);
    ASSERT_NEAR(channel(kPendubotAngleNorm), xw.head<2>().norm(), 1e-15);
    ASSERT_EQ(channel(kPendubotDq1Bound), 7.8);
    ASSERT_EQ(channel(kPendubotDq2Bound), 5.0);
    ASSERT_EQ(channel(kPendubotTorqueBound), 0.4);
  }
  EXPECT_TRUE(mode.finished());
  EXPECT_EQ(mode.steps_done(), 1500);
  EXPECT_EQ(switches, 1);  // one hand-over to the LQR, which keeps the arm
  EXPECT_EQ(past_reference, 1500 - int(ref.x.size()));
  EXPECT_FALSE(mode.step());  // the run is over
}

// Hysteresis: from q = (0.05, 0.05) rad at rest the NMPC hands the arm to the LQR within a few
// steps, with momentum that carries ‖wrap(q̂)‖ past an exit angle of 0.3 rad; the NMPC then takes
// over again from x̂.
TEST(Pendubot, LqrHandsBackToTheNmpcPastTheExitAngle) {
  PendubotScenario sc = load("pendubot_swingup.toml");
  sc.plant.initial_state = Eigen::Vector4d(0.05, 0.05, 0.0, 0.0);
  sc.lqr.exit_angle = 0.3;
  sc.duration = 0.4;
  const Trace tr = trace(sc);
  std::size_t entry = 0, exit = 0;
  for (std::size_t k = 0; k < tr.steps.size() && exit == 0; ++k) {
    if (entry == 0 && !tr.steps[k].solved) entry = k;
    if (entry > 0 && tr.steps[k].solved) exit = k;
  }
  ASSERT_GT(entry, 0u) << "the LQR never took the arm";
  ASSERT_GT(exit, 0u) << "the LQR never handed back";
  for (std::size_t k : {entry, exit}) EXPECT_NE(tr.steps[k].events & kEventSwitch, 0u) << k;
  EXPECT_LE(angle_norm(tr.steps[entry].x_measured), sc.lqr.enter_angle);
  EXPECT_GT(angle_norm(tr.steps[exit].x_measured), sc.lqr.exit_angle);
  // Between the thresholds the LQR kept the arm (hysteresis).
  EXPECT_GT(angle_norm(tr.steps[exit - 1].x_measured), sc.lqr.enter_angle);
  for (std::size_t k = entry; k < exit; ++k)
    ASSERT_LE(angle_norm(tr.steps[k].x_measured), sc.lqr.exit_angle) << k;
  EXPECT_EQ(tr.result.lqr_entries, 1);
  EXPECT_EQ(tr.result.lqr_entry_time, tr.steps[entry].t);
  EXPECT_EQ(tr.result.nmpc_steps, int(tr.steps.size() - (exit - entry)));
}

// An invalid OCP or setting fails setup with the reason, before anything is sized or written;
// the mode then does nothing, and a valid setup afterwards runs.
TEST(Pendubot, SetupFailsWithTheReason) {
  const PendubotScenario good = load("pendubot_swingup.toml");
  struct Case {
    const char* what;
    void (*edit)(PendubotScenario&);
    const char* reason;
  };
  const Case cases[] = {
      {"N = 0", [](PendubotScenario& s) { s.controller.N = 0; }, "N must be at least 1"},
      {"zero input weight", [](PendubotScenario& s) { s.controller.weights(4) = 0.0; },
       "input weight positive"},
      {"negative weight", [](PendubotScenario& s) { s.controller.weights(0) = -1.0; },
       "controller.weights"},
      {"NaN terminal weight",
       [](PendubotScenario& s) { s.controller.terminal_weights(2) = std::nan(""); },
       "terminal_weights"},
      {"negative slack weight", [](PendubotScenario& s) { s.controller.slack_weight = -1.0; },
       "slack weight"},
      {"no reference", [](PendubotScenario& s) { s.reference = TrajectoryFile{}; },
       "no swing-up reference"},
      {"no substep", [](PendubotScenario& s) { s.plant.rate_hz = 100.0; }, "plant.rate_hz"},
      {"no hysteresis", [](PendubotScenario& s) { s.lqr.exit_angle = s.lqr.enter_angle; },
       "exit_angle"},
      {"LQR r = 0", [](PendubotScenario& s) { s.lqr.r = 0.0; }, "r positive"},
      {"no encoder counts",
       [](PendubotScenario& s) {
         s.sensor.quantization = true;
         s.sensor.counts_q2 = 0;
       },
       "counts"},
  };
  for (const Case& c : cases) {
    PendubotScenario sc = good;
    c.edit(sc);
    PendubotMode mode;
    const SetupResult r = mode.setup(sc);
    EXPECT_FALSE(r.ok()) << c.what;
    EXPECT_NE(r.reason().find(c.reason), std::string::npos) << c.what << ": " << r.reason();
    EXPECT_TRUE(mode.finished()) << c.what;
    EXPECT_EQ(mode.steps_total(), 0) << c.what;
    EXPECT_FALSE(mode.step()) << c.what;
    EXPECT_EQ(mode.steps_done(), 0) << c.what;

    const PendubotRun run = simulate_pendubot_swingup(sc, true);
    EXPECT_FALSE(run.ok) << c.what;
    EXPECT_EQ(run.error, r.reason()) << c.what;
    EXPECT_EQ(run.steps, 0) << c.what;
    EXPECT_TRUE(run.t.empty()) << c.what;

    PendubotScenario short_run = good;
    short_run.duration = 0.01;
    ASSERT_TRUE(mode.setup(short_run).ok()) << c.what;
    while (mode.step()) {
    }
    EXPECT_EQ(mode.steps_done(), 5) << c.what;
  }
}

// simulate_pendubot_swingup: a loop over PendubotMode; its log has one entry per step and one
// for the final state.
TEST(Pendubot, SimulationLogsEveryStepAndTheEnd) {
  PendubotScenario sc = load("pendubot_swingup.toml");
  sc.duration = 1.5;
  const Trace tr = trace(sc);
  const PendubotRun run = simulate_pendubot_swingup(sc, true);
  ASSERT_TRUE(run.ok) << run.error;
  ASSERT_EQ(run.t.size(), tr.steps.size() + 1);
  ASSERT_EQ(run.x.size(), run.t.size());
  for (std::size_t k = 0; k < tr.steps.size(); ++k) {
    ASSERT_EQ(run.t[k], tr.steps[k].t);
    ASSERT_EQ(run.x[k], tr.x_before[k]);
    ASSERT_EQ(run.u[k], tr.steps[k].u(0));
    ASSERT_EQ(run.lqr[k] != 0, !tr.steps[k].solved);
  }
  EXPECT_EQ(run.t.back(), 1.5);
  EXPECT_EQ(run.x.back(), tr.x_final);
  EXPECT_EQ(run.u.back(), 0.0);
  EXPECT_EQ(run.max_abs_u, tr.result.max_abs_u);
  EXPECT_EQ(run.swingup_time, tr.result.swingup_time);
  EXPECT_EQ(run.tracking_rms, tr.result.tracking_rms);
}

TEST(Pendubot, FlownScenarioReportsTheModesMetrics) {
  const Flown r = fly_scenario(kDir + "pendubot_swingup.toml", 3.0);
  ASSERT_TRUE(r.ok) << r.error;
  const char* const names[] = {
      "duration_s",       "swingup_time_s", "hold_time_s", "final_angle_norm",
      "max_abs_u",        "velocity_violations", "worst_velocity_violation", "tracking_rms",
      "rti_median_us",    "rti_p99_us",     "rti_max_us",  "nmpc_steps",
      "fallbacks",        "lqr_entry_time_s", "lqr_time_s", "lqr_entries",
      "quantization"};
  ASSERT_EQ(r.metrics.size(), std::size(names));
  for (std::size_t i = 0; i < r.metrics.size(); ++i) EXPECT_EQ(r.metrics[i].first, names[i]);

  // The same as PendubotMode's own run of the scenario, timing apart.
  PendubotScenario sc = load("pendubot_swingup.toml");
  sc.duration = 3.0;
  PendubotMode mode;
  ASSERT_TRUE(mode.setup(sc).ok());
  // The hold measured on the flown states: from the first instant after which every state
  // is within the angle tolerance of up-up, to the end.
  const auto wrapped_norm = [](const Eigen::VectorXd& x) {
    return std::hypot(std::remainder(x(0), 2 * std::numbers::pi),
                      std::remainder(x(1), 2 * std::numbers::pi));
  };
  double entered = 0.0;
  while (mode.step()) {
    const Telemetry& s = mode.telemetry();
    if (wrapped_norm(s.x) > sc.angle_tolerance) entered = s.t + sc.controller.dt;
  }
  if (wrapped_norm(mode.state()) > sc.angle_tolerance) entered = sc.duration;
  const Metrics m = mode.metrics();
  ASSERT_EQ(m.size(), r.metrics.size());
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (m[i].first.ends_with("_us")) {
      EXPECT_GT(r.metrics[i].second, 0.0) << m[i].first;  // the RTI was timed
    } else {
      EXPECT_EQ(r.metrics[i].second, m[i].second) << m[i].first;
    }
  }
  auto metric = [&](const std::string& name) {
    for (const auto& [n, v] : r.metrics)
      if (n == name) return v;
    return std::nan("");
  };
  EXPECT_EQ(metric("duration_s"), 3.0);
  EXPECT_GT(metric("swingup_time_s"), 0.5);
  // Within a step of the flown states' hold (the metric samples the state after each step).
  EXPECT_GT(3.0 - entered, 1.0);
  EXPECT_NEAR(metric("hold_time_s"), 3.0 - entered, sc.controller.dt + 1e-12);
  EXPECT_EQ(metric("velocity_violations"), 0.0);
  EXPECT_EQ(metric("fallbacks"), 0.0);
  EXPECT_GT(metric("lqr_time_s"), 1.0);
  // The scenario and its mode first, as every mode's summary starts (the front end labels it).
  EXPECT_EQ(r.summary.rfind("pendubot_swingup (pendubot_swingup): 3.00 s, exact state", 0), 0u)
      << r.summary;
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
