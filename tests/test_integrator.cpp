// ERK4 (core/numerics/integrator_erk4.hpp): convergence order, sensitivities vs finite differences,
// quaternion norm, and agreement of the fixed-size and the virtual interfaces.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/numerics/integrator_erk4.hpp"
#include "core/numerics/matrix_checks.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"
#include "tests/random_states.hpp"

namespace mixpilot {
namespace {

using models::Crazyflie;
using models::MikroKopter;
using models::Pendubot;

template <class M>
typename M::State simulate(const IntegratorErk4<M>& erk4, typename M::State x,
                           const typename M::Input& u, double t_end, int steps) {
  const double dt = t_end / steps;
  for (int k = 0; k < steps; ++k) {
    typename M::State xn;
    erk4.step(x, u, dt, xn);
    x = xn;
  }
  return x;
}

// Global error at t_end for Δt = h, h/2, h/4 against a Δt = h/256 reference: a fourth-order
// method's error falls by 2⁴ = 16 per halving.
template <class M>
void expect_fourth_order(const M& model, const typename M::Input& u, int seed, double t_end,
                         int steps) {
  std::mt19937 rng(seed);
  const IntegratorErk4<M> erk4(model);
  const typename M::State x0 = testing_states::random_state(model, rng);
  const typename M::State ref = simulate(erk4, x0, u, t_end, steps * 256);
  double err[3];
  for (int k = 0; k < 3; ++k) {
    err[k] = (simulate(erk4, x0, u, t_end, steps << k) - ref).norm();
  }
  ASSERT_GT(err[2], 1e-11) << "errors too small to measure the order";
  for (int k = 0; k < 2; ++k) {
    const double ratio = err[k] / err[k + 1];
    EXPECT_NEAR(ratio, 16.0, 1.6) << M::name << " halving " << k << ": " << err[k] << " -> "
                                  << err[k + 1];
  }
}

TEST(Erk4, FourthOrderPendubot) {
  expect_fourth_order(Pendubot{}, Pendubot::Input(0.2), 11, 1.0, 200);
}
TEST(Erk4, FourthOrderCrazyflie) {
  std::mt19937 rng(12);
  const Crazyflie cf;
  expect_fourth_order(cf, testing_states::near_hover_input(cf, rng, 0.5), 12, 0.5, 25);
}
TEST(Erk4, FourthOrderMikroKopter) {
  std::mt19937 rng(13);
  const MikroKopter mk;
  expect_fourth_order(mk, testing_states::near_hover_input(mk, rng, 0.01), 13, 1.0, 50);
}

// A = ∂F/∂x and B = ∂F/∂u of one step against central differences of F, at the controllers'
// step sizes (Pendubot 2 ms, quadrotors 15 ms).
template <class M>
void expect_sensitivities_match_fd(const M& model, int seed, double dt) {
  std::mt19937 rng(seed);
  const IntegratorErk4<M> erk4(model);
  for (int trial = 0; trial < 20; ++trial) {
    const typename M::State x = testing_states::random_state(model, rng);
    const typename M::Input u = testing_states::random_input(model, rng);
    typename M::State xn, xn_plain;
    typename IntegratorErk4<M>::MatA A, A_fd;
    typename IntegratorErk4<M>::MatB B, B_fd;
    erk4.step(x, u, dt, xn, A, B);
    erk4.step(x, u, dt, xn_plain);
    EXPECT_LT((xn - xn_plain).norm(), 1e-14 * xn.norm());

    for (int j = 0; j < M::nx; ++j) {
      const double h = 1e-5 * std::max(1.0, std::abs(x(j)));
      typename M::State xp = x, xm = x, fp, fm;
      xp(j) += h;
      xm(j) -= h;
      erk4.step(xp, u, dt, fp);
      erk4.step(xm, u, dt, fm);
      A_fd.col(j) = (fp - fm) / (2.0 * h);
    }
    for (int j = 0; j < M::nu; ++j) {
      const double h = 1e-5 * std::max(1.0, std::abs(u(j)));
      typename M::Input up = u, um = u;
      typename M::State fp, fm;
      up(j) += h;
      um(j) -= h;
      erk4.step(x, up, dt, fp);
      erk4.step(x, um, dt, fm);
      B_fd.col(j) = (fp - fm) / (2.0 * h);
    }
    EXPECT_LE((A - A_fd).norm(), 1e-6 * A.norm()) << M::name << " trial " << trial;
    EXPECT_LE((B - B_fd).norm(), 1e-6 * B.norm()) << M::name << " trial " << trial;
  }
}

TEST(Erk4, SensitivitiesPendubot) { expect_sensitivities_match_fd(Pendubot{}, 21, 0.002); }
TEST(Erk4, SensitivitiesCrazyflie) { expect_sensitivities_match_fd(Crazyflie{}, 22, 0.015); }
TEST(Erk4, SensitivitiesMikroKopter) { expect_sensitivities_match_fd(MikroKopter{}, 23, 0.015); }

TEST(Erk4, QuaternionNormKeptOverOneStep) {
  // Plain ERK4 drifts by up to ~1e-8 here; the model's projection holds ‖q‖ to rounding.
  // Inputs span the whole box, so the rates change by hundreds of rad/s within the step.
  const Crazyflie cf;
  const IntegratorErk4<Crazyflie> erk4(cf);
  std::mt19937 rng(31);
  for (int trial = 0; trial < 1000; ++trial) {
    const Crazyflie::State x = testing_states::random_state(cf, rng);
    ASSERT_NEAR(x.segment<4>(3).norm(), 1.0, 1e-15);
    Crazyflie::State xn;
    erk4.step(x, testing_states::random_input(cf, rng), 0.015, xn);
    EXPECT_NEAR(xn.segment<4>(3).norm(), 1.0, 1e-9);
  }
}

TEST(Erk4, VirtualInterfaceMatchesFixedSize) {
  const MikroKopter mk;
  const IntegratorErk4<MikroKopter> erk4(mk);
  const Integrator& integ = erk4;
  std::mt19937 rng(41);
  const MikroKopter::State x = testing_states::random_state(mk, rng);
  const MikroKopter::Input u = testing_states::random_input(mk, rng);
  MikroKopter::State xn;
  IntegratorErk4<MikroKopter>::MatA A;
  IntegratorErk4<MikroKopter>::MatB B;
  erk4.step(x, u, 0.015, xn, A, B);

  Eigen::VectorXd xd(16);
  Eigen::MatrixXd Ad(16, 16), Bd(16, 4);
  ASSERT_EQ(integ.nx(), 16);
  ASSERT_EQ(integ.nu(), 4);
  EXPECT_EQ(integ.step_sensitivities(x, u, 0.015, xd, Ad, Bd), IntegratorStatus::success);
  EXPECT_EQ(xd, Eigen::VectorXd(xn));
  EXPECT_EQ(Ad, Eigen::MatrixXd(A));
  EXPECT_EQ(Bd, Eigen::MatrixXd(B));
}

TEST(Erk4, NonFiniteInputIsReported) {
  const IntegratorErk4<Crazyflie> erk4;
  Eigen::VectorXd x = Crazyflie{}.hover_state({0, 0, 1});
  Eigen::VectorXd u = Crazyflie{}.hover_input();
  u(2) = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd xn(13);
  Eigen::MatrixXd A(13, 13), B(13, 4);
  EXPECT_EQ(erk4.step(x, u, 0.015, xn), IntegratorStatus::non_finite);
  EXPECT_EQ(erk4.step_sensitivities(x, u, 0.015, xn, A, B), IntegratorStatus::non_finite);
}

// The whole-matrix checks (core/numerics/matrix_checks.hpp) on every kind of entry, at each
// position: ±0 passes, a subnormal, ±inf or NaN anywhere counts; the diagonal is not looked at
// by is_diagonal, and entries outside the n x n block of a larger leading dimension are ignored.
TEST(MatrixChecks, EveryEntryKindAtEveryPosition) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const int n : {1, 3, 4, 5, 8, 11, 16}) {  // whole blocks of 4 rows, and tails
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 2, n);  // leading dimension n + 2
    m.topRows(n).diagonal().setLinSpaced(n, 1.0, 2.0);
    m(n, 0) = nan;  // outside the n x n block
    const auto diagonal = [&] { return is_diagonal(m.data(), n, n + 2); };
    EXPECT_TRUE(diagonal());
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c)
        for (const double v : {-0.0, tiny, -1.0, inf, -inf, nan}) {
          const double kept = m(r, c);
          m(r, c) = v;
          const bool expected = r == c || v == 0.0;
          EXPECT_EQ(diagonal(), expected) << n << " x " << n << " (" << r << ", " << c << ") = " << v;
          m(r, c) = kept;
        }
    Eigen::MatrixXd z = Eigen::MatrixXd::Zero(n, n + 1);
    EXPECT_TRUE(is_zero(z) && all_finite(z));
    for (Eigen::Index k = 0; k < z.size(); ++k)
      for (const double v : {-0.0, tiny, -1.0, inf, -inf, nan}) {
        z.data()[k] = v;
        EXPECT_EQ(is_zero(z), v == 0.0) << k << " = " << v;
        EXPECT_EQ(all_finite(z), std::isfinite(v)) << k << " = " << v;
        z.data()[k] = 0.0;
      }
  }
}

}  // namespace
}  // namespace mixpilot
