// Models of SPEC §3: hover equilibria, energy conservation, continuous Jacobians vs FD.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "core/numerics/integrator_erk4.hpp"
#include "models/crazyflie.hpp"
#include "models/dual.hpp"
#include "models/mikrokopter.hpp"
#include "models/model.hpp"
#include "models/pendubot.hpp"
#include "tests/random_states.hpp"

namespace mixpilot {
namespace {

using models::Crazyflie;
using models::MikroKopter;
using models::Pendubot;

TEST(Crazyflie, HoverSpeedMatchesSpec) {
  const Crazyflie cf;
  EXPECT_NEAR(cf.hover_speed(), 15.78, 0.005);  // krpm, SPEC §3.2
}

TEST(Crazyflie, HoverIsAnEquilibrium) {
  const Crazyflie cf;
  Crazyflie::State xdot;
  cf.dynamics(cf.hover_state({0.3, -0.2, 1.0}), cf.hover_input(), xdot);
  EXPECT_LT(xdot.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(MikroKopter, HoverSpeedAndTorqueMatchSpec) {
  const MikroKopter mk;
  EXPECT_NEAR(mk.hover_speed(), 0.0655, 5e-5);   // SPEC §3.3
  EXPECT_NEAR(mk.hover_torque(), 0.0756, 5e-5);  // τ = C_D Ω² + D Ω
  EXPECT_LT(mk.hover_torque(), mk.p.tau_max);
  // Rotor time constant J_m / (2 C_D Ω + D) ≈ 44 ms.
  EXPECT_NEAR(mk.p.J_m / (2.0 * mk.p.C_D * mk.hover_speed() + mk.p.D), 0.044, 0.0005);
}

TEST(MikroKopter, HoverIsAnEquilibrium) {
  const MikroKopter mk;
  MikroKopter::State xdot;
  mk.dynamics(mk.hover_state({-1.0, 2.0, 0.5}), mk.hover_input(), xdot);
  EXPECT_LT(xdot.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(MikroKopter, HoverAttitudeHeldUnderYaw) {
  // Yaw does not change the hover equilibrium: R(γ)ᵀ e3 is independent of ψ.
  const MikroKopter mk;
  MikroKopter::State x = mk.hover_state({0, 0, 1});
  x(5) = 1.2;
  MikroKopter::State xdot;
  mk.dynamics(x, mk.hover_input(), xdot);
  EXPECT_LT(xdot.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Pendubot, UprightAndHangingAreEquilibria) {
  const Pendubot pb;
  Pendubot::State xdot;
  for (const auto& x : {Pendubot::up_up(), Pendubot::down_down()}) {
    pb.dynamics(x, Pendubot::Input(Pendubot::Input::Zero()), xdot);
    EXPECT_LT(xdot.cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Pendubot, PeakGravityTorqueIsJustBelowInputBound) {
  // SPEC §3.1: the shoulder holds the straight arm horizontal with ≈0.378 N·m, so swing-up must
  // pump. Measured on the model: the gravity torque at the shoulder is ∂V/∂q1 of the potential
  // energy (the model's energy at rest), largest over the straight arm's angles.
  const Pendubot pb;
  double peak = 0.0;
  for (double q1 = -std::numbers::pi; q1 <= std::numbers::pi; q1 += 1e-3) {
    const double h = 1e-6;
    const double torque = (pb.energy(Pendubot::State(q1 + h, 0, 0, 0)) -
                           pb.energy(Pendubot::State(q1 - h, 0, 0, 0))) / (2 * h);
    peak = std::max(peak, std::abs(torque));
  }
  EXPECT_NEAR(peak, 0.378, 0.001);
  EXPECT_LT(peak, pb.p.u_max);
}

TEST(Pendubot, FrictionlessMotionConservesEnergy) {
  // u = 0, Δt = 1 ms, 10 s of a large chaotic swing: ERK4's energy drift must stay below 1e-6
  // relative (E is measured from the down-down rest, so E > 0 throughout).
  const Pendubot pb;
  const IntegratorErk4<Pendubot> erk4(pb);
  Pendubot::State x(-std::numbers::pi + 1.2, 0.8, 1.5, -2.0);
  const double e0 = pb.energy(x);
  ASSERT_GT(e0, 0.1);
  double worst = 0.0;
  const double q1_0 = x(0), q2_0 = x(1);
  double q1_range = 0.0, q2_range = 0.0;
  for (int k = 0; k < 10000; ++k) {
    Pendubot::State xn;
    erk4.step(x, Pendubot::Input(Pendubot::Input::Zero()), 1e-3, xn);
    x = xn;
    worst = std::max(worst, std::abs(pb.energy(x) - e0) / e0);
    q1_range = std::max(q1_range, std::abs(x(0) - q1_0));
    q2_range = std::max(q2_range, std::abs(x(1) - q2_0));
  }
  EXPECT_LT(worst, 1e-6);
  // The motion really was large: both links swung through more than a right angle.
  EXPECT_GT(q1_range, std::numbers::pi / 2);
  EXPECT_GT(q2_range, std::numbers::pi / 2);
}

// ∂f/∂x and ∂f/∂u by AD against central finite differences at random states.
template <class M>
void expect_jacobians_match_fd(const M& model, int seed) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 20; ++trial) {
    const typename M::State x = testing_states::random_state(model, rng);
    const typename M::Input u = testing_states::random_input(model, rng);
    typename M::State f;
    Eigen::Matrix<double, M::nx, M::nx> fx;
    Eigen::Matrix<double, M::nx, M::nu> fu;
    models::dynamics_jacobians(model, x, u, f, fx, fu);

    typename M::State f_plain;
    model.dynamics(x, u, f_plain);
    EXPECT_LT((f - f_plain).norm(), 1e-14 * (1.0 + f_plain.norm()));

    Eigen::Matrix<double, M::nx, M::nx> fx_fd;
    Eigen::Matrix<double, M::nx, M::nu> fu_fd;
    for (int j = 0; j < M::nx; ++j) {
      const double h = 1e-5 * std::max(1.0, std::abs(x(j)));
      typename M::State xp = x, xm = x, fp, fm;
      xp(j) += h;
      xm(j) -= h;
      model.dynamics(xp, u, fp);
      model.dynamics(xm, u, fm);
      fx_fd.col(j) = (fp - fm) / (2.0 * h);
    }
    for (int j = 0; j < M::nu; ++j) {
      const double h = 1e-5 * std::max(1.0, std::abs(u(j)));
      typename M::Input up = u, um = u;
      typename M::State fp, fm;
      up(j) += h;
      um(j) -= h;
      model.dynamics(x, up, fp);
      model.dynamics(x, um, fm);
      fu_fd.col(j) = (fp - fm) / (2.0 * h);
    }
    EXPECT_LE((fx - fx_fd).norm(), 1e-6 * fx.norm()) << M::name << " trial " << trial;
    EXPECT_LE((fu - fu_fd).norm(), 1e-6 * fu.norm()) << M::name << " trial " << trial;
  }
}

TEST(Jacobians, PendubotMatchesFiniteDifferences) { expect_jacobians_match_fd(Pendubot{}, 1); }
TEST(Jacobians, CrazyflieMatchesFiniteDifferences) { expect_jacobians_match_fd(Crazyflie{}, 2); }
TEST(Jacobians, MikroKopterMatchesFiniteDifferences) {
  expect_jacobians_match_fd(MikroKopter{}, 3);
}

// A model's hand-written tangent (dynamics_tangent, models/model.hpp) against the AD of its
// dynamics(), to rounding: random states and inputs, every seed direction dense and random, so
// each Jacobian nonzero meets a nonzero derivative in every lane (a wrong or missing partial
// shows as an O(1) relative error). Rounding: a few dozen operations on terms no larger than the
// largest derivative, against 1e-12 of it.
template <class M, int n>
void expect_tangent_matches_ad(const M& model, int seed) {
  using Ad = models::Dual<n>;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const auto seeded = [&](double value) {
    Ad a(value);
    for (int j = 0; j < n; ++j) a.d[j / 4][j % 4] = normal(rng);
    return a;
  };
  for (int trial = 0; trial < 50; ++trial) {
    const typename M::State x = testing_states::random_state(model, rng);
    const typename M::Input u = testing_states::random_input(model, rng);
    Eigen::Matrix<Ad, M::nx, 1> xa, fa, ft;
    Eigen::Matrix<Ad, M::nu, 1> ua;
    for (int i = 0; i < M::nx; ++i) xa(i) = seeded(x(i));
    for (int i = 0; i < M::nu; ++i) ua(i) = seeded(u(i));
    model.dynamics(xa, ua, fa);
    model.dynamics_tangent(xa, ua, ft);
    double scale = 0.0, value_scale = 0.0;
    for (int i = 0; i < M::nx; ++i) {
      value_scale = std::max(value_scale, std::abs(fa(i).v));
      for (int j = 0; j < n; ++j) scale = std::max(scale, std::abs(fa(i).derivative(j)));
    }
    for (int i = 0; i < M::nx; ++i) {
      EXPECT_NEAR(ft(i).v, fa(i).v, 1e-14 * (1.0 + value_scale)) << "f(" << i << ")";
      for (int j = 0; j < n; ++j)
        EXPECT_NEAR(ft(i).derivative(j), fa(i).derivative(j), 1e-12 * scale)
            << M::name << " trial " << trial << ": f(" << i << ") direction " << j;
    }
  }
}

TEST(Jacobians, MikroKopterTangentMatchesItsAd) {
  expect_tangent_matches_ad<MikroKopter, MikroKopter::nx + MikroKopter::nu>(MikroKopter{}, 4);
  expect_tangent_matches_ad<MikroKopter, 3>(MikroKopter{}, 5);  // one block, one padding lane
}

TEST(Jacobians, CrazyflieTangentMatchesItsAd) {
  expect_tangent_matches_ad<Crazyflie, Crazyflie::nx + Crazyflie::nu>(Crazyflie{}, 6);
  expect_tangent_matches_ad<Crazyflie, 3>(Crazyflie{}, 7);  // one block, one padding lane
}

// Dual numbers (models/dual.hpp): every operation against Eigen's AutoDiffScalar (to rounding)
// and against central differences of the same expression in double. The operands a(z), b(z)
// are affine in z ∈ R⁵ with dense gradients, so each direction and the padding lanes of the
// second block (5 of 8 used) are exercised.
constexpr int kDirs = 5;
using D = models::Dual<kDirs>;
using Eig = Eigen::AutoDiffScalar<Eigen::Matrix<double, kDirs, 1>>;
using Vec = Eigen::Matrix<double, kDirs, 1>;

struct Operand {
  double value;
  Vec grad;
  D dual() const {
    D r(value);
    for (int j = 0; j < kDirs; ++j) r.d[j / 4][j % 4] = grad(j);
    return r;
  }
  Eig eigen() const { return Eig(value, grad); }
  double at(int j, double h) const { return value + h * grad(j); }  // a(z₀ + h e_j)
};

template <class F>
void expect_op_matches(const char* what, F f, const Operand& a, const Operand& b) {
  const D r = f(a.dual(), b.dual());
  const Eig e = f(a.eigen(), b.eigen());
  const double scale = std::max(1.0, e.derivatives().norm());
  EXPECT_NEAR(r.value(), e.value(), 1e-15 * std::max(1.0, std::abs(e.value()))) << what;
  EXPECT_LE((r.derivatives() - e.derivatives()).norm(), 1e-14 * scale) << what;
  for (int j = kDirs; j < 4 * D::blocks; ++j) EXPECT_EQ(r.d[j / 4][j % 4], 0.0) << what;
  for (int j = 0; j < kDirs; ++j) {
    const double h = 1e-6;
    const double fd = (f(a.at(j, h), b.at(j, h)) - f(a.at(j, -h), b.at(j, -h))) / (2.0 * h);
    EXPECT_NEAR(r.derivative(j), fd, 1e-7 * scale) << what << " direction " << j;
  }
}

TEST(Dual, OperationsMatchAutoDiffAndFiniteDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    Operand a{uni(rng), Vec::NullaryExpr([&] { return uni(rng); })};
    Operand b{uni(rng), Vec::NullaryExpr([&] { return uni(rng); })};
    if (std::abs(b.value) < 0.2) b.value += 0.5;  // keep a/b, c/b well conditioned
    const Operand pos{0.5 + std::abs(a.value), a.grad};  // for sqrt
    const double c = uni(rng);
    using std::cos;
    using std::sin;
    using std::sqrt;
    expect_op_matches("-a", [](auto x, auto) { return -x; }, a, b);
    expect_op_matches("a + b", [](auto x, auto y) { return x + y; }, a, b);
    expect_op_matches("a - b", [](auto x, auto y) { return x - y; }, a, b);
    expect_op_matches("a * b", [](auto x, auto y) { return x * y; }, a, b);
    expect_op_matches("a / b", [](auto x, auto y) { return x / y; }, a, b);
    expect_op_matches("a + c", [c](auto x, auto) { return x + c; }, a, b);
    expect_op_matches("c + a", [c](auto x, auto) { return c + x; }, a, b);
    expect_op_matches("a - c", [c](auto x, auto) { return x - c; }, a, b);
    expect_op_matches("c - a", [c](auto x, auto) { return c - x; }, a, b);
    expect_op_matches("a * c", [c](auto x, auto) { return x * c; }, a, b);
    expect_op_matches("c * a", [c](auto x, auto) { return c * x; }, a, b);
    expect_op_matches("a / c", [c](auto x, auto) { return x / (c + 3.0); }, a, b);
    expect_op_matches("c / b", [c](auto, auto y) { return c / y; }, a, b);
    expect_op_matches("sqrt a", [](auto x, auto) { return sqrt(x); }, pos, b);
    expect_op_matches("sin a", [](auto x, auto) { return sin(x); }, a, b);
    expect_op_matches("cos a", [](auto x, auto) { return cos(x); }, a, b);
    // Compound assignments, including with an aliased operand.
    expect_op_matches("a += b", [](auto x, auto y) { x += y; return x; }, a, b);
    expect_op_matches("a -= b", [](auto x, auto y) { x -= y; return x; }, a, b);
    expect_op_matches("a *= b", [](auto x, auto y) { x *= y; return x; }, a, b);
    expect_op_matches("a /= b", [](auto x, auto y) { x /= y; return x; }, a, b);
    expect_op_matches("a *= a", [](auto x, auto) { x *= x; return x; }, a, b);
    expect_op_matches("a += c", [c](auto x, auto) { x += c; return x; }, a, b);
    expect_op_matches("a -= c", [c](auto x, auto) { x -= c; return x; }, a, b);
    expect_op_matches("a *= c", [c](auto x, auto) { x *= c; return x; }, a, b);
    expect_op_matches("a /= c", [c](auto x, auto) { x /= (c + 3.0); return x; }, a, b);
    // A composite, as models use them.
    expect_op_matches(
        "composite",
        [c](auto x, auto y) { return (1.0 - 2.0 * (x * x + y * y)) * sin(x) / (3.0 + cos(y)) + c; },
        a, b);
  }
}

TEST(Dual, SeedsAndEigenScalar) {
  // variable() and AutoDiffScalar's (value, n, i) constructor seed unit vectors; constants
  // have zero derivatives; Eigen expressions mix Dual with double.
  for (int i = 0; i < kDirs; ++i) {
    const D z = D::variable(0.5 + i, i), w(0.5 + i, kDirs, i);
    EXPECT_EQ(z.value(), 0.5 + i);
    EXPECT_EQ(z.derivatives(), Vec::Unit(i));
    EXPECT_EQ(w.derivatives(), Vec::Unit(i));
    for (int j = kDirs; j < 4 * D::blocks; ++j) EXPECT_EQ(z.d[j / 4][j % 4], 0.0);
  }
  EXPECT_EQ(D(2.5).derivatives(), Vec::Zero());
  Eigen::Matrix<D, 2, 1> x(D::variable(1.0, 0), D::variable(2.0, 3));
  const Eigen::Matrix<D, 2, 1> y = x + 0.5 * x;
  EXPECT_EQ(y(0).value(), 1.5);
  EXPECT_EQ(y(1).derivatives(), 1.5 * Vec::Unit(3));
}

}  // namespace
}  // namespace mixpilot
