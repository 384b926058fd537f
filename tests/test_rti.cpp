// RTI engine (core/nlp/rti.hpp) on the Crazyflie tracking OCP of SPEC §5.2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/control/crazyflie_tracking.hpp"
#include "core/nlp/nlp_ipopt.hpp"
#include "core/control/obstacle_constraint.hpp"
#include "core/nlp/rti.hpp"
#include "core/nlp/trajectory_io.hpp"

namespace mixpilot {
namespace {

constexpr double kDt = 0.015;
constexpr int kN = 50;

// The plant: the same model, ERK4 at 1 kHz with the input held over the control interval.
Eigen::VectorXd plant_step(const IntegratorErk4<models::Crazyflie>& erk4, Eigen::VectorXd x,
                           const Eigen::VectorXd& u) {
  models::Crazyflie::State xs = x, xn;
  const models::Crazyflie::Input us = u;
  for (int k = 0; k < 15; ++k) {
    erk4.step(xs, us, kDt / 15, xn);
    xs = xn;
  }
  return xs;
}

struct ClosedLoopResult {
  double final_error = 0;       // ‖p − target‖ at the end
  double settle_time = 0;       // first time after which ‖p − target‖ ≤ 5 cm for good
  double max_bound_violation = 0;
  double overshoot = 0;         // max over time of the position error's component past target
  int fallbacks = 0;
  int steps = 0;
};

const TrajectoryFile& smooth_step() {
  static const TrajectoryFile file = [] {
    std::string error;
    auto f = read_trajectory_csv(
        MIXPILOT_SOURCE_DIR "/scenarios/references/crazyflie_smooth_step.csv", error);
    if (!f) ADD_FAILURE() << error;
    return f ? *f : TrajectoryFile{};
  }();
  return file;
}

// Flies hover (0,0,0.4) → (1,−1,1) along the Ipopt smooth-step reference of SPEC §5.2 (the
// reference holds its last state after T = 6 s) for `seconds`, with one RTI iteration per
// step, or, with sqp_iterations > 0, SQP to convergence each step.
ClosedLoopResult fly_step(double seconds, int sqp_iterations = 0) {
  CrazyflieTracking problem(kN, kDt);
  RtiSolver rti;
  EXPECT_TRUE(rti.setup(problem.ocp()));
  const Eigen::Vector3d start(0, 0, 0.4), target(1, -1, 1);
  const OcpTrajectory& ref = smooth_step().trajectory;
  EXPECT_EQ(ref.u.size(), 400u);
  problem.hover_guess(rti.trajectory(), start);
  Eigen::VectorXd x = problem.model().hover_state(start);

  ClosedLoopResult res;
  const int steps = int(std::lround(seconds / kDt));
  double last_outside = 0;
  for (int k = 0; k < steps; ++k) {
    problem.set_reference(rti.data(), ref, k);
    if (sqp_iterations > 0) {
      rti.sqp(x, sqp_iterations, 1e-9);
    } else {
      rti.prepare();
      rti.feedback(x);
    }
    const Eigen::VectorXd u = rti.control();
    res.max_bound_violation = std::max(
        {res.max_bound_violation, -u.minCoeff(), u.maxCoeff() - problem.model().p.omega_max});
    x = plant_step(problem.integrator(), x, u);
    rti.shift();
    const double err = (x.head<3>() - target).norm();
    if (err > 0.05) last_outside = (k + 1) * kDt;
    res.overshoot = std::max(res.overshoot, x(2) - target(2));
  }
  res.final_error = (x.head<3>() - target).norm();
  res.settle_time = last_outside;
  res.fallbacks = int(rti.stats().fallbacks);
  res.steps = steps;
  return res;
}

TEST(RtiClosedLoop, CrazyflieStepSettles) {
  const ClosedLoopResult rti = fly_step(7.5);
  const ClosedLoopResult sqp = fly_step(7.5, 20);
  std::printf("RTI: settle %.3f s, final error %.2e m, overshoot z %.3f m, fallbacks %d\n",
              rti.settle_time, rti.final_error, rti.overshoot, rti.fallbacks);
  std::printf("SQP: settle %.3f s, final error %.2e m, overshoot z %.3f m, fallbacks %d\n",
              sqp.settle_time, sqp.final_error, sqp.overshoot, sqp.fallbacks);
  for (const auto* r : {&rti, &sqp}) {
    EXPECT_EQ(r->fallbacks, 0);
    EXPECT_LE(r->max_bound_violation, 1e-9);  // input bounds hold (QP tolerance)
    // The loop converges to the target (6e-12 m after 7.5 s: the QP's tolerance, not a
    // residual offset) and settles within a step either side of the 0.69 s it takes (the
    // run is deterministic; the slack covers QP-tolerance changes of the last digits).
    EXPECT_LT(r->final_error, 1e-6);
    EXPECT_NEAR(r->settle_time, 0.69, 0.015 + 1e-9);
  }
  // One RTI iteration per step tracks the converged controller closely.
  EXPECT_NEAR(rti.settle_time, sqp.settle_time, 0.3);
}

// The QP observer sees each feedback phase's QP and warm start exactly as they are solved:
// solving the observed QP from the observed start with a solver of the same kind gives the
// loop's own solution bit for bit (what the closed-loop QP sets of mixpilot-bench rely on).
TEST(RtiQpObserver, SeesEveryQpWithTheWarmStartTheLoopUsed) {
  CrazyflieTracking problem(kN, kDt);
  RtiSolver rti;
  ASSERT_TRUE(rti.setup(problem.ocp()));
  struct Seen final : RtiQpObserver {
    std::vector<OcpQp> qps;
    std::vector<OcpQpSolution> starts;
    std::vector<QpWarmStart> warm;
    void on_qp(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart w) override {
      qps.push_back(qp);
      starts.push_back(start);
      warm.push_back(w);
    }
  } seen;
  rti.set_qp_observer(&seen);
  const OcpTrajectory& ref = smooth_step().trajectory;
  problem.hover_guess(rti.trajectory(), {0, 0, 0.4});
  Eigen::VectorXd x = problem.model().hover_state({0, 0, 0.4});
  std::vector<OcpQpSolution> solved;
  for (int k = 0; k < 6; ++k) {
    problem.set_reference(rti.data(), ref, k);
    rti.prepare();
    ASSERT_EQ(rti.feedback(x), RtiStatus::success);
    solved.push_back(rti.qp_solution());
    x = plant_step(problem.integrator(), x, rti.control());
    rti.shift();
  }
  rti.set_qp_observer(nullptr);
  ASSERT_EQ(seen.qps.size(), 6u);
  EXPECT_EQ(seen.warm.front(), QpWarmStart::cold);
  EXPECT_EQ(seen.warm.back(), QpWarmStart::primal_dual);
  ASSERT_EQ(rti.settings().qp_solver, QpSolverKind::riccati_ipm_pairs);  // the RTI default
  QpRiccatiIpmPairs solver(seen.qps[0].dims, rti.settings().qp, rti.settings().qp_pair_levels);
  for (std::size_t k = 0; k < seen.qps.size(); ++k) {
    OcpQpSolution sol = seen.starts[k];
    solver.prepare(seen.qps[k]);
    ASSERT_EQ(solver.solve(seen.qps[k], sol, seen.warm[k]), QpStatus::success) << k;
    EXPECT_EQ(sol.iterations, solved[k].iterations) << k;
    for (int i = 0; i <= kN; ++i) {
      ASSERT_EQ(sol.x[i], solved[k].x[i]) << k << " stage " << i;
      ASSERT_EQ(sol.u[i], solved[k].u[i]) << k << " stage " << i;
    }
  }
}

// A hard 1.5 m step (the reference jumps to the target at once) is beyond what one Gauss-Newton
// step per sample can follow, and the vehicle tumbles. The primal-dual warm start from a
// trajectory that swings between samples used to end in min_step at the first iteration (steps
// 44, 51, 57, 59: four fallbacks); QpRiccatiIpm now restarts such a solve cold. The tumble is
// chaotic: any change of the solver's rounding moves it, and late in it the QPs can become so
// badly scaled (objective ~5e6) that the absolute stationarity tolerance lies below what double
// precision resolves: such a QP ends in max_iterations or factorization_failed from a cold start
// as from a warm one (with the solver before this test was written too). Those are the failure
// policy's fallbacks, not the warm start's; a well-scaled QP must never fail, and none may end
// in min_step.
TEST(RtiFailurePolicy, WarmStartFarFromTheNewQpDoesNotFallBack) {
  CrazyflieTracking problem(kN, kDt);
  RtiSolver rti;
  ASSERT_TRUE(rti.setup(problem.ocp()));
  problem.hover_guess(rti.trajectory(), Eigen::Vector3d(0, 0, 0.4));
  problem.set_hover_target(rti.data(), Eigen::Vector3d(1, -1, 1));
  models::Crazyflie::State x = problem.model().hover_state(Eigen::Vector3d(0, 0, 0.4)), xn;
  for (int k = 0; k < 60; ++k) {  // plant: the model's own ERK4 step
    rti.prepare();
    rti.feedback(x);
    if (rti.stats().status != RtiStatus::success) {
      EXPECT_NE(rti.stats().qp_status, QpStatus::min_step) << "step " << k;
      EXPECT_GT(std::abs(rti.qp_solution().objective), 1e5)
          << "step " << k << ": a well-scaled QP failed, " << to_string(rti.stats().qp_status);
    }
    problem.integrator().step(x, models::Crazyflie::Input(rti.control()), kDt, xn);
    x = xn;
    rti.shift();
  }
}

// RtiSettings::qp_solver = riccati_ipm_pairs (partial condensing in prepare()) flies the smooth
// step like the plain Riccati IPM: eliminating x_{k+1} commutes with the Newton step, so both
// take the same IPM iterates in exact arithmetic and the inputs differ by rounding only.
TEST(RtiQpSolvers, PairCondensingFliesTheSameLoop) {
  CrazyflieTracking problem(kN, kDt);
  RtiSolver plain, pairs;
  RtiSettings s;
  s.qp_solver = QpSolverKind::riccati_ipm;
  ASSERT_TRUE(plain.setup(problem.ocp(), s));
  s.qp_solver = QpSolverKind::riccati_ipm_pairs;
  ASSERT_TRUE(pairs.setup(problem.ocp(), s));
  const Eigen::Vector3d start(0, 0, 0.4);
  problem.hover_guess(plain.trajectory(), start);
  problem.hover_guess(pairs.trajectory(), start);
  Eigen::VectorXd x = problem.model().hover_state(start);
  double worst = 0;
  for (int k = 0; k < 120; ++k) {
    for (RtiSolver* r : {&plain, &pairs}) {
      problem.set_reference(r->data(), smooth_step().trajectory, k);
      r->prepare();
      r->feedback(x);
      EXPECT_EQ(r->stats().status, RtiStatus::success) << k;
    }
    worst = std::max(worst, (plain.control() - pairs.control()).lpNorm<Eigen::Infinity>());
    x = plant_step(problem.integrator(), x, plain.control());
    plain.shift();
    pairs.shift();
  }
  EXPECT_LE(worst, 1e-9);  // krpm, inputs ~16
  std::printf("max |u_plain - u_pairs| over 120 steps: %.2e krpm\n", worst);
}

// A converged SQP iterate is only as stationary as its QPs: with weights as small as 1e-5 (SPEC
// §5.2), the RTI default (1e-6) leaves primal errors ~1e-5, so fully converged runs tighten it.
RtiSettings converged_settings() {
  RtiSettings s;
  s.qp.tol_stat = 1e-11;
  s.qp.tol_eq = 1e-11;
  s.qp.tol_ineq = 1e-11;
  s.qp.tol_comp = 1e-11;
  return s;
}

TEST(RtiSqp, ConvergesToIpoptSolution) {
  // SPEC §5.2 OCP (N = 50) from a perturbed hover back to hover at (0, 0, 0.4).
  CrazyflieTracking problem(kN, kDt);
  RtiSolver rti;
  ASSERT_TRUE(rti.setup(problem.ocp(), converged_settings()));
  problem.set_hover_target(rti.data(), {0, 0, 0.4});
  Eigen::VectorXd x0 = problem.model().hover_state({0.15, -0.1, 0.3});
  x0.segment<4>(3) = Eigen::Vector4d(1.0, 0.05, -0.04, 0.1).normalized();
  x0.segment<3>(7) << 0.3, -0.2, 0.1;  // body velocity
  x0.segment<3>(10) << 0.5, -0.3, 0.2;  // body rates

  problem.hover_guess(rti.trajectory(), {0, 0, 0.4});
  const SqpResult sqp = rti.sqp(x0, 100, 1e-10);
  ASSERT_TRUE(sqp.converged) << "step " << sqp.step_norm << " after " << sqp.iterations;

  OcpTrajectory ipopt_traj(problem.ocp());
  problem.hover_guess(ipopt_traj, {0, 0, 0.4});
  IpoptOcpSolver ipopt;
  const IpoptOcpResult res = ipopt.solve(problem.ocp(), rti.data(), x0, ipopt_traj);
  ASSERT_EQ(res.status, IpoptOcpStatus::solved) << res.message;

  double dx = 0, du = 0;
  for (int i = 0; i <= kN; ++i)
    dx = std::max(dx, (rti.trajectory().x[i] - ipopt_traj.x[i]).lpNorm<Eigen::Infinity>());
  for (int i = 0; i < kN; ++i)
    du = std::max(du, (rti.trajectory().u[i] - ipopt_traj.u[i]).lpNorm<Eigen::Infinity>());
  std::printf("SQP %d iterations, Ipopt %d iterations; max |Δx| %.1e, max |Δu| %.1e\n",
              sqp.iterations, res.iterations, dx, du);
  EXPECT_LE(dx, 1e-5);
  EXPECT_LE(du, 1e-5);
}

// Path constraints and ℓ1-softened constraints through RTI's SQP and through Ipopt: an obstacle
// (d_C = 0.2 m, SPEC §5.3 slack weights) sits 0.15 m beside the straight path, so the clearance
// is active. Both constraint forms must converge to the same trajectory as Ipopt.
TEST(RtiSqp, SoftObstacleConstraintMatchesIpopt) {
  CrazyflieTracking problem(kN, kDt);
  const Eigen::Vector3d obstacle(0.3, 0.15, 0.4), target(0.6, 0.0, 0.4);
  const double clearance = 0.2;
  OcpTrajectory lcl_solution;
  for (const ObstacleForm form : {ObstacleForm::lcl, ObstacleForm::squared}) {
    ObstacleConstraint constraint(1, form);
    Ocp ocp = problem.ocp();
    ocp.np = ObstacleConstraint::kParamsPerObstacle;
    ocp.constraint = &constraint;
    ocp.lg = Eigen::VectorXd::Zero(1);
    ocp.ug = Eigen::VectorXd::Constant(1, 1e20);
    // Pure exact ℓ1 penalty (Zl = Zu = 0) as SPEC §5.3 prescribes; the upper side is absent.
    ocp.soft_constraints = {SoftConstraint{0, 0.0, 0.0, 14.5e3, 14.2e3}};

    RtiSolver rti;
    ASSERT_TRUE(rti.setup(ocp, converged_settings()));
    problem.set_hover_target(rti.data(), target);
    for (auto& p : rti.data().p) {
      p.head<3>() = obstacle;
      p(3) = clearance;
    }
    const Eigen::VectorXd x0 = problem.model().hover_state({0, 0, 0.4});
    problem.hover_guess(rti.trajectory(), {0, 0, 0.4});
    const SqpResult sqp = rti.sqp(x0, 200, 1e-10);
    ASSERT_TRUE(sqp.converged) << "step " << sqp.step_norm << " after " << sqp.iterations
                               << ", QP " << to_string(sqp.qp_status);

    OcpTrajectory ipopt_traj(ocp);
    problem.hover_guess(ipopt_traj, {0, 0, 0.4});
    IpoptOcpSettings ipopt_settings;
    ipopt_settings.tolerance = 1e-12;
    IpoptOcpSolver ipopt(ipopt_settings);
    const IpoptOcpResult res = ipopt.solve(ocp, rti.data(), x0, ipopt_traj);
    ASSERT_EQ(res.status, IpoptOcpStatus::solved) << res.message;

    double dx = 0, du = 0, min_dist = 1e9;
    for (int i = 0; i <= kN; ++i) {
      dx = std::max(dx, (rti.trajectory().x[i] - ipopt_traj.x[i]).lpNorm<Eigen::Infinity>());
      min_dist = std::min(min_dist, (rti.trajectory().x[i].head<3>() - obstacle).norm());
    }
    for (int i = 0; i < kN; ++i)
      du = std::max(du, (rti.trajectory().u[i] - ipopt_traj.u[i]).lpNorm<Eigen::Infinity>());
    std::printf("%s: SQP %d it, Ipopt %d it; max |Δx| %.1e, |Δu| %.1e; min distance %.4f m\n",
                form == ObstacleForm::lcl ? "lcl" : "squared", sqp.iterations, res.iterations, dx,
                du, min_dist);
    EXPECT_LE(dx, 1e-5);
    EXPECT_LE(du, 1e-5);
    EXPECT_GE(min_dist, clearance - 1e-6);  // the exact penalty keeps the constraint
    EXPECT_LE(min_dist, clearance + 1e-3);  // and it is active
    if (form == ObstacleForm::lcl) {
      lcl_solution = rti.trajectory();
    } else {
      // Converged, both forms describe the same feasible set: the same solution.
      double diff = 0;
      for (int i = 0; i <= kN; ++i)
        diff = std::max(diff, (rti.trajectory().x[i] - lcl_solution.x[i]).lpNorm<Eigen::Infinity>());
      std::printf("lcl vs squared: max |Δx| %.1e\n", diff);
      EXPECT_LE(diff, 1e-6);
    }
  }
}

// Wraps an integrator and returns NaN sensitivities on one chosen call.
class FaultyIntegrator final : public Integrator {
 public:
  FaultyIntegrator(const Integrator& inner, long fail_call) : inner_(inner), fail_call_(fail_call) {}
  int nx() const override { return inner_.nx(); }
  int nu() const override { return inner_.nu(); }
  IntegratorStatus step(const Eigen::Ref<const Eigen::VectorXd>& x,
                        const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                        Eigen::Ref<Eigen::VectorXd> x_next) const override {
    return inner_.step(x, u, dt, x_next);
  }
  IntegratorStatus step_sensitivities(const Eigen::Ref<const Eigen::VectorXd>& x,
                                      const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                                      Eigen::Ref<Eigen::VectorXd> x_next,
                                      Eigen::Ref<Eigen::MatrixXd> A,
                                      Eigen::Ref<Eigen::MatrixXd> B) const override {
    const IntegratorStatus st = inner_.step_sensitivities(x, u, dt, x_next, A, B);
    if (calls_++ != fail_call_) return st;
    A(3, 2) = std::numeric_limits<double>::quiet_NaN();
    return IntegratorStatus::non_finite;
  }

