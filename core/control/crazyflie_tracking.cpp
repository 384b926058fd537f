#include "core/control/crazyflie_tracking.hpp"

#include <algorithm>

namespace mixpilot {

CrazyflieTracking::CrazyflieTracking(int N, double dt, const models::Crazyflie& model)
    : integrator_(model),
      output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi::LinSpaced(nu, 0, nu - 1)),
      terminal_output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi()),
      stage_weights_(stage_weights()),
      terminal_weights_(terminal_weights()) {
  ocp_.integrator = &integrator_;
  ocp_.N = N;
  ocp_.dt = dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::LinSpaced(nu, 0, nu - 1);
  ocp_.lbu = Eigen::VectorXd::Constant(nu, model.p.omega_min);
  ocp_.ubu = Eigen::VectorXd::Constant(nu, model.p.omega_max);
}

Eigen::VectorXd CrazyflieTracking::stage_weights() {
  Eigen::VectorXd w(nx + nu);
  w << 120, 100, 100,           // p
      1e-3, 1e-3, 1e-3, 1e-3,   // q
      0.7, 1, 4,                // v_b
      1e-5, 1e-5, 10,           // ω
      6e-2, 6e-2, 6e-2, 6e-2;   // Ω
  return w;
}

Eigen::VectorXd CrazyflieTracking::terminal_weights() { return 50.0 * stage_weights().head(nx); }

void CrazyflieTracking::set_hover_target(OcpStageData& data, const Eigen::Vector3d& position) const {
  const Eigen::VectorXd& w = stage_weights_;
  const Eigen::VectorXd& wN = terminal_weights_;
  Eigen::VectorXd y(nx + nu);
  y << model().hover_state(position), model().hover_input();
  for (int i = 0; i < ocp_.N; ++i) {
    data.yref[i] = y;
    data.W[i] = w.asDiagonal();
  }
  data.yref[ocp_.N] = y.head(nx);
  data.W[ocp_.N] = wN.asDiagonal();
}

void CrazyflieTracking::set_reference(OcpStageData& data, const OcpTrajectory& ref, int k) const {
  const int last_u = int(ref.u.size()) - 1;
  const int last_x = int(ref.x.size()) - 1;
  for (int i = 0; i < ocp_.N; ++i) {
    data.yref[i].head(nx) = ref.x[std::min(k + i, last_x)];
    data.yref[i].tail(nu) = ref.u[std::min(k + i, last_u)];
    data.W[i].diagonal() = stage_weights_;
  }
  data.yref[ocp_.N] = ref.x[std::min(k + ocp_.N, last_x)];
  data.W[ocp_.N].diagonal() = terminal_weights_;
}

void CrazyflieTracking::hover_guess(OcpTrajectory& traj, const Eigen::Vector3d& position) const {
  for (auto& x : traj.x) x = model().hover_state(position);
  for (auto& u : traj.u) u = model().hover_input();
}

}  // namespace mixpilot
