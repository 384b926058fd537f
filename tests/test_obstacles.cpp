// Obstacle avoidance with the LCL constraint (SPEC §5.3: core/control/obstacle_avoidance.hpp,
// core/modes/obstacle_mode.hpp): Proposition 1, the shipped scenarios in closed loop with both
// constraint forms, converged SQP equivalence, the mode's metrics and telemetry against a replay
// of its log, its setup failures, a flight through make_mode() and scenario diagnostics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/control/obstacle_constraint.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/obstacle_mode.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "fly_scenario.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {
namespace {

const std::string kBalls = MIXPILOT_SOURCE_DIR "/scenarios/obstacles_thrown_balls.toml";
const std::string kCluttered = MIXPILOT_SOURCE_DIR "/scenarios/obstacles_cluttered.toml";

const ObstacleScenario& scenario(const std::string& path) {
  static std::map<std::string, ObstacleScenario> cache;
  auto it = cache.find(path);
  if (it == cache.end()) {
    std::string error;
    auto sc = load_obstacle_scenario(path, error);
    EXPECT_TRUE(sc) << error;
    it = cache.emplace(path, sc ? *sc : ObstacleScenario{}).first;
  }
  return it->second;
}

// Obstacle j of a scenario at time t, written out here from the scenario's numbers, apart from
// ObstacleWorld: spheres first, then balls, at rest until the throw, then p0 + v·τ − ½gτ²·e_z.
Eigen::Vector3d obstacle_at(const ObstacleScenario& sc, int j, double t) {
  const int ns = int(sc.world.spheres.size());
  if (j < ns) return sc.world.spheres[std::size_t(j)];
  const ThrownBall& b = sc.world.balls[std::size_t(j - ns)];
  const double tau = t > b.throw_time ? t - b.throw_time : 0.0;
  return b.position + tau * b.velocity - Eigen::Vector3d(0.0, 0.0, 0.5 * b.gravity * tau * tau);
}

double distance_to_obstacles(const ObstacleScenario& sc, const Eigen::Vector3d& p, double t) {
  double m = std::numeric_limits<double>::infinity();
  for (int j = 0; j < sc.world.size(); ++j) m = std::min(m, (p - obstacle_at(sc, j, t)).norm());
  return m;
}

// ---------------------------------------------------------------------------------------------
// Proposition 1 (thesis ch. 6.3.1): at any linearization point p̄ ≠ o,
//   H1 = {p : ‖p̄−o‖ + (p̄−o)ᵀ(p−p̄)/‖p̄−o‖ ≥ d},  H2 = {p : ‖p̄−o‖² + 2(p̄−o)ᵀ(p−p̄) ≥ d²},
//   S = {p : ‖p−o‖ ≥ d}:  H2 ⊆ H1 ⊆ S.
// With n = (p̄−o)/r̄, r̄ = ‖p̄−o‖, both are half-spaces {nᵀ(p−o) ≥ b}: b1 = d and
// b2 = (r̄² + d²)/(2r̄) = d + (r̄ − d)²/(2r̄) ≥ b1 (equality iff r̄ = d); and nᵀ(p−o) ≥ d implies
// ‖p−o‖ ≥ d. The half-spaces are built from ObstacleConstraint's own g and ∇g, so the test
// also checks the implementation of both forms.

struct HalfSpace {  // {p : a + gᵀ(p − p̄) ≥ 0}
  double a;
  Eigen::Vector3d g;
  Eigen::Vector3d pbar;
  bool contains(const Eigen::Vector3d& p) const { return a + g.dot(p - pbar) >= 0.0; }
  // Offset along n = g/‖g‖ from o: the half-space is {nᵀ(p−o) ≥ b}.
  double offset(const Eigen::Vector3d& o) const { return g.normalized().dot(pbar - o) - a / g.norm(); }
};

HalfSpace linearize(ObstacleForm form, const Eigen::Vector3d& pbar, const Eigen::Vector3d& o,
                    double d) {
  const ObstacleConstraint c(1, form);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(13), u(0), p(4), g(1);
  x.head<3>() = pbar;
  p << o, d;
  Eigen::MatrixXd Gx(1, 13), Gu(1, 0);
  c.eval(x, u, p, g, Gx, Gu);
  return {g(0), Gx.row(0).head<3>().transpose(), pbar};
}

TEST(Proposition1, SquaredHalfSpaceInsideLclHalfSpaceInsideClearanceSet) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const auto rand3 = [&] { return Eigen::Vector3d(uni(rng), uni(rng), uni(rng)); };
  int in_h2 = 0, in_h1_only = 0, samples = 0;
  double min_gap = 1e9;  // b2 − b1
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d o = 2.0 * rand3();
    const double d = 0.05 + 0.5 * (uni(rng) + 1.0) / 2.0;
    // Linearization points inside and outside the clearance, on it, and far away.
    const double r = trial % 10 == 0 ? d : d * std::exp(1.5 * uni(rng));
    const Eigen::Vector3d pbar = o + r * rand3().normalized();
    const HalfSpace h1 = linearize(ObstacleForm::lcl, pbar, o, d);
    const HalfSpace h2 = linearize(ObstacleForm::squared, pbar, o, d);

