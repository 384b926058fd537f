#pragma once
// Pendubot swing-up (SPEC §5.1, thesis ch. 4, issue 6): from down-down to up-up and balance.
//
// - NMPC (RTI, Δt = 2 ms, N = 10): y = (x, u), y_N = x, W = diag(3,3,1,1,5), W_N = diag(3,3,1,1),
//   |u| ≤ 0.4 N·m hard, (−7.8,−5) ≤ q̇ ≤ (7.8,5) rad/s soft with ℓ2² weight ρ = 40 per side. It
//   tracks an offline swing-up reference (Ipopt, compute_pendubot_reference(), committed as
//   scenarios/references/pendubot_swingup.csv); past its end the reference is up-up, u = 0.
// - LQR: discrete, Δt = 2 ms, on the ERK4 linearization at up-up (DARE by Riccati iteration).
//   Switch rule (hysteresis), evaluated every control step on the measured state x̂ with
//   wrapped angles: NMPC → LQR when ‖wrap(q̂)‖ ≤ enter_angle, ‖q̂̇‖ ≤ enter_velocity and the
//   LQR input |K x̂| ≤ u_max (unsaturated: inside the LQR's linear region); LQR → NMPC when
//   ‖wrap(q̂)‖ > exit_angle (> enter_angle), the NMPC then restarting from x̂ towards up-up.
// - Plant: the same model, RK4 at `rate_hz` (default 4 kHz: 0.25 ms substeps), input held over Δt.
// - Sensor: exact state, or encoders (q1: 1/8192 turn, q2: 1/4096 turn) with velocities from
//   differenced quantized angles through a first-order low-pass, or from a model-based α-β
//   observer driven by the quantized angles.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "core/numerics/integrator_erk4.hpp"
#include "core/modes/mode.hpp"
#include "core/nlp/nlp_ipopt.hpp"
#include "core/nlp/ocp.hpp"
#include "core/nlp/trajectory_io.hpp"
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

// ---------------------------------------------------------------------------------------------
// Offline swing-up reference (Ipopt). Down-down → up-up over T = N·dt with |u| ≤ u_max and hard
// velocity bounds, both tightened from SPEC §5.1's so the tracking NMPC keeps authority and
// margin; cost ½Σ (wq‖q‖² + wv‖q̇‖² + r u²) + ½ w_N (‖q_N‖² + 0.1‖q̇_N‖²). Solved twice: first on
// a grid coarse_factor times coarser from the guess q1: −π → 0 linearly, u = 0 (the energy-
// pumping rollout is a worse start: its link 2 tumbles and Ipopt ends in a spinning local
// minimum), then on the 2 ms grid from the coarse solution (inputs held, states interpolated).
struct PendubotReferenceSettings {
  int N = 1250;                        // intervals (T = 2.5 s)
  double dt = pendubot_defaults::kDt;  // [s]
  int coarse_factor = 10;              // ≤ 1: solve the fine grid directly
  double u_max = 0.36;                 // 90 % of the 0.4 N·m bound [N·m]
  Eigen::Vector2d velocity_bound{7.0, 4.5};  // 90 % of (7.8, 5) [rad/s]
  double angle_weight = 1.0;
  double velocity_weight = 0.01;
  double input_weight = 1.0;
  double terminal_weight = 1e4;
  // Initial guess: 0 = the linear guess above, 1 = the energy-pumping rollout.
  int guess = 0;
  IpoptOcpSettings ipopt{1e-8, 3000, 0};
};

struct PendubotReferenceResult {
  IpoptOcpResult coarse;  // the coarse-grid solve (iterations 0 when skipped)
  IpoptOcpResult ipopt;   // the 2 ms solve
  OcpTrajectory trajectory;
  double max_abs_u = 0.0;
  Eigen::Vector2d max_abs_velocity = Eigen::Vector2d::Zero();
  double final_error = 0.0;  // ‖x_N‖∞
};

// The energy-pumping rollout used as initial guess: u = sat(k_E (E − E_top) q̇1 − k_p q2 −
// k_d q̇2), ERK4 at dt, N intervals from down-down.
void pendubot_energy_guess(const models::Pendubot& model, double dt, int N, double u_max,
                           OcpTrajectory& traj);

PendubotReferenceResult compute_pendubot_reference(const PendubotReferenceSettings& settings,
                                                   const models::Pendubot& model = {});

