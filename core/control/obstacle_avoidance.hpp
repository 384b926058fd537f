#pragma once
// Obstacle avoidance with the LCL constraint, SPEC §5.3 (thesis ch. 6): the controller's world
// model and its OCP.
//
// OCP (ObstacleAvoidanceOcp): Crazyflie, Δt = 15 ms, N = 50, y = (ξ − ξʳ, u − uʳ) with
//   W = blkdiag(30·I2, 60, 0.1·I4, 2, 3, 5, 3·I3, 0.05·I4), W_N = W without the input block,
//   0 ≤ Ω ≤ 22 krpm, and per obstacle j and stage i = 1..N (x_0 is fixed) the soft clearance
//   ‖p_i − o_{j,i}‖ + ε ≥ d_C (lcl) or ‖p_i − o_{j,i}‖² + ε ≥ d_C² (squared), ε ≥ 0 with
//   ℓ1 weight 14.5e3 (core/control/obstacle_constraint.hpp). Each obstacle's centre is a per-stage
//   parameter, so a moving obstacle is its predicted position at each shooting node.
// World (ObstacleWorld): static spheres and thrown balls. A ball rests at its initial
// position until its throw time, then flies ballistically (exact, no drag). The controller
// predicts each ball from its current state: ballistic once thrown, at rest before (it does
// not know when the ball will be thrown).
// The closed loop is core/modes/obstacle_mode.hpp; the scenario file core/scenario/
// obstacle_scenario.hpp.
#include <vector>

#include <Eigen/Core>

#include "core/control/obstacle_constraint.hpp"
#include "core/nlp/ocp.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/numerics/types.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

const char* to_string(ObstacleForm form);

struct ThrownBall {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // at rest here until throw_time [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // at the throw [m/s]
  double throw_time = 0.0;                             // [s]
  double gravity = obstacle_defaults::kGravity;        // [m/s²] along −z

  // Exact position and velocity at time t.
  Eigen::Vector3d position_at(double t) const;
  Eigen::Vector3d velocity_at(double t) const;
};

struct ObstacleWorld {
  std::vector<Eigen::Vector3d> spheres;  // static obstacle centres [m]
  std::vector<ThrownBall> balls;

  int size() const { return int(spheres.size() + balls.size()); }
  // Obstacle j (spheres first, then balls) at time t.
  Eigen::Vector3d position(int j, double t) const;
  // The controller's prediction of obstacle j at t_now + tau from its state at t_now.
  Eigen::Vector3d predict(int j, double t_now, double tau) const;
};

struct ObstacleControllerSettings {
  int N = obstacle_defaults::kHorizon;
  double dt = obstacle_defaults::kDt;
  ObstacleForm form = ObstacleForm::lcl;
  double clearance = obstacle_defaults::kClearance;  // d_C [m]
  double slack_l1_lower = obstacle_defaults::kSlackL1Lower;
  double slack_l1_upper = obstacle_defaults::kSlackL1Upper;
  double slack_l2 = obstacle_defaults::kSlackL2;
};

// The OCP of SPEC §5.3 with `num_obstacles` soft clearance constraints (0: the obstacle-free
// reference problem). Owns what its Ocp points to.
class ObstacleAvoidanceOcp {
 public:
  static constexpr int nx = models::Crazyflie::nx;  // 13
  static constexpr int nu = models::Crazyflie::nu;  // 4

  ObstacleAvoidanceOcp(int num_obstacles, const ObstacleControllerSettings& settings = {},
                       const models::Crazyflie& model = models::Crazyflie{});
  ObstacleAvoidanceOcp(const ObstacleAvoidanceOcp&) = delete;  // ocp_ points into this object
  ObstacleAvoidanceOcp& operator=(const ObstacleAvoidanceOcp&) = delete;

  const Ocp& ocp() const { return ocp_; }
  const models::Crazyflie& model() const { return integrator_.model(); }
  const IntegratorErk4<models::Crazyflie>& integrator() const { return integrator_; }
  const ObstacleControllerSettings& settings() const { return settings_; }
  int num_obstacles() const { return num_obstacles_; }

  // SPEC §5.3 weights: w (17) for stages 0..N−1, w_N (13).
  static Eigen::VectorXd stage_weights();
  static Eigen::VectorXd terminal_weights();

  // Every stage tracks the hover at `position` (the reference problem).
  void set_hover_target(OcpStageData& data, const Eigen::Vector3d& position) const;
  // Stage i tracks (x_ref[k+i], u_ref[k+i]), clamped to the last entry. No allocation.
  void set_reference(OcpStageData& data, const OcpTrajectory& ref, int k) const;
  // Stage i holds each obstacle's predicted centre at t + i·Δt and d_C. No allocation.
  void set_obstacles(OcpStageData& data, const ObstacleWorld& world, double t) const;
  void hover_guess(OcpTrajectory& traj, const Eigen::Vector3d& position) const;

 private:
  ObstacleControllerSettings settings_;
  int num_obstacles_;
  IntegratorErk4<models::Crazyflie> integrator_;
  SelectionOutput output_;           // y = (x, u): 17 selected entries
  SelectionOutput terminal_output_;  // y_N = x: 13 selected entries
  ObstacleConstraint constraint_;
  Ocp ocp_;
  Eigen::VectorXd stage_weights_;     // nx + nu: diagonal of W
  Eigen::VectorXd terminal_weights_;  // nx: diagonal of W_N
};

}  // namespace mixpilot