    // Analytically: the same normal, offsets b1 = d ≤ b2 = (r² + d²)/(2r).
    ASSERT_NEAR(h1.g.normalized().dot(h2.g.normalized()), 1.0, 1e-12);
    ASSERT_NEAR(h1.offset(o), d, 1e-12);
    ASSERT_NEAR(h2.offset(o), (r * r + d * d) / (2 * r), 1e-12 * (1 + 1 / r));
    ASSERT_GE(h2.offset(o), h1.offset(o) - 1e-12);
    min_gap = std::min(min_gap, h2.offset(o) - h1.offset(o));
    if (trial % 10 == 0) {
      ASSERT_NEAR(h2.offset(o), h1.offset(o), 1e-12);  // on the boundary
    }

    // By sampling: p ∈ H2 ⇒ p ∈ H1 ⇒ p ∈ S.
    for (int s = 0; s < 50; ++s, ++samples) {
      const Eigen::Vector3d p = o + 3.0 * std::max(r, d) * rand3();
      const bool a2 = h2.contains(p), a1 = h1.contains(p), in_s = (p - o).norm() >= d;
      if (a2) {
        ++in_h2;
        ASSERT_TRUE(a1) << "p in H2 but not in H1";
      }
      if (a1) {
        ASSERT_TRUE(in_s) << "p in H1 but not in S";
      }
      in_h1_only += a1 && !a2;
    }
  }
  std::printf("Proposition 1: %d samples, %d in H2, %d in H1 \\ H2; min b2 - b1 = %.1e\n",
              samples, in_h2, in_h1_only, min_gap);
  EXPECT_GT(in_h2, samples / 20);      // the samples do exercise H2
  EXPECT_GT(in_h1_only, samples / 50);  // and the strict inclusion
}

// ---------------------------------------------------------------------------------------------
// Scenario design: following the reference would hit the obstacles.

double min_distance_to_reference(const ObstacleScenario& sc, int j) {
  const OcpTrajectory& ref = sc.reference.trajectory;
  double m = 1e9;
  for (std::size_t k = 0; k < ref.x.size(); ++k) {
    const Eigen::Vector3d o = sc.world.position(j, double(k) * sc.controller.dt);
    m = std::min(m, (ref.x[k].head<3>() - o).norm());
  }
  return m;
}

