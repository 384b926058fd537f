#pragma once
// Mixed-initiative NMPC of SPEC §5.4 (thesis ch. 7) on the MikroKopter. The pilot's reference
// ν^r and the planner's η^r are blended inside the cost by the PH index λ ∈ (0, 1):
//   L = ½[(1−λ) Δηᵀ Q_η Δη + λ Δνᵀ Q_ν Δν + (1−λ) Δeᵀ Q_e Δe + (1−λ) uᵀ R u],
// η = p, ν = (φ, θ, Ω1..4), e = (ψ, v_b, ω) with reference 0; terminal cost without u.
// λ comes from the previous step's prediction (ph_index.hpp) and is held over the horizon;
// ν^r is held constant over the horizon (ZOH); η^r is the planner's trajectory sampled at the
// shooting nodes. Ω and τ are bounded (SPEC §3.3). A probe flight (settings.assist = off,
// SPEC §10) uses λ = 1 for η and ν (capped only by the pilot source's authority) whatever the
// PH index says, which is still computed from each prediction (ph_index()) but not applied; e
// and u keep the weight settings.probe_regularization · (Q_e, R), without which the QP is
// singular.
//
// Safety beyond the thesis (on by default): the ball B is only a soft working condition, so the
// nearest obstacles enter as lcl clearance constraints ‖p − o‖ ≥ r_o + r_vehicle and the arena
// walls and floor as bounds on p, all soft with an exact ℓ1 penalty.
#include <vector>

#include <Eigen/Core>

#include "core/numerics/integrator_erk4.hpp"
#include "core/control/obstacle_constraint.hpp"
#include "core/control/ph_index.hpp"
#include "core/nlp/ocp.hpp"
#include "core/control/pilot.hpp"
#include "core/nlp/rti.hpp"
#include "core/control/mi_settings.hpp"
#include "models/mikrokopter.hpp"

namespace mixpilot {

class MiController {
 public:
  static constexpr int nx = models::MikroKopter::nx;  // 16
  static constexpr int nu = models::MikroKopter::nu;  // 4
  static constexpr int ny = 20;                        // η (3), ν (6), e (7), u (4)

  // What the next step reads of the last one besides the RTI solver's state (rti().state()):
  // λ for the next step, and the last step's outputs (a snapshot of a flight copies it).
  struct Outputs {
    Eigen::VectorXd control;     // nu
    Eigen::VectorXd applied;     // nx: predicted state at stage 1
    Eigen::Matrix3Xd predicted;  // 3 x (N+1)
    Eigen::Matrix3Xd reference;  // 3 x (N+1)
    double lambda_next = 0.5;
    double lambda_used = 0.5;
    LambdaReason reason_next;  // this step's prediction read by the PH index (cap none)
    LambdaReason reason;       // what decided lambda_used
    AuthorityBounds bounds;    // the instructor's bounds on λ from the next step on
  };

  MiController() = default;
  MiController(const MiController&) = delete;  // the Ocp points into this object
  MiController& operator=(const MiController&) = delete;

  // Sizes everything. Fails with the reason if the settings do not describe a valid OCP.
  SetupResult setup(const models::MikroKopter& model, const MiControllerSettings& settings,
             const Arena& arena, const HelixReference& reference,
             const RtiSettings& rti_settings = {});

  // Initializes the trajectory at x (hover guess at its position); λ restarts at its initial
  // value until a prediction exists.
  void reset(const Eigen::VectorXd& x);

  // The instructor's bounds on λ (SPEC §10) from the next step on; kept by reset(). Valid
  // bounds only (AuthorityBounds::valid()).
  void set_bounds(const AuthorityBounds& bounds) { out_.bounds = bounds; }
  const AuthorityBounds& bounds() const { return out_.bounds; }

  // One control step at time t from the measured state x with the pilot's reference.
  // Allocates nothing. control() then holds τ to apply (never NaN).
  RtiStatus step(double t, const Eigen::VectorXd& x, const PilotCommand& pilot);

  const Eigen::VectorXd& control() const { return out_.control; }  // τ (nu)
  double lambda() const { return out_.lambda_used; }               // λ used in the last step
  // λ of the next step and what decides it, before it runs (SPEC §10): min(max(λ_PH, floor),
  // ceiling, cap), `cap` the pilot source's authority; λ_PH the last prediction's PH index (the
  // initial λ before any), 1 for a probe. step() flies with it; before the first step it is
  // what a trainee is told the flight starts with.
  struct NextLambda {
    double lambda = 0.0;
    LambdaReason reason;
  };
  NextLambda next_lambda(double cap = 1.0) const;
  // The PH index of the last step's prediction: λ for the next step when assisted (a probe
  // computes it and does not apply it).
  double ph_index() const { return out_.lambda_next; }
  // What decided λ in the last step (SPEC §10 "Why λ fell"): the previous step's d_res, i* and
  // direction, and the cap that held λ below the PH index (input lost, probe) if any.
  const LambdaReason& reason() const { return out_.reason; }
  bool assisted() const { return settings_.assist == Assistance::on; }
  // The MPC's own (φ, θ, Ω) at stage 1: what the pilot's command became.
  PilotCommand applied_command() const;
  // Predicted positions and planner reference at the nodes of the last step (3 x (N+1)).
  const Eigen::Matrix3Xd& predicted_positions() const { return out_.predicted; }
  const Eigen::Matrix3Xd& reference_positions() const { return out_.reference; }
  const RtiSolver& rti() const { return rti_; }
  RtiSolver& rti() { return rti_; }
  const models::MikroKopter& model() const { return model_; }
  const MiControllerSettings& settings() const { return settings_; }
  int constrained_obstacles() const { return num_obstacles_; }

  // The outputs and λ, and back (a controller set up alike: no allocation). The RTI solver's
  // state is rti().state() and rti().restore().
  const Outputs& outputs() const { return out_; }
  void restore(const Outputs& outputs) { out_ = outputs; }

 private:
  void set_stage_data(double t, const PilotCommand& pilot, const Eigen::VectorXd& x);

  models::MikroKopter model_{};
  IntegratorErk4<models::MikroKopter> integrator_{};
  MiControllerSettings settings_{};
  Arena arena_{};
  HelixReference helix_{};
  SelectionOutput output_;
  SelectionOutput terminal_output_;
  ObstacleConstraint obstacles_{0, ObstacleForm::lcl};
  Ocp ocp_;
  RtiSolver rti_;
  int num_obstacles_ = 0;

  Eigen::VectorXd weights_;           // ny: unscaled diagonal of W
  Outputs out_;
  Eigen::VectorXi nearest_;           // obstacle indices, by distance (scratch)
  Eigen::VectorXd distance_;          // per obstacle (scratch)
};

}  // namespace mixpilot
