// The Ipopt adapter (core/nlp/nlp_ipopt.hpp) and trajectory files (core/nlp/trajectory_io.hpp):
// - a linear-quadratic OCP against a dense KKT solve;
// - hard and soft (ℓ1, ℓ2²) path constraints and state bounds against the dense KKT solve of
//   the active set the adapter found (which verifies that set: multiplier signs, feasibility);
// - the committed SPEC §5.2 smooth-step reference: dynamics, bounds, endpoints, recomputation;
// - CSV round trip and reader errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include <Eigen/Dense>

#include "core/control/crazyflie_tracking.hpp"
#include "core/nlp/nlp_ipopt.hpp"
#include "core/nlp/trajectory_io.hpp"

#ifndef MIXPILOT_SOURCE_DIR
#error "MIXPILOT_SOURCE_DIR must point to the repository root"
#endif

namespace mixpilot {
namespace {

// Two decoupled double integrators, exact zero-order-hold discretization:
// x = (p1, p2, v1, v2), u = (a1, a2); F(x, u) = A x + B u.
class DoubleIntegrator final : public Integrator {
 public:
  explicit DoubleIntegrator(double dt) : A_(Eigen::MatrixXd::Identity(4, 4)), B_(4, 2) {
    A_(0, 2) = A_(1, 3) = dt;
    B_.setZero();
    B_(0, 0) = B_(1, 1) = 0.5 * dt * dt;
    B_(2, 0) = B_(3, 1) = dt;
  }
  int nx() const override { return 4; }
  int nu() const override { return 2; }
  const Eigen::MatrixXd& A() const { return A_; }
  const Eigen::MatrixXd& B() const { return B_; }
  IntegratorStatus step(const Eigen::Ref<const Eigen::VectorXd>& x,
                        const Eigen::Ref<const Eigen::VectorXd>& u, double,
                        Eigen::Ref<Eigen::VectorXd> x_next) const override {
    x_next = A_ * x + B_ * u;
    return IntegratorStatus::success;
  }
  IntegratorStatus step_sensitivities(const Eigen::Ref<const Eigen::VectorXd>& x,
                                      const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                                      Eigen::Ref<Eigen::VectorXd> x_next,
                                      Eigen::Ref<Eigen::MatrixXd> A,
                                      Eigen::Ref<Eigen::MatrixXd> B) const override {
    A = A_;
    B = B_;
    return step(x, u, dt, x_next);
  }

 private:
  Eigen::MatrixXd A_;  // 4 x 4
  Eigen::MatrixXd B_;  // 4 x 2
};

// g(x, u) = sign · p1 (a linear path constraint; sign = −1 exercises the lower side).
class PositionConstraint final : public PathConstraint {
 public:
  explicit PositionConstraint(double sign) : sign_(sign) {}
  int ng() const override { return 1; }
  void eval(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>&,
            const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd> g,
            Eigen::Ref<Eigen::MatrixXd> Gx, Eigen::Ref<Eigen::MatrixXd> Gu) const override {
    g(0) = sign_ * x(0);
    Gx.setZero();
    Gx(0, 0) = sign_;
    Gu.setZero();
  }

 private:
  double sign_;
};

constexpr int kN = 20;
constexpr double kDt = 0.1;
constexpr double kCap = 0.5;  // the constrained position: p1 ≤ kCap

// The test OCP: y = (x, u), y_N = x with random symmetric positive definite weights and random
// references; the terminal reference pulls p1 to 1, past the cap.
struct LinearProblem {
  DoubleIntegrator integrator{kDt};
  SelectionOutput output{Eigen::VectorXi::LinSpaced(4, 0, 3), Eigen::VectorXi::LinSpaced(2, 0, 1)};
  SelectionOutput terminal{Eigen::VectorXi::LinSpaced(4, 0, 3), Eigen::VectorXi()};
  PositionConstraint upper{1.0}, lower{-1.0};
  Ocp ocp;
  OcpStageData data;
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(4);