TEST(ObstacleScenarios, ObstaclesBlockTheReference) {
  const ObstacleScenario& balls = scenario(kBalls);
  ASSERT_EQ(balls.world.balls.size(), 2u);
  for (int j = 0; j < balls.world.size(); ++j) {
    EXPECT_LT(min_distance_to_reference(balls, j), 0.01) << "ball " << j << " misses the reference";
  }
  const ObstacleScenario& clutter = scenario(kCluttered);
  ASSERT_GE(clutter.world.spheres.size(), 5u);
  int blocking = 0;
  const Eigen::Vector3d start = clutter.reference.trajectory.x.front().head<3>();
  const Eigen::Vector3d goal = clutter.reference.trajectory.x.back().head<3>();
  for (int j = 0; j < clutter.world.size(); ++j) {
    blocking += min_distance_to_reference(clutter, j) < clutter.controller.clearance;
    EXPECT_GT((clutter.world.spheres[j] - start).norm(), clutter.controller.clearance);
    EXPECT_GT((clutter.world.spheres[j] - goal).norm(), clutter.controller.clearance);
  }
  EXPECT_GE(blocking, 3);
}

// ---------------------------------------------------------------------------------------------
// Closed loop, both scenarios x both forms: no violation (d ≥ d_C − 1 mm at every 1 kHz plant
// substep); the LCL form's minimum distance is the closer to d_C from the conservative side, i.e.
// the smaller (Proposition 1: less conservative). Noise-free and with exact obstacle predictions,
// each node is re-linearized ~N times before it is flown, so at the control instants both forms
// sit on d_C (to 1e-6 m here); the minima differ below a millimetre, between the samples.

TEST(ObstacleClosedLoop, NoViolationAndLclCloserToClearance) {
  for (const std::string& path : {kBalls, kCluttered}) {
    const ObstacleScenario& sc = scenario(path);
    const double d_c = sc.controller.clearance;
    ObstacleRunResult r[2];
    for (const ObstacleForm form : {ObstacleForm::lcl, ObstacleForm::squared}) {
      ObstacleRunOptions options;
      options.form = form;
      options.keep_trajectory = true;
      ObstacleRunResult& res = r[int(form)];
      res = run_obstacle_avoidance(sc, options);
      ASSERT_TRUE(res.error.empty()) << res.error;
      std::printf("%-24s %-7s min distance %.6f m (margin %+.6f m) at %.3f s, %.6f m at the "
                  "control instants; violations %d, tracking rms %.3f m, final error %.3f m, "
                  "RTI median %.0f us, fallbacks %d\n",
                  sc.name.c_str(), to_string(form), res.min_distance_m, res.min_margin_m,
                  res.min_distance_time, res.min_distance_control_m, res.violations,
                  res.tracking_rms_m, res.final_error_m, res.rti_median_us, res.fallbacks);
      EXPECT_EQ(res.form, form);
      EXPECT_FALSE(res.lost);
      EXPECT_EQ(res.violations, 0);
      // The minimum at the control instants, recomputed from the logged positions; the plant
      // substeps include the control instants, so their minimum is no larger.
      ASSERT_EQ(res.positions.size(), std::size_t(res.steps) + 1);
      double control_min = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < res.positions.size(); ++k)
        control_min = std::min(control_min, distance_to_obstacles(sc, res.positions[k],
                                                                  double(k) * sc.controller.dt));
      EXPECT_NEAR(res.min_distance_control_m, control_min, 1e-12);
      EXPECT_LE(res.min_distance_m, control_min + 1e-12);
      EXPECT_NEAR(res.min_distance_control_m, d_c, 1e-6) << "the clearance is not active";
      EXPECT_EQ(res.fallbacks, 0);
      EXPECT_LT(res.final_error_m, 0.05);  // reaches the goal despite the obstacles
    }
    const double lcl = r[int(ObstacleForm::lcl)].min_distance_m;
    const double squared = r[int(ObstacleForm::squared)].min_distance_m;
    std::printf("%-24s min distance - d_C: lcl %+.2e m, squared %+.2e m\n", sc.name.c_str(),
                lcl - d_c, squared - d_c);
    EXPECT_LT(lcl, squared) << sc.name;
  }
}

