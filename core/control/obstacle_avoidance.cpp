#include "core/control/obstacle_avoidance.hpp"

#include <algorithm>

namespace mixpilot {

const char* to_string(ObstacleForm form) {
  return form == ObstacleForm::lcl ? "lcl" : "squared";
}

// ---------------------------------------------------------------------------------------------
// World

Eigen::Vector3d ThrownBall::position_at(double t) const {
  const double tau = std::max(0.0, t - throw_time);
  Eigen::Vector3d p = position + tau * velocity;
  p.z() -= 0.5 * gravity * tau * tau;
  return p;
}

Eigen::Vector3d ThrownBall::velocity_at(double t) const {
  if (t < throw_time) return Eigen::Vector3d::Zero();
  Eigen::Vector3d v = velocity;
  v.z() -= gravity * (t - throw_time);
  return v;
}

Eigen::Vector3d ObstacleWorld::position(int j, double t) const {
  const int ns = int(spheres.size());
  return j < ns ? spheres[j] : balls[j - ns].position_at(t);
}

Eigen::Vector3d ObstacleWorld::predict(int j, double t_now, double tau) const {
  const int ns = int(spheres.size());
  if (j < ns) return spheres[j];
  // From the ball's current state: at rest stays at rest; in flight, ballistic.
  const ThrownBall& b = balls[j - ns];
  const Eigen::Vector3d p = b.position_at(t_now);
  if (t_now < b.throw_time) return p;
  Eigen::Vector3d q = p + tau * b.velocity_at(t_now);
  q.z() -= 0.5 * b.gravity * tau * tau;
  return q;
}

// ---------------------------------------------------------------------------------------------
// OCP (SPEC §5.3)

ObstacleAvoidanceOcp::ObstacleAvoidanceOcp(int num_obstacles,
                                           const ObstacleControllerSettings& settings,
                                           const models::Crazyflie& model)
    : settings_(settings),
      num_obstacles_(num_obstacles),
      integrator_(model),
      output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi::LinSpaced(nu, 0, nu - 1)),
      terminal_output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi()),
      constraint_(num_obstacles, settings.form),
      stage_weights_(stage_weights()),
      terminal_weights_(terminal_weights()) {
  ocp_.integrator = &integrator_;
  ocp_.N = settings.N;
  ocp_.dt = settings.dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::LinSpaced(nu, 0, nu - 1);
  ocp_.lbu = Eigen::VectorXd::Constant(nu, model.p.omega_min);
  ocp_.ubu = Eigen::VectorXd::Constant(nu, model.p.omega_max);
  if (num_obstacles > 0) {
    // g_j ≥ 0 (lcl: ‖p − o‖ − d_C; squared: ‖p − o‖² − d_C²), no upper side (d_M = ∞).
    ocp_.np = ObstacleConstraint::kParamsPerObstacle * num_obstacles;
    ocp_.constraint = &constraint_;
    ocp_.lg = Eigen::VectorXd::Zero(num_obstacles);
    ocp_.ug = Eigen::VectorXd::Constant(num_obstacles, qp_defaults::kInfBound);
    for (int j = 0; j < num_obstacles; ++j) {
      ocp_.soft_constraints.push_back(SoftConstraint{j, settings.slack_l2, settings.slack_l2,
                                                     settings.slack_l1_lower,
                                                     settings.slack_l1_upper});
    }
  }
}

Eigen::VectorXd ObstacleAvoidanceOcp::stage_weights() {
  Eigen::VectorXd w(nx + nu);
  w << 30, 30, 60,                // p
      0.1, 0.1, 0.1, 0.1,         // q
      2, 3, 5,                    // v_b
      3, 3, 3,                    // ω
      0.05, 0.05, 0.05, 0.05;     // Ω
  return w;
}

Eigen::VectorXd ObstacleAvoidanceOcp::terminal_weights() { return stage_weights().head(nx); }

void ObstacleAvoidanceOcp::set_hover_target(OcpStageData& data,
                                            const Eigen::Vector3d& position) const {
  Eigen::VectorXd y(nx + nu);
  y << model().hover_state(position), model().hover_input();
  for (int i = 0; i < ocp_.N; ++i) {
    data.yref[i] = y;
    data.W[i] = stage_weights_.asDiagonal();
  }
  data.yref[ocp_.N] = y.head(nx);
  data.W[ocp_.N] = terminal_weights_.asDiagonal();
}

void ObstacleAvoidanceOcp::set_reference(OcpStageData& data, const OcpTrajectory& ref,
                                         int k) const {
  const int last_u = int(ref.u.size()) - 1;
  const int last_x = int(ref.x.size()) - 1;
  for (int i = 0; i < ocp_.N; ++i) {
    data.yref[i].head(nx) = ref.x[std::min(k + i, last_x)];
    // Past the end the reference hovers: its last input would be the last move's, not hover's.
    if (k + i <= last_u)
      data.yref[i].tail(nu) = ref.u[k + i];
    else
      data.yref[i].tail(nu) = model().hover_input();
    data.W[i].diagonal() = stage_weights_;
  }
  data.yref[ocp_.N] = ref.x[std::min(k + ocp_.N, last_x)];
  data.W[ocp_.N].diagonal() = terminal_weights_;
}

void ObstacleAvoidanceOcp::set_obstacles(OcpStageData& data, const ObstacleWorld& world,
                                         double t) const {
  constexpr int kP = ObstacleConstraint::kParamsPerObstacle;
  for (int i = 0; i <= ocp_.N; ++i) {
    for (int j = 0; j < num_obstacles_; ++j) {
      data.p[i].segment<3>(kP * j) = world.predict(j, t, i * ocp_.dt);
      data.p[i](kP * j + 3) = settings_.clearance;
    }
  }
}

void ObstacleAvoidanceOcp::hover_guess(OcpTrajectory& traj,
                                       const Eigen::Vector3d& position) const {
  for (auto& x : traj.x) x = model().hover_state(position);
  for (auto& u : traj.u) u = model().hover_input();
}

}  // namespace mixpilot
