#include "core/control/tracking.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "core/numerics/dare.hpp"

namespace mixpilot {

// ---------------------------------------------------------------------------------------------
// Reference

OcpTrajectory helix_reference(const TrackingHelix& hx, double dt, const models::Crazyflie& model) {
  const int n = std::max(1, int(std::lround(hx.length / dt)));
  OcpTrajectory ref;
  ref.x.assign(std::size_t(n) + 1, Eigen::VectorXd::Zero(models::Crazyflie::nx));
  ref.u.assign(std::size_t(n), model.hover_input());
  const double cx = -hx.radius * std::cos(hx.phase), cy = -hx.radius * std::sin(hx.phase);
  for (int i = 0; i <= n; ++i) {
    const double t = i * dt, a = hx.phase + hx.angular_rate * t;
    Eigen::VectorXd& x = ref.x[std::size_t(i)];
    x.head<3>() << cx + hx.radius * std::cos(a), cy + hx.radius * std::sin(a),
        hx.start_height + hx.climb_rate * t;
    x(3) = 1.0;  // q = identity: body velocity = world velocity
    if (i < n) {
      x.segment<3>(7) << -hx.radius * hx.angular_rate * std::sin(a),
          hx.radius * hx.angular_rate * std::cos(a), hx.climb_rate;
    }
  }
  return ref;
}

// ---------------------------------------------------------------------------------------------
// LQR

Eigen::Matrix<double, 12, 1> TrackingLqr::q_diagonal() {
  Eigen::Matrix<double, 12, 1> q;
  q << 12.24e3, 10.2e3, 9e5,   // p
      0.102, 0.102, 0.102,     // q_x, q_y, q_z
      71.4, 102, 408,          // v_b
      1.02e-3, 1.02e-3, 1.02e3;  // ω
  return q;
}

Eigen::Matrix<double, 12, 1> TrackingLqr::reduce(const State& x) {
  Eigen::Matrix<double, 12, 1> z;
  z << x.head<3>(), x.segment<9>(4);
  return z;
}

SetupResult TrackingLqr::setup(const models::Crazyflie& model, double dt) {
  const IntegratorErk4<models::Crazyflie> erk4(model);
  const State xh = model.hover_state(Eigen::Vector3d::Zero());
  u_hover_ = model.hover_input();
  State xn;
  Eigen::Matrix<double, 13, 13> A13;
  Eigen::Matrix<double, 13, 4> B13;
  erk4.step(xh, u_hover_, dt, xn, A13, B13);
  // Rows and columns of q_w dropped: at hover ∂q_w/∂q_v = −q_v/q_w = 0.
  const int keep[12] = {0, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) A_(i, j) = A13(keep[i], keep[j]);
    B_.row(i) = B13.row(keep[i]);
  }
  const Eigen::MatrixXd Q = q_diagonal().asDiagonal();
  const Eigen::MatrixXd R = Eigen::MatrixXd::Identity(4, 4) * r_weight();
  Eigen::MatrixXd P;
  if (!solve_dare(A_, B_, Q, R, P))
    return SetupResult::failure("the LQR's Riccati equation did not converge");
  P_ = P;
  const Eigen::Matrix4d S = B_.transpose() * P_ * B_ + Eigen::Matrix4d::Identity() * r_weight();
  K_ = S.ldlt().solve(B_.transpose() * P_ * A_);
  const Mat12 res = A_.transpose() * P_ * A_ - P_ -
                    (A_.transpose() * P_ * B_) * S.ldlt().solve(B_.transpose() * P_ * A_) +
                    Mat12(Q);
  residual_ = res.lpNorm<Eigen::Infinity>() / P_.lpNorm<Eigen::Infinity>();
  u_min_ = model.p.omega_min;
  u_max_ = model.p.omega_max;
  return {};
}

void TrackingLqr::control(const State& x, const State& x_ref, const Input& u_ref, Input& u) const {
  u = u_ref - K_ * (reduce(x) - reduce(x_ref));
  u = u.cwiseMax(u_min_).cwiseMin(u_max_);
}

}  // namespace mixpilot