// ---------------------------------------------------------------------------------------------
// Proposition 1 in the solver, and converged equivalence, on one fixed OCP: hover at (0,0,1),
// target (0.8,0,1), a sphere at (0.4,0.05,1) in between, linearized at the hover (r̄ ≈ 0.403 m).
// One RTI step (one QP) obeys H1 resp. H2 at every node: the lcl plan reaches d_C, the squared
// plan stops at (r̄² + d²)/(2r̄) ≈ 0.251 m. Iterated to convergence (SQP) both forms give the
// same solution, on the boundary.

// Tight QP tolerances (see test_rti.cpp: converged SQP is only as stationary as its QPs).
RtiSettings converged_settings() {
  RtiSettings s;
  s.qp.tol_stat = 1e-11;
  s.qp.tol_eq = 1e-11;
  s.qp.tol_ineq = 1e-11;
  s.qp.tol_comp = 1e-11;
  return s;
}

struct FixedProblemSolution {
  double one_step_min_distance = 1e9;  // of the plan after one RTI step from the hover
  OcpTrajectory converged;
  double converged_min_distance = 1e9;
  int sqp_iterations = 0;
};

FixedProblemSolution solve_fixed_problem(ObstacleForm form) {
  const Eigen::Vector3d start(0, 0, 1), target(0.8, 0, 1), obstacle(0.4, 0.05, 1);
  ObstacleControllerSettings cs;
  cs.form = form;
  ObstacleAvoidanceOcp problem(1, cs);
  ObstacleWorld world;
  world.spheres = {obstacle};
  RtiSolver rti;
  EXPECT_TRUE(rti.setup(problem.ocp(), converged_settings()));
  problem.set_hover_target(rti.data(), target);
  problem.set_obstacles(rti.data(), world, 0.0);
  problem.hover_guess(rti.trajectory(), start);
  const Eigen::VectorXd x0 = problem.model().hover_state(start);
  const auto min_distance = [&] {
    double m = 1e9;
    for (int i = 1; i <= cs.N; ++i)
      m = std::min(m, (rti.trajectory().x[i].head<3>() - obstacle).norm());
    return m;
  };
  FixedProblemSolution s;
  EXPECT_EQ(rti.prepare(), RtiStatus::success);
  EXPECT_EQ(rti.feedback(x0), RtiStatus::success);
  s.one_step_min_distance = min_distance();
  const SqpResult r = rti.sqp(x0, 200, 1e-10);
  EXPECT_TRUE(r.converged) << to_string(form) << ": step " << r.step_norm << " after "
                           << r.iterations << ", QP " << to_string(r.qp_status);
  s.converged = rti.trajectory();
  s.converged_min_distance = min_distance();
  s.sqp_iterations = r.iterations;
  return s;
}