 private:
  const Integrator& inner_;
  long fail_call_;
  mutable long calls_ = 0;
};

TEST(RtiFailurePolicy, NaNInLinearizationFallsBackAndLoopContinues) {
  CrazyflieTracking problem(kN, kDt);
  // Stage 7 of control step 20 gets a NaN sensitivity.
  FaultyIntegrator faulty(problem.integrator(), 20L * kN + 7);
  Ocp ocp = problem.ocp();
  ocp.integrator = &faulty;
  RtiSolver rti;
  ASSERT_TRUE(rti.setup(ocp));
  const Eigen::Vector3d start(0, 0, 0.4), target(0.2, -0.2, 0.5);
  problem.set_hover_target(rti.data(), target);
  problem.hover_guess(rti.trajectory(), start);
  Eigen::VectorXd x = problem.model().hover_state(start);
  Eigen::VectorXd expected_fallback_input;
  for (int k = 0; k < 200; ++k) {
    if (k == 20) expected_fallback_input = rti.trajectory().u[0];  // previous solution's u_1
    rti.prepare();
    const RtiStatus st = rti.feedback(x);
    ASSERT_TRUE(rti.control().allFinite());
    if (k == 20) {
      EXPECT_EQ(st, RtiStatus::fallback);
      EXPECT_FALSE(rti.stats().linearization_finite);
      EXPECT_EQ(rti.control(), expected_fallback_input);
    } else {
      EXPECT_EQ(st, RtiStatus::success) << "step " << k;
    }
    x = plant_step(problem.integrator(), x, rti.control());
    rti.shift();
  }
  EXPECT_EQ(rti.stats().fallbacks, 1);
  EXPECT_LT((x.head<3>() - target).norm(), 0.01);  // the loop carried on and settled
}

TEST(RtiFailurePolicy, InvalidMeasurementIsRejected) {
  CrazyflieTracking problem(kN, kDt);
  RtiSolver rti;
  ASSERT_TRUE(rti.setup(problem.ocp()));
  problem.hover_guess(rti.trajectory(), {0, 0, 0.4});
  rti.prepare();
  Eigen::VectorXd x = problem.model().hover_state({0, 0, 0.4});
  x(0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(rti.feedback(x), RtiStatus::invalid);
  EXPECT_EQ(rti.feedback(Eigen::VectorXd::Zero(3)), RtiStatus::invalid);
  EXPECT_TRUE(rti.control().allFinite());
}

TEST(RtiSetup, RejectsIncompleteOcp) {
  CrazyflieTracking problem(kN, kDt);
  Ocp ocp = problem.ocp();
  ocp.output = nullptr;
  RtiSolver rti;
  EXPECT_FALSE(rti.setup(ocp));
  EXPECT_EQ(rti.prepare(), RtiStatus::invalid);
}

}  // namespace
}  // namespace mixpilot