  LinearProblem() {
    ocp.integrator = &integrator;
    ocp.N = kN;
    ocp.dt = kDt;
    ocp.output = &output;
    ocp.terminal_output = &terminal;
    data.resize(ocp);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    for (int i = 0; i <= kN; ++i) {
      const int ny = i < kN ? 6 : 4;
      Eigen::MatrixXd L(ny, ny);
      for (int r = 0; r < ny; ++r)
        for (int c = 0; c < ny; ++c) L(r, c) = 0.3 * uni(rng);
      data.W[i] = L * L.transpose() + Eigen::MatrixXd::Identity(ny, ny) * (i < kN ? 0.5 : 50.0);
      for (int r = 0; r < ny; ++r) data.yref[i](r) = 0.1 * uni(rng);
    }
    data.yref[kN](0) = 1.0;
    x0 << 0.0, 0.0, 0.1, -0.1;
  }

  // Soft or hard p1 ≤ kCap as a state bound (mode 0), a path constraint g = p1 ≤ kCap (mode 1)
  // or g = −p1 ≥ −kCap (mode 2).
  void constrain(int mode, bool soft, double Z, double z) {
    SoftConstraint s;
    s.index = 0;
    if (mode == 0) {
      ocp.idxbx = Eigen::VectorXi::Constant(1, 0);
      ocp.lbx = Eigen::VectorXd::Constant(1, -1e20);
      ocp.ubx = Eigen::VectorXd::Constant(1, kCap);
      if (soft) ocp.soft_state_bounds = {s};
    } else {
      ocp.constraint = mode == 1 ? &upper : &lower;
      ocp.lg = Eigen::VectorXd::Constant(1, mode == 1 ? -1e20 : -kCap);
      ocp.ug = Eigen::VectorXd::Constant(1, mode == 1 ? kCap : 1e20);
      if (soft) ocp.soft_constraints = {s};
    }
    for (auto* list : {&ocp.soft_state_bounds, &ocp.soft_constraints})
      for (auto& sc : *list) {
        (mode == 2 ? sc.Zl : sc.Zu) = Z;
        (mode == 2 ? sc.zl : sc.zu) = z;
      }
  }
};

// Dense reference: z = (u_0, x_1, u_1, ..., x_N); min ½zᵀHz + gᵀz s.t. Cz = d, solved through
// its KKT system. `active` stages get p1 = kCap; `penalized` stages get ½Z(p1 − kCap)² +
// z(p1 − kCap) added (the soft problem on the set where the slack is positive).
struct DenseSolution {
  OcpTrajectory traj;
  std::vector<double> nu;  // multiplier of p1 ≤ kCap per active stage (≥ 0 at a KKT point)
};

DenseSolution dense_solve(const LinearProblem& lp, const std::vector<int>& active,
                          const std::vector<int>& penalized, double Z, double zl1) {
  const int nx = 4, nu = 2, N = kN;
  const int nz = N * (nx + nu);
  auto uidx = [&](int i) { return i == 0 ? 0 : nu + (i - 1) * (nx + nu) + nx; };
  auto xidx = [&](int k) { return nu + (k - 1) * (nx + nu); };
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(nz, nz);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(nz);
  for (int i = 0; i <= N; ++i) {
    // y_i = M z + m.
    const int ny = i < N ? 6 : 4;
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(ny, nz);
    Eigen::VectorXd m = -lp.data.yref[i];
    if (i == 0)
      m.head(nx) += lp.x0;
    else
      M.block(0, xidx(i), nx, nx).setIdentity();
    if (i < N) M.block(nx, uidx(i), nu, nu).setIdentity();
    H += M.transpose() * lp.data.W[i] * M;
    g += M.transpose() * lp.data.W[i] * m;
  }
  for (int k : penalized) {
    H(xidx(k), xidx(k)) += Z;
    g(xidx(k)) += zl1 - Z * kCap;
  }
  const int nc = N * nx + int(active.size());
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(nc, nz);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(nc);
  for (int i = 0; i < N; ++i) {  // x_{i+1} − A x_i − B u_i = 0
    C.block(i * nx, xidx(i + 1), nx, nx).setIdentity();
    C.block(i * nx, uidx(i), nx, nu) = -lp.integrator.B();
    if (i == 0)
      d.head(nx) = lp.integrator.A() * lp.x0;
    else
      C.block(i * nx, xidx(i), nx, nx) = -lp.integrator.A();
  }
  for (size_t a = 0; a < active.size(); ++a) {
    C(N * nx + a, xidx(active[a])) = 1.0;
    d(N * nx + a) = kCap;
  }
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nz + nc, nz + nc);
  K.topLeftCorner(nz, nz) = H;
  K.topRightCorner(nz, nc) = C.transpose();
  K.bottomLeftCorner(nc, nz) = C;
  Eigen::VectorXd rhs(nz + nc);
  rhs << -g, d;
  const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
  DenseSolution out;
  out.traj.resize(lp.ocp);
  out.traj.x[0] = lp.x0;
  for (int i = 0; i < N; ++i) out.traj.u[i] = sol.segment(uidx(i), nu);
  for (int k = 1; k <= N; ++k) out.traj.x[k] = sol.segment(xidx(k), nx);
  for (size_t a = 0; a < active.size(); ++a) out.nu.push_back(sol(nz + N * nx + a));
  return out;
}

double max_difference(const OcpTrajectory& a, const OcpTrajectory& b) {
  double d = 0.0;
  for (size_t k = 0; k < a.x.size(); ++k) d = std::max(d, (a.x[k] - b.x[k]).cwiseAbs().maxCoeff());
  for (size_t i = 0; i < a.u.size(); ++i) d = std::max(d, (a.u[i] - b.u[i]).cwiseAbs().maxCoeff());
  return d;
}

IpoptOcpResult solve(const LinearProblem& lp, OcpTrajectory& traj,
                     IpoptHessian hessian = IpoptHessian::gauss_newton_fd_curvature) {
  traj.resize(lp.ocp);
  IpoptOcpSettings settings;
  settings.hessian = hessian;
  IpoptOcpSolver solver(settings);
  return solver.solve(lp.ocp, lp.data, lp.x0, traj);
}

TEST(IpoptOcp, LinearQuadraticMatchesDenseKkt) {
  const LinearProblem lp;
  const DenseSolution ref = dense_solve(lp, {}, {}, 0.0, 0.0);
  for (IpoptHessian h : {IpoptHessian::gauss_newton_fd_curvature, IpoptHessian::gauss_newton}) {
    OcpTrajectory traj;
    const IpoptOcpResult r = solve(lp, traj, h);
    ASSERT_EQ(r.status, IpoptOcpStatus::solved) << r.message;
    EXPECT_LE(max_difference(traj, ref.traj), 1e-7);
    EXPECT_LE(r.dynamics_residual, 1e-9);
    EXPECT_LE(r.iterations, 20);
  }
}

TEST(IpoptOcp, InvalidInputIsReportedNotThrown) {
  const LinearProblem lp;
  OcpTrajectory traj(lp.ocp);
  traj.u.pop_back();
  IpoptOcpSolver solver;
  const IpoptOcpResult r = solver.solve(lp.ocp, lp.data, lp.x0, traj);
  EXPECT_EQ(r.status, IpoptOcpStatus::invalid_input);
  EXPECT_STRNE(r.message, "");
  EXPECT_EQ(int(traj.u.size()), kN - 1);  // untouched
}

// The hard-constrained solution for each way of stating p1 ≤ kCap: the dense KKT solution on
// the adapter's active set agrees, its multipliers are ≥ 0 and the other stages are feasible.
// Returns the multipliers.
std::vector<double> check_hard(int mode, OcpTrajectory* out = nullptr) {
  LinearProblem lp;
  lp.constrain(mode, false, 0.0, 0.0);
  OcpTrajectory traj;
  const IpoptOcpResult r = solve(lp, traj);
  EXPECT_EQ(r.status, IpoptOcpStatus::solved) << r.message;
  std::vector<int> active;
  for (int k = 1; k <= kN; ++k) {
    EXPECT_LE(traj.x[k](0), kCap + 1e-9) << "stage " << k;
    if (traj.x[k](0) > kCap - 1e-6) active.push_back(k);
  }
  EXPECT_FALSE(active.empty());
  const DenseSolution ref = dense_solve(lp, active, {}, 0.0, 0.0);
  EXPECT_LE(max_difference(traj, ref.traj), 1e-7) << "mode " << mode;
  for (double nu : ref.nu) EXPECT_GT(nu, 1e-6);
  if (out) *out = traj;
  return ref.nu;
}

TEST(IpoptOcp, HardStateBoundAndPathConstraintsAgreeWithKkt) {
  OcpTrajectory a, b, c;
  check_hard(0, &a);
  check_hard(1, &b);
  check_hard(2, &c);
  EXPECT_LE(max_difference(a, b), 1e-7);
  EXPECT_LE(max_difference(a, c), 1e-7);
}

// Soft p1 ≤ kCap with weights (Z, z): the slack is positive exactly where p1 > kCap and equals
// the violation; the trajectory is the dense solution with the penalty on that set.
void check_soft(int mode, double Z, double z, bool expect_violation) {
  LinearProblem lp;
  lp.constrain(mode, true, Z, z);
  OcpTrajectory traj;
  traj.resize(lp.ocp);
  IpoptOcpSolver solver;
  const IpoptOcpResult r = solver.solve(lp.ocp, lp.data, lp.x0, traj);
  ASSERT_EQ(r.status, IpoptOcpStatus::solved) << r.message;
  const auto& slack = mode == 2 ? solver.slack_lower() : solver.slack_upper();
  const auto& other = mode == 2 ? solver.slack_upper() : solver.slack_lower();
  ASSERT_EQ(int(slack.size()), kN + 1);
  std::vector<int> violated;
  double max_violation = 0.0;
  for (int k = 1; k <= kN; ++k) {
    const double violation = traj.x[k](0) - kCap;
    max_violation = std::max(max_violation, violation);
    EXPECT_NEAR(slack[k](0), std::max(0.0, violation), 1e-8) << "stage " << k;
    EXPECT_EQ(other[k](0), 0.0);  // the infinite side has no slack
    if (violation > 1e-6) violated.push_back(k);
  }
  if (expect_violation) {
    EXPECT_FALSE(violated.empty());
    EXPECT_GT(max_violation, 1e-3);
  } else {
    EXPECT_LE(max_violation, 1e-8);
  }
  // The exact penalty keeps p1 = kCap on stages that are at the cap without slack.
  std::vector<int> active;
  for (int k = 1; k <= kN; ++k)
    if (std::abs(traj.x[k](0) - kCap) <= 1e-6) active.push_back(k);
  const DenseSolution ref = dense_solve(lp, active, violated, Z, z);
  EXPECT_LE(max_difference(traj, ref.traj), 1e-7) << "mode " << mode << " Z " << Z << " z " << z;
  for (double nu : ref.nu) {  // 0 ≤ ν ≤ z where the slack is zero (ℓ1 subgradient)
    EXPECT_GE(nu, -1e-6);
    EXPECT_LE(nu, z + 1e-6);
  }
}

TEST(IpoptOcp, SoftConstraintsExactPenaltyAndSlackValues) {
  const std::vector<double> nu = check_hard(1);
  const double nu_max = *std::max_element(nu.begin(), nu.end());
  for (int mode : {0, 1, 2}) {
    SCOPED_TRACE("mode " + std::to_string(mode));
    check_soft(mode, 0.0, 2.0 * nu_max, false);   // ℓ1 above the multipliers: exact
    check_soft(mode, 0.0, 0.25 * nu_max, true);   // ℓ1 below: violated, slack = violation
    check_soft(mode, 100.0, 0.1 * nu_max, true);  // ℓ2² + ℓ1
  }
}

// --- The committed smooth-step reference (SPEC §5.2) ---

const std::string kReference =
    std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/references/crazyflie_smooth_step.csv";

TEST(SmoothStepReference, CommittedFileIsAFeasibleConvergedStep) {
  std::string error;
  const auto file = read_trajectory_csv(kReference, error);
  ASSERT_TRUE(file) << error;
  const OcpTrajectory& ref = file->trajectory;
  ASSERT_EQ(int(ref.u.size()), 400);
  ASSERT_EQ(int(ref.x.size()), 401);
  EXPECT_DOUBLE_EQ(file->dt, 0.015);
  const CrazyflieTracking problem(400, 0.015);
  const Eigen::VectorXd hover0 = problem.model().hover_state({0.0, 0.0, 0.4});
  EXPECT_EQ(ref.x[0], hover0);
  EXPECT_LE((ref.x[400].head<3>() - Eigen::Vector3d(1.0, -1.0, 1.0)).norm(), 0.01);
  Eigen::VectorXd xn(13);
  double residual = 0.0;
  for (int i = 0; i < 400; ++i) {
    ASSERT_EQ(ref.x[i].size(), 13);
    ASSERT_EQ(ref.u[i].size(), 4);
    EXPECT_GE(ref.u[i].minCoeff(), 0.0) << "stage " << i;
    EXPECT_LE(ref.u[i].maxCoeff(), 22.0) << "stage " << i;
    problem.integrator().step(ref.x[i], ref.u[i], 0.015, xn);
    residual = std::max(residual, (xn - ref.x[i + 1]).norm());
  }
  EXPECT_LE(residual, 1e-8);
}

TEST(SmoothStepReference, RecomputationMatchesTheFile) {
  std::string error;
  const auto file = read_trajectory_csv(kReference, error);
  ASSERT_TRUE(file) << error;
  const CrazyflieTracking problem(400, 0.015);
  OcpStageData data(problem.ocp());
  problem.set_hover_target(data, {1.0, -1.0, 1.0});
  OcpTrajectory traj(problem.ocp());
  problem.hover_guess(traj, {0.0, 0.0, 0.4});
  IpoptOcpSolver solver;
  const IpoptOcpResult r =
      solver.solve(problem.ocp(), data, problem.model().hover_state({0.0, 0.0, 0.4}), traj);
  ASSERT_EQ(r.status, IpoptOcpStatus::solved) << r.message;
  EXPECT_LE(r.iterations, 60);
  EXPECT_LE(r.dynamics_residual, 1e-9);
  EXPECT_LE(max_difference(traj, file->trajectory), 1e-6);
}

// --- CSV files ---

std::string temp_path(const std::string& name) {
  return (std::string(::testing::TempDir()) + "/mixpilot_" + name);
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(TrajectoryCsv, RoundTripIsExact) {
  OcpTrajectory traj;
  std::mt19937 rng(3);
  std::normal_distribution<double> nd;
  for (int k = 0; k <= 5; ++k) traj.x.push_back(Eigen::VectorXd::NullaryExpr(3, [&] { return nd(rng); }));
  for (int i = 0; i < 5; ++i) traj.u.push_back(Eigen::VectorXd::NullaryExpr(2, [&] { return nd(rng); }));
  const std::string path = temp_path("roundtrip.csv");
  std::string error;
  ASSERT_TRUE(write_trajectory_csv(path, traj, 0.015, error)) << error;
  const auto back = read_trajectory_csv(path, error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(back->dt, 0.015);
  ASSERT_EQ(back->trajectory.x.size(), traj.x.size());
  ASSERT_EQ(back->trajectory.u.size(), traj.u.size());
  for (size_t k = 0; k < traj.x.size(); ++k) EXPECT_EQ(back->trajectory.x[k], traj.x[k]);
  for (size_t i = 0; i < traj.u.size(); ++i) EXPECT_EQ(back->trajectory.u[i], traj.u[i]);
  std::remove(path.c_str());
}

TEST(TrajectoryCsv, ErrorsNameFileAndLine) {
  std::string error;
  const std::string missing = temp_path("does_not_exist.csv");
  EXPECT_FALSE(read_trajectory_csv(missing, error));
  EXPECT_NE(error.find(missing), std::string::npos) << error;

  const std::string header = "t,x0,x1,u0\n";
  const std::string short_row = temp_path("short_row.csv");
  write_text(short_row, header + "0,1,2,3\n0.1,1,2\n0.2,1,2,\n");
  EXPECT_FALSE(read_trajectory_csv(short_row, error));
  EXPECT_NE(error.find(short_row + ":3:"), std::string::npos) << error;
  EXPECT_NE(error.find("expected 4 cells"), std::string::npos) << error;

  const std::string not_number = temp_path("not_number.csv");
  write_text(not_number, header + "0,1,2,3\n0.1,1,abc,3\n0.2,1,2,\n");
  EXPECT_FALSE(read_trajectory_csv(not_number, error));
  EXPECT_NE(error.find(not_number + ":3:"), std::string::npos) << error;
  EXPECT_NE(error.find("x1"), std::string::npos) << error;
  EXPECT_NE(error.find("abc"), std::string::npos) << error;

  const std::string bad_header = temp_path("bad_header.csv");
  write_text(bad_header, "t,x0,y1,u0\n");
  EXPECT_FALSE(read_trajectory_csv(bad_header, error));
  EXPECT_NE(error.find(bad_header + ":1:"), std::string::npos) << error;

  const std::string no_last = temp_path("no_last.csv");
  write_text(no_last, header + "0,1,2,3\n0.1,1,2,3\n");
  EXPECT_FALSE(read_trajectory_csv(no_last, error));
  EXPECT_NE(error.find("last row"), std::string::npos) << error;

  const std::string good = temp_path("good.csv");
  write_text(good, header + "0,1,2,3\n0.1,1,2,\n");
  const auto ok = read_trajectory_csv(good, error);
  ASSERT_TRUE(ok) << error;
  EXPECT_EQ(ok->trajectory.x.size(), 2u);
  EXPECT_EQ(ok->trajectory.u.size(), 1u);
  for (const auto& p : {short_row, not_number, bad_header, no_last, good}) std::remove(p.c_str());
}

// A CSV read as any editor or spreadsheet writes it: a UTF-8 byte-order mark, CR LF or old
// Mac CR line ends; and a cell echoed in an error never carries a terminal escape sequence.
TEST(TrajectoryCsv, EditorsLineEndsAndNoEscapesInErrors) {
  std::string error;
  for (const std::string nl : {"\n", "\r\n", "\r"}) {
    const std::string path = temp_path("line_ends.csv");
    write_text(path, "\xEF\xBB\xBFt,x0,x1,u0" + nl + "0,1,2,3" + nl + "0.1,1,2," + nl);
    const auto ok = read_trajectory_csv(path, error);
    ASSERT_TRUE(ok) << error;
    EXPECT_EQ(ok->trajectory.x.size(), 2u);
    EXPECT_EQ(ok->dt, 0.1);
    std::remove(path.c_str());
  }
  const std::string path = temp_path("escape.csv");
  write_text(path, "t,x0,x1,u0\n0,1,\x1b[2J\x1b]0;owned\x07,3\n0.1,1,2,\n");
  EXPECT_FALSE(read_trajectory_csv(path, error));
  EXPECT_EQ(error.find('\x1b'), std::string::npos) << error;
  EXPECT_EQ(error.find('\x07'), std::string::npos) << error;
  EXPECT_NE(error.find("found \"\\x1B[2J\\x1B]0;owned\\x07\""), std::string::npos) << error;
  write_text(path, "t,x0,\x1b[31mx1,u0\n");
  EXPECT_FALSE(read_trajectory_csv(path, error));
  EXPECT_NE(error.find("found \"\\x1B[31mx1\""), std::string::npos) << error;
  std::remove(path.c_str());
}

}  // namespace
}  // namespace mixpilot