TEST(ObstacleSqp, OneStepLclLessConservativeConvergedFormsEqual) {
  const double d = obstacle_defaults::kClearance;
  const double rbar = Eigen::Vector3d(0.4, 0.05, 0).norm();
  const FixedProblemSolution lcl = solve_fixed_problem(ObstacleForm::lcl);
  const FixedProblemSolution sq = solve_fixed_problem(ObstacleForm::squared);
  double dx = 0, du = 0;
  for (std::size_t i = 0; i < lcl.converged.x.size(); ++i)
    dx = std::max(dx, (lcl.converged.x[i] - sq.converged.x[i]).lpNorm<Eigen::Infinity>());
  for (std::size_t i = 0; i < lcl.converged.u.size(); ++i)
    du = std::max(du, (lcl.converged.u[i] - sq.converged.u[i]).lpNorm<Eigen::Infinity>());
  std::printf("one RTI step: min predicted distance lcl %.6f m, squared %.6f m "
              "(H2 offset (r^2 + d^2)/2r = %.6f m)\n",
              lcl.one_step_min_distance, sq.one_step_min_distance,
              (rbar * rbar + d * d) / (2 * rbar));
  std::printf("converged SQP: lcl %d it, squared %d it; max |dx| %.1e, max |du| %.1e; "
              "min distance lcl %.8f m, squared %.8f m\n",
              lcl.sqp_iterations, sq.sqp_iterations, dx, du, lcl.converged_min_distance,
              sq.converged_min_distance);
  // One step: lcl reaches the boundary (the linearized nodes are on the tangent plane, so the
  // true distance is ≥ d_C), squared stays behind its deeper half-space.
  EXPECT_GE(lcl.one_step_min_distance, d - 1e-4);
  EXPECT_LT(lcl.one_step_min_distance, d + 0.01);
  EXPECT_GT(sq.one_step_min_distance, lcl.one_step_min_distance + 0.03);
  // Converged: the same solution, on the boundary.
  EXPECT_LE(dx, 1e-6);
  EXPECT_LE(du, 1e-5);
  EXPECT_NEAR(lcl.converged_min_distance, d, 1e-6);
  EXPECT_NEAR(sq.converged_min_distance, d, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// ObstacleMode against a replay of its own log. From each logged state x_k and input u_k the
// plant is integrated again here (RK4, h = Δt / substeps), and the distances to the obstacles
// (obstacle_at above) are recomputed at every substep. The metrics, the channels and the events
// must be those of the replay, and the logged states must chain (x_{k+1} = the replayed end of
// step k). The replay uses the same integrator and step, so only rounding (contraction,
// inlining) can differ: 1e-9 m is far below the millimetre scale of the checked distances.

double channel(const Telemetry& s, const std::string& name) {
  for (int i = 0; i < s.num_channels; ++i)
    if (name == s.channels[std::size_t(i)].name) return s.channels[std::size_t(i)].value;
  ADD_FAILURE() << "no channel \"" << name << "\"";
  return std::numeric_limits<double>::quiet_NaN();
}

struct ReplayCase {
  const char* name;
  ObstacleScenario scenario;
  bool expect_violations;
};

std::vector<ReplayCase> replay_cases() {
  ObstacleScenario balls = scenario(kBalls);
  balls.duration = 1.2;  // past ball 1's closest approach (~0.9 s)
  // A sphere 0.1 m from the start, inside d_C = 0.2 m: the first steps violate the clearance
  // while the vehicle backs off.
  ObstacleScenario start_inside = scenario(kCluttered);
  start_inside.duration = 0.6;
  start_inside.world.spheres.push_back(start_inside.reference.trajectory.x[0].head<3>() +
                                       Eigen::Vector3d(0.1, 0.0, 0.0));
  return {{"balls", balls, false}, {"start inside", start_inside, true}};
}

TEST(ObstacleModeReplay, MetricsChannelsAndEventsMatchAReplayOfTheLog) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const ReplayCase& c : replay_cases()) {
    SCOPED_TRACE(c.name);
    const ObstacleScenario& sc = c.scenario;
    ObstacleMode mode;
    const SetupResult setup = mode.setup(sc);
    ASSERT_TRUE(setup.ok()) << setup.reason();
    const double dt = sc.controller.dt, d_c = sc.controller.clearance;
    const double limit = d_c - obstacle_defaults::kViolationTolerance;
    const int substeps = int(std::lround(dt * sc.plant_rate_hz));
    const double h = dt / substeps;
    const OcpTrajectory& ref = sc.reference.trajectory;
    const std::size_t last = ref.x.size() - 1;
    const IntegratorErk4<models::Crazyflie> plant;

    // Run minima over substeps (with when and which obstacle) and at the control instants.
    double min_distance = kInf, min_time = 0.0, min_control = kInf, sq_tracking = 0.0;
    int closest = -1, violations = 0;
    const auto distance = [&](const Eigen::Vector3d& p, double t, bool& violated) {
      double m = kInf;
      for (int j = 0; j < sc.world.size(); ++j) {
        const double d = (p - obstacle_at(sc, j, t)).norm();
        if (d < min_distance) min_distance = d, min_time = t, closest = j;
        violated |= d < limit;
        m = std::min(m, d);
      }
      return m;
    };
    models::Crazyflie::State x_end = ref.x[0];
    bool violated0 = false;
    min_control = distance(x_end.head<3>(), 0.0, violated0);
    violations += violated0;

    int k = 0;
    double chain = 0.0, prediction = 0.0;
    while (mode.step()) {
      const Telemetry& s = mode.telemetry();
      ASSERT_EQ(s.step, k);
      ASSERT_EQ(s.x.size(), 13);
      ASSERT_EQ(s.u.size(), 4);
      ASSERT_EQ(s.predicted_reference.cols(), sc.controller.N + 1);
      EXPECT_EQ(s.t, k * dt);
      EXPECT_TRUE(s.solved);
      chain = std::max(chain, (s.x - x_end).lpNorm<Eigen::Infinity>());
      const Eigen::Vector3d p = s.x.head<3>();
      const Eigen::Vector3d p_ref = ref.x[std::min(std::size_t(k), last)].head<3>();
      EXPECT_EQ((s.reference - p_ref).norm(), 0.0);
      for (int i = 0; i <= sc.controller.N; ++i) {
        const Eigen::Vector3d r = ref.x[std::min(std::size_t(k + i), last)].head<3>();
        EXPECT_EQ((s.predicted_reference.col(i) - r).norm(), 0.0) << "node " << i;
      }
      prediction = std::max(prediction, (s.predicted.col(0) - p).norm());
      sq_tracking += (p - p_ref).squaredNorm();

      models::Crazyflie::State x = s.x, xn;
      const models::Crazyflie::Input u = s.u;
      double step_min = kInf;
      bool violated = false;
      for (int j = 0; j < substeps; ++j) {
        plant.step(x, u, h, xn);
        x = xn;
        step_min = std::min(step_min, distance(x.head<3>(), s.t + (j + 1) * h, violated));
      }
      violations += violated;
      bool ignored = false;
      min_control = std::min(min_control, distance(x.head<3>(), s.t + dt, ignored));
      x_end = x;

      EXPECT_NEAR(channel(s, "min distance"), step_min, 1e-9) << "step " << k;
      EXPECT_NEAR(channel(s, "clearance margin"), step_min - d_c, 1e-9) << "step " << k;
      EXPECT_NEAR(channel(s, "tracking error"), (p - p_ref).norm(), 1e-12) << "step " << k;
      EXPECT_EQ(channel(s, "QP iterations"), s.stats.qp_iterations) << "step " << k;
      EXPECT_EQ((s.events & kEventViolation) != 0, violated) << "step " << k;
      EXPECT_EQ((s.events & kEventFallback) != 0, s.stats.status == RtiStatus::fallback);
      EXPECT_EQ(s.events & kEventLost, 0u);
      ++k;
    }
    chain = std::max(chain, (mode.state() - x_end).lpNorm<Eigen::Infinity>());
    std::printf("%-13s %d steps: min distance %.6f m at %.3f s (obstacle %d), %.6f m at the "
                "control instants, violations %d; max |x_k - replay| %.1e, max |predicted_0 - "
                "p_k| %.1e\n",
                c.name, k, min_distance, min_time, closest, min_control, violations, chain,
                prediction);
    EXPECT_EQ(k, std::lround(sc.duration / dt));
    EXPECT_TRUE(mode.finished());
    EXPECT_FALSE(mode.step());
    EXPECT_FALSE(mode.lost());
    EXPECT_LE(chain, 1e-9);
    EXPECT_LE(prediction, 1e-9);  // the RTI plan starts at the measured state
    // Not vacuous: the vehicle comes within a millimetre of d_C, or inside it.
    EXPECT_LT(min_distance, d_c + 1e-3);
    EXPECT_EQ(violations > 0, c.expect_violations) << violations << " violations";

    std::map<std::string, double> m;
    for (const auto& [name, value] : mode.metrics()) m[name] = value;
    EXPECT_NEAR(m["min_distance_m"], min_distance, 1e-9);
    EXPECT_NEAR(m["min_margin_m"], min_distance - d_c, 1e-9);
    EXPECT_NEAR(m["min_distance_control_m"], min_control, 1e-9);
    EXPECT_EQ(m["clearance_m"], d_c);
    EXPECT_EQ(m["violations"], violations);
    EXPECT_NEAR(m["tracking_rms_m"], std::sqrt(sq_tracking / k), 1e-12);
    EXPECT_NEAR(m["final_error_m"], (x_end.head<3>() - ref.x[last].head<3>()).norm(), 1e-9);
    EXPECT_EQ(m["steps"], k);
    const ObstacleRunResult r = mode.result();
    EXPECT_NEAR(r.min_distance_time, min_time, 1e-12);
    EXPECT_EQ(r.closest_obstacle, closest);
  }
}

