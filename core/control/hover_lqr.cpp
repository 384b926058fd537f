#include "core/control/hover_lqr.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "core/numerics/dare.hpp"
#include "core/numerics/integrator_erk4.hpp"

namespace mixpilot {

namespace {
// Weights on the states the λ = 0 cost leaves free (φ, θ, Ω): small against Q_η and Q_e, enough
// for a unique, stabilizing solution of the Riccati equation.
constexpr double kTiltWeight = 1.0;
constexpr double kRotorWeight = 1e-2;
}  // namespace

SetupResult HoverLqr::setup(const Model& model, const MiWeights& w, double dt) {
  const IntegratorErk4<Model> erk4(model);
  x_hover_ = model.hover_state(Eigen::Vector3d::Zero());
  u_hover_ = model.hover_input();
  State xn;
  Eigen::Matrix<double, nx, nx> A;
  Eigen::Matrix<double, nx, nu> B;
  erk4.step(x_hover_, u_hover_, dt, xn, A, B);
  // x = (p, φ θ ψ, v_b, ω, Ω).
  Eigen::Matrix<double, nx, 1> q;
  q << w.q_eta, kTiltWeight, kTiltWeight, w.q_e(0), w.q_e.tail<6>(),
      Eigen::Vector4d::Constant(kRotorWeight);
  const Eigen::MatrixXd Q = q.asDiagonal();
  const Eigen::MatrixXd R = Eigen::MatrixXd::Identity(nu, nu) * w.r;
  Eigen::MatrixXd P;
  if (!solve_dare(A, B, Q, R, P))
    return SetupResult::failure("the hover LQR's Riccati equation did not converge");
  const Eigen::Matrix<double, nu, nu> S = B.transpose() * P * B + R;
  K_ = S.ldlt().solve(B.transpose() * P * A);
  const Eigen::Matrix<double, nx, nx> closed = A - B * K_;
  spectral_radius_ = closed.eigenvalues().cwiseAbs().maxCoeff();
  u_min_ = model.p.tau_min;
  u_max_ = model.p.tau_max;
  return {};
}

void HoverLqr::control(const State& x, const Eigen::Vector3d& position, Input& u) const {
  State e = x - x_hover_;
  e.head<3>() -= position;
  e(5) = std::remainder(e(5), 2.0 * std::numbers::pi);  // yaw, the shorter way round
  u = u_hover_ - K_ * e;
  u = u.cwiseMax(u_min_).cwiseMin(u_max_);
}

}  // namespace mixpilot
