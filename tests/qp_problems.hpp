#pragma once
// The OCP-QPs of the three controllers (SPEC §5.1, §5.2, §5.4) as the first RTI step poses them:
// dynamics linearized by ERK4 along the nominal trajectory started at the linearization point
// with constant input, variables are deviations (δx, δu) from it, Gauss-Newton cost of the
// controller's output weights around its reference, bounds shifted by the nominal trajectory.
// Shared by tests/test_qp.cpp (correctness) and tests/benchmarks/bench_qp.cpp (speed).
#include <cmath>
#include <numbers>

#include "core/numerics/integrator_erk4.hpp"
#include "core/qp/ocp_qp.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"

namespace mixpilot::testing_qp {

// Fills A, B, b of every stage from the nominal trajectory x̄_{i+1} = F(x̄_i, ū), x̄_0 = xbar;
// returns the trajectory. The QP's x0 is set to x_init − x̄_0.
template <class M>
std::vector<typename M::State> linearize(const M& model, OcpQp& qp, double dt,
                                         const typename M::State& xbar,
                                         const typename M::Input& ubar,
                                         const typename M::State& x_init) {
  const IntegratorErk4<M> erk4(model);
  const int N = qp.dims.N;
  std::vector<typename M::State> xs(static_cast<std::size_t>(N) + 1);
  xs[0] = xbar;
  typename IntegratorErk4<M>::MatA A;
  typename IntegratorErk4<M>::MatB B;
  for (int i = 0; i < N; ++i) {
    erk4.step(xs[i], ubar, dt, xs[i + 1], A, B);
    qp.stage[i].A = A;
    qp.stage[i].B = B;
    qp.stage[i].b.setZero();  // the nominal trajectory is consistent
  }
  qp.x0 = x_init - xbar;
  return xs;
}

// Cost ½(x − x_ref)ᵀQ(x − x_ref) + ½(u − u_ref)ᵀR(u − u_ref) in deviation variables.
template <class State, class Input>
void tracking_cost(OcpQpStage& s, const Eigen::VectorXd& qdiag, const Eigen::VectorXd& rdiag,
                   const State& xbar, const State& xref, const Input& ubar, const Input& uref,
                   bool has_input) {
  const Eigen::VectorXd dx = xbar - xref, du = ubar - uref;
  s.Q = qdiag.asDiagonal();
  s.q = qdiag.cwiseProduct(dx);
  if (has_input) {
    s.R = rdiag.asDiagonal();
    s.r = rdiag.cwiseProduct(du);
  }
}

// Mixed-initiative problem (SPEC §5.4) with λ = 0.5: MikroKopter, N = 50, Δt = 15 ms, τ bounds
// on u_0..u_{N−1}, Ω bounds on x_1..x_N. Planner reference η^r = (0, 0, 1), pilot reference
// ν^r = (0, 0, Ω_hover), the quadrotor starts 0.3 m off the reference and moving.
inline OcpQp mixed_initiative_qp(double lambda = 0.5) {
  const models::MikroKopter m;
  constexpr int N = 50, nx = 16, nu = 4;
  OcpQp qp(OcpQpDims::uniform(N, nx, nu, 4, 4));
  const auto xbar = m.hover_state({0.0, 0.0, 1.0});
  const auto ubar = m.hover_input();
  auto xinit = xbar;
  xinit.head<3>() += Eigen::Vector3d(0.25, -0.15, -0.1);
  xinit.segment<3>(6) = Eigen::Vector3d(0.4, 0.3, 0.2);  // v_b
  const auto xs = linearize(m, qp, 0.015, xbar, ubar, xinit);
  // State weights: (1−λ)Q_η on p, λQ_ν on (φ, θ, Ω), (1−λ)Q_e on (ψ, v_b, ω); (1−λ)R on τ.
  Eigen::VectorXd qd(nx);
  const double a = 1.0 - lambda, l = lambda;
  qd << a * 100, a * 100, a * 200,                 // p
      l * 800, l * 800, a * 10,                    // φ, θ (ν), ψ (e)
      a * 3, a * 3, a * 3, a * 3, a * 3, a * 10,   // v_b, ω (e)
      l * 800, l * 800, l * 800, l * 800;          // Ω (ν)
  const Eigen::VectorXd rd = Eigen::VectorXd::Constant(nu, a * 70);
  const auto xref = m.hover_state({0.0, 0.0, 1.0});  // η^r, ν^r = (0, 0, Ω_h), e^r = 0
  const models::MikroKopter::Input uref = models::MikroKopter::Input::Zero();  // uᵀRu
  for (int i = 0; i <= N; ++i) {
    OcpQpStage& s = qp.stage[i];
    tracking_cost(s, qd, rd, xs[i], xref, ubar, uref, i < N);
    if (i < N)
      for (int k = 0; k < nu; ++k) {
        s.idxbu[k] = k;
        s.lbu[k] = m.p.tau_min - ubar[k];
        s.ubu[k] = m.p.tau_max - ubar[k];
      }
    if (i > 0)
      for (int k = 0; k < 4; ++k) {
        s.idxbx[k] = 12 + k;
        s.lbx[k] = m.p.omega_min - xs[i][12 + k];
        s.ubx[k] = m.p.omega_max - xs[i][12 + k];
      }
  }
  return qp;
}

// Crazyflie position step (SPEC §5.2): hover at (0, 0, 0.4) towards (1, −1, 1); N = 50,
// Δt = 15 ms, 0 ≤ Ω ≤ 22 krpm on u_0..u_{N−1}.
inline OcpQp crazyflie_qp() {
  const models::Crazyflie m;
  constexpr int N = 50, nx = 13, nu = 4;
  OcpQp qp(OcpQpDims::uniform(N, nx, nu, 0, 4));
  const auto xbar = m.hover_state({0.0, 0.0, 0.4});
  const auto ubar = m.hover_input();
  const auto xs = linearize(m, qp, 0.015, xbar, ubar, xbar);
  // W = blkdiag(120, 100·I2, 1e-3·I4, 0.7, 1, 4, 1e-5·I2, 10, 6e-2·I4) over (p, q, v_b, ω, u).
  Eigen::VectorXd qd(nx), rd(nu);
  qd << 120, 100, 100, 1e-3, 1e-3, 1e-3, 1e-3, 0.7, 1, 4, 1e-5, 1e-5, 10;
  rd.setConstant(6e-2);
  const auto xref = m.hover_state({1.0, -1.0, 1.0});
  for (int i = 0; i <= N; ++i) {
    OcpQpStage& s = qp.stage[i];
    const Eigen::VectorXd w = i < N ? qd : Eigen::VectorXd(50.0 * qd);  // W_N = 50·W_ξ
    tracking_cost(s, w, rd, xs[i], xref, ubar, ubar, i < N);
    if (i < N)
      for (int k = 0; k < nu; ++k) {
        s.idxbu[k] = k;
        s.lbu[k] = m.p.omega_min - ubar[k];
        s.ubu[k] = m.p.omega_max - ubar[k];
      }
  }
  return qp;
}

// Pendubot swing-up (SPEC §5.1): N = 10, Δt = 2 ms, |u| ≤ 0.4 on u_0..u_{N−1}, soft joint-velocity
// bounds (−7.8, −5) ≤ q̇ ≤ (7.8, 5) with ℓ2² weight ρ = 40 per side on x_1..x_N. Linearized
// mid-swing, where the second joint's speed is at its bound and the input saturates.
inline OcpQp pendubot_qp() {
  const models::Pendubot m;
  constexpr int N = 10, nx = 4, nu = 1;
  OcpQp qp(OcpQpDims::uniform(N, nx, nu, 2, 1, 0, 0));
  for (int i = 1; i <= N; ++i) qp.dims.ns[i] = 2;
  qp.resize(qp.dims);
  const models::Pendubot::State xbar(-1.2, 0.9, 7.2, -4.9);
  const models::Pendubot::Input ubar(0.3);
  const auto xs = linearize(m, qp, 0.002, xbar, ubar, xbar);
  Eigen::VectorXd qd(nx), rd(nu);
  qd << 3, 3, 1, 1;
  rd << 5;
  const models::Pendubot::State xref = models::Pendubot::up_up();
  const models::Pendubot::Input uref = models::Pendubot::Input::Zero();
  for (int i = 0; i <= N; ++i) {
    OcpQpStage& s = qp.stage[i];
    tracking_cost(s, qd, rd, xs[i], xref, ubar, uref, i < N);
    if (i < N) {
      s.idxbu[0] = 0;
      s.lbu[0] = -m.p.u_max - ubar[0];
      s.ubu[0] = m.p.u_max - ubar[0];
    }
    if (i > 0) {
      const double vmax[2] = {7.8, 5.0};
      for (int k = 0; k < 2; ++k) {
        s.idxbx[k] = 2 + k;
        s.lbx[k] = -vmax[k] - xs[i][2 + k];
        s.ubx[k] = vmax[k] - xs[i][2 + k];
        s.idxs[k] = qp.dims.nbu[i] + k;  // constraints [bu; bx]
        s.Zl[k] = s.Zu[k] = 40.0;
        s.zl[k] = s.zu[k] = 0.0;
      }
    }
  }
  return qp;
}

}  // namespace mixpilot::testing_qp