// ---------------------------------------------------------------------------------------------
// A scenario that cannot be flown fails in setup with the reason, and nothing runs.

TEST(ObstacleModeSetup, FailsWithTheReasonInsteadOfRunning) {
  struct Case {
    const char* what;
    void (*edit)(ObstacleScenario&);
    const char* reason;
  };
  const Case cases[] = {
      {"N = 0", [](ObstacleScenario& sc) { sc.controller.N = 0; }, "N must be at least 1"},
      {"dt = 0", [](ObstacleScenario& sc) { sc.controller.dt = 0.0; }, "dt must be positive"},
      {"negative slack weight", [](ObstacleScenario& sc) { sc.controller.slack_l2 = -1.0; },
       "negative ℓ2² slack weight"},
      {"no reference", [](ObstacleScenario& sc) { sc.reference = {}; }, "reference: no states"},
      {"1.5 substeps", [](ObstacleScenario& sc) { sc.plant_rate_hz = 100.0; },
       "whole number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    ObstacleScenario sc = scenario(kBalls);
    c.edit(sc);
    ObstacleMode mode;
    const SetupResult r = mode.setup(sc);
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.reason().find(c.reason), std::string::npos) << r.reason();
    EXPECT_TRUE(mode.finished());
    EXPECT_FALSE(mode.step());
    EXPECT_EQ(mode.steps_done(), 0);
    const ObstacleRunResult run = run_obstacle_avoidance(sc);
    EXPECT_EQ(run.error, r.reason());
    EXPECT_EQ(run.steps, 0);
    // The same object flies once set up with a valid scenario.
    const SetupResult again = mode.setup(scenario(kBalls));
    ASSERT_TRUE(again.ok()) << again.reason();
    EXPECT_TRUE(mode.step());
    EXPECT_EQ(mode.steps_done(), 1);
  }
}

