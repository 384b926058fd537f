// Models of SPEC §3: hover equilibria, energy conservation, continuous Jacobians vs FD.
#include <gtest/gtest.h>

#include <random>

#include "core/integrator_erk4.hpp"
#include "models/crazyflie.hpp"
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
  // SPEC §3.1: the shoulder holds the arm horizontal with ≈0.378 N·m, so swing-up must pump.
  const Pendubot pb;
  const double peak = (pb.p.m1 * pb.p.a1 + pb.p.m2 * pb.p.l1 + pb.p.m2 * pb.p.a2) * pb.p.g;
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
  for (int k = 0; k < 10000; ++k) {
    Pendubot::State xn;
    erk4.step(x, Pendubot::Input(Pendubot::Input::Zero()), 1e-3, xn);
    x = xn;
    worst = std::max(worst, std::abs(pb.energy(x) - e0) / e0);
  }
  EXPECT_LT(worst, 1e-6);
  // The motion really was large: the energy is well above hanging still.
  EXPECT_GT(e0, 0.1);
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

}  // namespace
}  // namespace mixpilot
