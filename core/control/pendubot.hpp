#pragma once
// Pendubot swing-up controllers (SPEC §5.1, thesis ch. 4): the tracking NMPC's OCP and the LQR
// that balances at up-up. The offline swing-up reference is core/control/pendubot_reference.hpp;
// the closed loop with its switch rule, plant and sensor is core/modes/pendubot_mode.hpp.
//
// - NMPC (RTI, Δt = 2 ms, N = 10): y = (x, u), y_N = x, W = diag(3,3,1,1,5), W_N = diag(3,3,1,1),
//   |u| ≤ 0.4 N·m hard, (−7.8,−5) ≤ q̇ ≤ (7.8,5) rad/s soft with ℓ2² weight ρ = 40 per side. It
//   tracks the offline swing-up reference; past its end the reference is up-up, u = 0.
// - LQR: discrete, Δt = 2 ms, on the ERK4 linearization at up-up: u = −K x with angles wrapped,
//   P from the discrete Riccati equation (solve_dare, core/numerics/dare.hpp).
#include <Eigen/Core>

#include "core/nlp/ocp.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/numerics/types.hpp"
#include "models/pendubot.hpp"

namespace mixpilot {

// The tracking OCP of SPEC §5.1 (also the base of the offline reference OCP).
struct PendubotOcpSettings {
  int N = pendubot_defaults::kHorizon;
  double dt = pendubot_defaults::kDt;  // [s]
  double u_max = pendubot_defaults::kInputBound;  // [N·m]
  Eigen::Vector2d velocity_bound{pendubot_defaults::kVelocityBound1,
                                 pendubot_defaults::kVelocityBound2};  // [rad/s]
  bool soft_velocity_bounds = true;  // false: hard bounds (the offline reference)
  double slack_weight = pendubot_defaults::kSlackWeight;  // ρ, ℓ2² per side
  Eigen::Matrix<double, 5, 1> weights{3.0, 3.0, 1.0, 1.0, 5.0};  // W on (x, u)
  Eigen::Vector4d terminal_weights{3.0, 3.0, 1.0, 1.0};          // W_N on x
  // QP of the RTI: condensing suits N = 10 with one input (SPEC §4); the warm-started active set
  // confirms the previous step's active set in one or two factorizations (IPM as fallback).
  QpSolverKind qp_solver = QpSolverKind::condensed_active_set;
};

class PendubotSwingup {
 public:
  static constexpr int nx = models::Pendubot::nx;  // 4
  static constexpr int nu = models::Pendubot::nu;  // 1
  using State = models::Pendubot::State;

  explicit PendubotSwingup(const PendubotOcpSettings& settings = {},
                           const models::Pendubot& model = models::Pendubot{});
  PendubotSwingup(const PendubotSwingup&) = delete;  // ocp_ points into this object
  PendubotSwingup& operator=(const PendubotSwingup&) = delete;

  const Ocp& ocp() const { return ocp_; }
  const PendubotOcpSettings& settings() const { return settings_; }
  const models::Pendubot& model() const { return integrator_.model(); }
  const IntegratorErk4<models::Pendubot>& integrator() const { return integrator_; }

  // Stage i tracks (x_ref[k+i], u_ref[k+i]), clamped to the last entry, with W and W_N.
  // Allocates nothing: usable in the control loop.
  void set_reference(OcpStageData& data, const OcpTrajectory& ref, int k) const;
  // Every stage tracks (x, u) = 0 (up-up).
  void set_up_target(OcpStageData& data) const;
  // x_i = x, u_i = 0.
  static void constant_guess(OcpTrajectory& traj, const State& x);

 private:
  PendubotOcpSettings settings_;
  IntegratorErk4<models::Pendubot> integrator_;
  SelectionOutput output_;
  SelectionOutput terminal_output_;
  Ocp ocp_;
};

// Discrete LQR at up-up: u = −K x (angles wrapped).
struct PendubotLqr {
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();  // 4 x 4: ERK4 linearization ∂F/∂x at x = 0, u = 0
  Eigen::Vector4d B = Eigen::Vector4d::Zero();  // 4 x 1: ∂F/∂u there
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();  // 4 x 4: DARE solution
  Eigen::RowVector4d K = Eigen::RowVector4d::Zero();  // 1 x 4: (r + BᵀPB)⁻¹ BᵀPA
  bool converged = false;        // solve_dare converged (else P, K are zero)
  double spectral_radius = 0.0;  // of A − B K: < 1 when the LQR stabilizes the linearization
};

// P solves P = Q + AᵀPA − AᵀPB (r + BᵀPB)⁻¹ BᵀPA with Q = diag(q) (solve_dare); K from P.
PendubotLqr pendubot_lqr(const models::Pendubot& model, double dt, const Eigen::Vector4d& q,
                         double r);

// wrap to (−π, π].
double wrap_angle(double a);

}  // namespace mixpilot