// ---------------------------------------------------------------------------------------------
// A flight through make_mode() (`mixpilot fly --headless --report`): the duration override,
// the metric names in report order, the summary.

TEST(ObstacleMode, RunnerReportsMetrics) {
  const Flown r = fly_scenario(kBalls, 1.2);  // past ball 1
  ASSERT_TRUE(r.ok) << r.error;
  std::vector<std::string> names;
  for (const auto& [name, value] : r.metrics) names.push_back(name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "min_distance_m", "min_margin_m", "min_distance_control_m", "clearance_m",
                       "violations", "tracking_rms_m", "final_error_m", "rti_median_us",
                       "rti_p99_us", "fallbacks", "form", "steps"}));
  std::map<std::string, double> m(r.metrics.begin(), r.metrics.end());
  EXPECT_EQ(m["steps"], 80);
  EXPECT_EQ(m["violations"], 0);
  EXPECT_EQ(m["form"], 0);  // lcl
  EXPECT_GT(m["rti_p99_us"], 0);
  EXPECT_GE(m["rti_p99_us"], m["rti_median_us"]);
  EXPECT_NE(r.summary.find("form lcl"), std::string::npos) << r.summary;
  EXPECT_NE(r.summary.find("80 steps of 15 ms"), std::string::npos) << r.summary;
}