// ---------------------------------------------------------------------------------------------
// Discrete LQR at up-up: u = −K x (angles wrapped).
struct PendubotLqr {
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();  // ERK4 linearization at x = 0, u = 0
  Eigen::Vector4d B = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();  // DARE solution
  Eigen::RowVector4d K = Eigen::RowVector4d::Zero();
  int iterations = 0;
  bool converged = false;
  double spectral_radius = 0.0;  // of A − B K
};

// Solves P = Q + AᵀPA − AᵀPB (R + BᵀPB)⁻¹ BᵀPA by iterating the Riccati difference equation
// from P = Q until the relative change is ≤ 1e-13 (at most max_iterations).
PendubotLqr pendubot_lqr(const models::Pendubot& model, double dt, const Eigen::Vector4d& q,
                         double r, int max_iterations = 200000);

// ---------------------------------------------------------------------------------------------
// Scenario (docs/scenario-format.md, "Pendubot swing-up").
struct PendubotScenario {
  std::string name;
  std::string source_path;
  double duration = 8.0;  // [s]
  double angle_tolerance = pendubot_defaults::kAngleTolerance;  // [rad]

  PendubotOcpSettings controller{};
  std::string reference_path;   // as written (relative to the scenario file's folder)
  TrajectoryFile reference;     // loaded and checked (Δt = controller.dt, nx = 4, nu = 1)

  struct Lqr {
    bool enabled = true;
    Eigen::Vector4d q{3.0, 3.0, 1.0, 1.0};  // default: the NMPC's W
    double r = 5.0;
    double enter_angle = pendubot_defaults::kLqrEnter;            // [rad]
    double enter_velocity = pendubot_defaults::kLqrEnterVelocity;  // [rad/s]
    double exit_angle = pendubot_defaults::kLqrExit;              // [rad]
  } lqr;

  struct Plant {
    double rate_hz = pendubot_defaults::kPlantRateHz;  // RK4 substeps per second (≥ 1000)
    Eigen::Vector4d initial_state = models::Pendubot::down_down();
  } plant;

  struct Sensor {
    bool quantization = false;
    int counts_q1 = pendubot_defaults::kEncoderCounts1;  // per turn
    int counts_q2 = pendubot_defaults::kEncoderCounts2;
    double velocity_cutoff_hz = pendubot_defaults::kVelocityCutoffHz;  // 0: raw differences
    // "difference": angles = encoder cell centres, velocities = low-passed differences.
    // "observer": the model predicts x̂ over Δt with the applied input, and the encoder angles
    // correct it (α-β gains): q̂ += α e, q̇̂ += β e / Δt with e = q_enc − q̂⁻.
    std::string estimator = "difference";
    double observer_alpha = pendubot_defaults::kObserverAlpha;
    double observer_beta = pendubot_defaults::kObserverBeta;
  } sensor;
};

std::optional<PendubotScenario> load_pendubot_scenario(const std::string& path, std::string& error);
// The same from text; the reference path is resolved against source_name's folder.
std::optional<PendubotScenario> parse_pendubot_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error);

// ---------------------------------------------------------------------------------------------
// Closed loop.
struct PendubotRun {
  int steps = 0;
  std::optional<double> swingup_time;  // first t after which ‖wrap(q)‖ ≤ tolerance to the end
  double final_angle_norm = 0.0;       // ‖wrap(q)‖ at the end [rad]
  double max_abs_u = 0.0;              // applied input [N·m]
  int velocity_violations = 0;         // control intervals with a plant substep outside bounds
  double worst_velocity_violation = 0.0;  // max excess over the bound [rad/s]
  double tracking_rms = 0.0;  // RMS of ‖q − q_ref‖ over the reference span, NMPC steps [rad]
  double rti_median_us = 0.0;  // prepare + feedback + shift
  double rti_p99_us = 0.0;
  double rti_max_us = 0.0;
  int nmpc_steps = 0;
  std::int64_t fallbacks = 0;
  double lqr_time = 0.0;  // time under LQR [s]
  int lqr_entries = 0;
  double lqr_entry_time = -1.0;  // first switch to LQR [s], −1 if none

  // Per control step (when logging): t, true state, applied u, LQR active.
  std::vector<double> t;
  std::vector<Eigen::Vector4d> x;
  std::vector<double> u;
  std::vector<std::uint8_t> lqr;
};

// wrap to (−π, π].
double wrap_angle(double a);

PendubotRun simulate_pendubot_swingup(const PendubotScenario& scenario, bool log = false);

// `mixpilot fly` runner of mode "pendubot_swingup" (core/modes/mode.hpp).
ModeResult fly_pendubot_swingup(const std::string& path, const ModeOptions& options);

}  // namespace mixpilot
