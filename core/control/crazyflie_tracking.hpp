#pragma once
// The Crazyflie position-tracking OCP of SPEC §5.2: Δt = 15 ms, y = (ξ, u), y_N = ξ,
// W = blkdiag(120, 100·I2, 1e-3·I4, 0.7, 1, 4, 1e-5·I2, 10, 6e-2·I4), W_N = 50·W[0:13],
// 0 ≤ Ω ≤ 22 krpm. Owns the integrator and outputs the Ocp points to.
#include <Eigen/Core>

#include "core/numerics/integrator_erk4.hpp"
#include "core/nlp/ocp.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

class CrazyflieTracking {
 public:
  static constexpr int nx = models::Crazyflie::nx;  // 13
  static constexpr int nu = models::Crazyflie::nu;  // 4

  explicit CrazyflieTracking(int N = 50, double dt = 0.015,
                             const models::Crazyflie& model = models::Crazyflie{});
  CrazyflieTracking(const CrazyflieTracking&) = delete;  // ocp_ points into this object
  CrazyflieTracking& operator=(const CrazyflieTracking&) = delete;

  const Ocp& ocp() const { return ocp_; }
  const models::Crazyflie& model() const { return integrator_.model(); }
  const IntegratorErk4<models::Crazyflie>& integrator() const { return integrator_; }

  // Stage weights of SPEC §5.2: w (17) for stages 0..N−1, w_N (13).
  static Eigen::VectorXd stage_weights();
  static Eigen::VectorXd terminal_weights();

  // Every stage tracks the hover at `position` (ỹ = (hover state, hover input)).
  void set_hover_target(OcpStageData& data, const Eigen::Vector3d& position) const;
  // Stage i tracks (x_ref[k+i], u_ref[k+i]), clamped to the last entry (x_ref has one more
  // entry than u_ref: a trajectory of the same OCP), with the SPEC §5.2 weights. Allocates
  // nothing: usable in the control loop.
  void set_reference(OcpStageData& data, const OcpTrajectory& ref, int k) const;

  // x_i = hover at `position`, u_i = hover input: the usual initial guess.
  void hover_guess(OcpTrajectory& traj, const Eigen::Vector3d& position) const;

 private:
  IntegratorErk4<models::Crazyflie> integrator_;
  SelectionOutput output_;
  SelectionOutput terminal_output_;
  Ocp ocp_;
  Eigen::VectorXd stage_weights_;     // nx + nu
  Eigen::VectorXd terminal_weights_;  // nx
};

}  // namespace mixpilot