// ---------------------------------------------------------------------------------------------
// Scenario diagnostics: file:line:col: key: what was expected.

std::string parse_error(const std::string& text) {
  std::string error;
  const auto sc =
      parse_obstacle_scenario(text, MIXPILOT_SOURCE_DIR "/scenarios/test.toml", error);
  EXPECT_FALSE(sc);
  return error;
}

const std::string kHeader = R"(name = "t"
mode = "obstacle_avoidance"
model = "crazyflie"
[reference]
file = "references/obstacles_to_1_-1_1.csv"
)";

TEST(ObstacleScenarioFile, ValidMinimalFileLoads) {
  std::string error;
  const auto sc = parse_obstacle_scenario(kHeader, MIXPILOT_SOURCE_DIR "/scenarios/t.toml", error);
  ASSERT_TRUE(sc) << error;
  EXPECT_EQ(sc->controller.form, ObstacleForm::lcl);
  EXPECT_EQ(sc->controller.clearance, 0.2);
  EXPECT_EQ(sc->controller.N, 50);
  EXPECT_EQ(sc->reference.trajectory.u.size(), 200u);
  EXPECT_EQ(sc->world.size(), 0);
}

TEST(ObstacleScenarioFile, ErrorsNameFileLineAndKey) {
  const std::string file = MIXPILOT_SOURCE_DIR "/scenarios/test.toml";
  EXPECT_EQ(parse_error(kHeader + "[controller]\nconstraint_form = \"cubic\"\n"),
            file + ":7:19: controller.constraint_form: expected one of \"lcl\", \"squared\", got "
                   "the string \"cubic\"");
  EXPECT_EQ(parse_error(kHeader + "[controller]\nclearance = -0.2\n"),
            file + ":7:13: controller.clearance: value outside [0.001, 10], got -0.2");
  EXPECT_EQ(parse_error(kHeader + "[[balls]]\nposition = [1, 2, 3]\nvelocty = [0, 0, 1]\n"),
            file + ":6:1: balls[0].velocity: missing required key (expected an array of 3 "
                   "numbers)\n" +
                file + ":8:1: balls[0].velocty: unknown key (did you mean \"velocity\"?)");
  EXPECT_EQ(parse_error(kHeader + "[[spheres]]\ncenter = [1, 2]\n"),
            file + ":7:10: spheres[0].center: expected an array of 3 numbers, got an array of 2");
  EXPECT_EQ(parse_error(kHeader + "[plant]\nrate_hz = 1500\n"),
            file + ":7:11: plant.rate_hz: expected a rate giving a whole number of substeps per "
                   "control step, got controller.dt * rate_hz = 22.5");
  const std::string wrong_model =
      parse_error("name = \"t\"\nmode = \"obstacle_avoidance\"\nmodel = \"pendubot\"\n"
                  "[reference]\nfile = \"references/obstacles_to_1_-1_1.csv\"\n");
  EXPECT_EQ(wrong_model, file + ":3:9: model: expected one of \"crazyflie\", got the string "
                                "\"pendubot\"");
  const std::string missing = parse_error(
      "name = \"t\"\nmode = \"obstacle_avoidance\"\nmodel = \"crazyflie\"\n[reference]\n"
      "file = \"references/nope.csv\"\n");
  EXPECT_EQ(missing.rfind(file + ":5:8: reference.file: expected a readable trajectory CSV: ", 0),
            0u)
      << missing;
  // A reference with another Δt than the controller's.
  const std::string dt = parse_error(kHeader + "[controller]\ndt = 0.01\n");
  EXPECT_NE(dt.find(file + ":5:8: reference.file: expected a trajectory with the controller's "
                           "dt = 0.01 s, got dt = 0.015"),
            std::string::npos)
      << dt;
}

}  // namespace
}  // namespace mixpilot
