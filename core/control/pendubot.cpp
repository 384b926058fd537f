#include "core/control/pendubot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "core/numerics/dare.hpp"

namespace mixpilot {

// ---------------------------------------------------------------------------------------------
// OCP (SPEC §5.1)

PendubotSwingup::PendubotSwingup(const PendubotOcpSettings& settings, const models::Pendubot& model)
    : settings_(settings),
      integrator_(model),
      output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi::LinSpaced(nu, 0, nu - 1)),
      terminal_output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi()) {
  ocp_.integrator = &integrator_;
  ocp_.N = settings.N;
  ocp_.dt = settings.dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::Zero(1);
  ocp_.lbu = Eigen::VectorXd::Constant(1, -settings.u_max);
  ocp_.ubu = Eigen::VectorXd::Constant(1, settings.u_max);
  ocp_.idxbx.resize(2);
  ocp_.idxbx << 2, 3;
  ocp_.lbx.resize(2);
  ocp_.lbx << -settings.velocity_bound(0), -settings.velocity_bound(1);
  ocp_.ubx.resize(2);
  ocp_.ubx << settings.velocity_bound(0), settings.velocity_bound(1);
  if (settings.soft_velocity_bounds) {
    for (int j = 0; j < 2; ++j) {
      SoftConstraint sc;
      sc.index = j;
      sc.Zl = sc.Zu = settings.slack_weight;
      ocp_.soft_state_bounds.push_back(sc);
    }
  }
}

void PendubotSwingup::set_reference(OcpStageData& data, const OcpTrajectory& ref, int k) const {
  const int last_u = int(ref.u.size()) - 1;
  const int last_x = int(ref.x.size()) - 1;
  const int N = ocp_.N;
  for (int i = 0; i < N; ++i) {
    const int j = k + i;
    data.yref[i].head<nx>() = ref.x[std::min(j, last_x)];
    data.yref[i](nx) = j <= last_u ? ref.u[j](0) : 0.0;  // past the end: hold up-up, u = 0
    data.W[i].diagonal() = settings_.weights;
  }
  data.yref[N] = ref.x[std::min(k + N, last_x)];
  data.W[N].diagonal() = settings_.terminal_weights;
}

void PendubotSwingup::set_up_target(OcpStageData& data) const {
  const int N = ocp_.N;
  for (int i = 0; i < N; ++i) {
    data.yref[i].setZero();
    data.W[i].diagonal() = settings_.weights;
  }
  data.yref[N].setZero();
  data.W[N].diagonal() = settings_.terminal_weights;
}

void PendubotSwingup::constant_guess(OcpTrajectory& traj, const State& x) {
  for (auto& xi : traj.x) xi = x;
  for (auto& ui : traj.u) ui.setZero();
}
// ---------------------------------------------------------------------------------------------
// LQR

double wrap_angle(double a) {
  constexpr double kPi = std::numbers::pi;
  a = std::remainder(a, 2.0 * kPi);  // [−π, π]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

PendubotLqr pendubot_lqr(const models::Pendubot& model, double dt, const Eigen::Vector4d& q,
                         double r) {
  PendubotLqr l;
  const IntegratorErk4<models::Pendubot> erk4(model);
  Eigen::Matrix<double, 4, 1> xn;
  Eigen::Matrix<double, 4, 4> A;
  Eigen::Matrix<double, 4, 1> B;
  erk4.step(models::Pendubot::up_up(), models::Pendubot::Input::Zero(), dt, xn, A, B);
  l.A = A;
  l.B = B;
  Eigen::MatrixXd P;
  const Eigen::Matrix4d Q = q.asDiagonal();
  l.converged = solve_dare(A, B, Q, Eigen::MatrixXd::Constant(1, 1, r), P);
  if (l.converged) {
    l.P = P;
    l.K = (B.transpose() * l.P * A) / (r + B.dot(l.P * B));
  }
  const Eigen::Matrix4d Acl = A - B * l.K;
  l.spectral_radius = Acl.eigenvalues().cwiseAbs().maxCoeff();
  return l;
}

}  // namespace mixpilot
