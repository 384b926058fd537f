#include "core/control/delay_margin.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "core/control/crazyflie_tracking.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

double delayed_loop_spectral_radius(int delay, int N, double dt, int substeps) {
  const models::Crazyflie model{};
  const IntegratorErk4<models::Crazyflie> erk4(model);
  const int s = substeps;
  const double h = dt / s;
  const auto xh = model.hover_state(Eigen::Vector3d::Zero());
  const auto uh = model.hover_input();
  const int keep[12] = {0, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12};  // q_w dropped
  auto reduced = [&](double step, Eigen::MatrixXd& A, Eigen::MatrixXd& B) {
    models::Crazyflie::State xn;
    Eigen::Matrix<double, 13, 13> A13;
    Eigen::Matrix<double, 13, 4> B13;
    erk4.step(xh, uh, step, xn, A13, B13);
    A.resize(12, 12);
    B.resize(12, 4);
    for (int i = 0; i < 12; ++i) {
      for (int j = 0; j < 12; ++j) A(i, j) = A13(keep[i], keep[j]);
      B.row(i) = B13.row(keep[i]);
    }
  };
  Eigen::MatrixXd A, B, Ah, Bh;
  reduced(dt, A, B);
  reduced(h, Ah, Bh);
  const Eigen::VectorXd w = CrazyflieTracking::stage_weights();
  Eigen::VectorXd q(12);
  for (int i = 0; i < 12; ++i) q[i] = w[keep[i]];
  const Eigen::MatrixXd Q = q.asDiagonal(), R = w.tail(4).asDiagonal();
  Eigen::MatrixXd P = 50.0 * Q, K;
  for (int i = N - 1; i >= 0; --i) {  // K_0 of the N-stage Riccati recursion
    K = (R + B.transpose() * P * B).ldlt().solve(B.transpose() * P * A);
    P = Q + A.transpose() * P * (A - B * K);
    P = 0.5 * (P + P.transpose()).eval();
  }
  // The period map acts on (x_k, u_{k-1}, ..., u_{k-L}): the commands that still act during
  // period k.
  const int L = (delay + s - 1) / s, n = 12 + 4 * L;
  Eigen::MatrixXd M(n, n);
  for (int c = 0; c < n; ++c) {
    const Eigen::VectorXd z = Eigen::VectorXd::Unit(n, c);
    Eigen::VectorXd x = z.head(12);
    Eigen::MatrixXd u(4, L + 1);  // column a: u_{k-a}
    u.col(0) = -K * x;
    for (int a = 1; a <= L; ++a) u.col(a) = z.segment(12 + 4 * (a - 1), 4);
    for (int j = 0; j < s; ++j) {
      const int m = (j - delay) >= 0 ? 0 : -((delay - j + s - 1) / s);  // floor((j − delay)/s)
      x = (Ah * x + Bh * u.col(-m)).eval();
    }
    M.col(c).head(12) = x;
    for (int a = 0; a < L; ++a) M.col(c).segment(12 + 4 * a, 4) = u.col(a);
  }
  return M.eigenvalues().cwiseAbs().maxCoeff();
}

double linearized_delay_margin(int N, double dt, int substeps, int max_delay) {
  int margin = -1;  // the largest delay [substeps] with every smaller one stable
  for (int delay = 0; delay <= max_delay; ++delay) {
    if (delayed_loop_spectral_radius(delay, N, dt, substeps) >= 1.0) break;
    margin = delay;
  }
  return margin < 0 ? 0.0 : double(margin) * dt / substeps;
}

}  // namespace mixpilot
