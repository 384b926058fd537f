#pragma once
// Crazyflie position tracking under a communication round-trip delay (SPEC §5.2, thesis ch. 5,
// issue 6): mode `crazyflie_tracking`.
//
// Delay model (thesis §5.3.1: only the round-trip time τ_r matters, its split is arbitrary).
// The plant integrates RK4 substeps of h = 1/rate_hz; τ_r = n_r·h is split into a measurement
// delay τ_m = n_m·h (the controller at t_k sees the state of t_k − τ_m) and a command delay
// τ_c = n_c·h (command u_k acts on the rotors over [t_k + τ_c, t_{k+1} + τ_c)), n_m + n_c = n_r.
// The computation time is taken as part of τ_c. Before its first command reaches it the vehicle
// rests in its initial (hover) state.
//
// Clocks. On the controller's clock σ = t − τ_c (the time a command was sent), the plant state
// when u_k starts acting is x(σ = t_k), and the measurement at t_k is x(σ = t_k − τ_r): the
// closed loop depends on τ_r only. Tracking errors are taken on that clock, e_k = p(t_k + τ_c)
// − p_ref(t_k): the command link's transport lag itself is not an error (a reference on the
// controller's clock cannot reach the vehicle sooner), so runs with different splits agree.
//
// Delay compensation (SPEC §5.2): the measurement is predicted over τ_r by ERK4 with the inputs
// already sent (DelayPredictor), and the controller starts from the prediction. With the plant's
// substep and model it reproduces the plant exactly: x0 = x(σ = t_k).
//
// Controllers: the SPEC §5.2 NMPC (core/control/crazyflie_tracking.hpp, RTI) or the 12-state LQR
// baseline (TrackingLqr). Everything in the control loop runs on preallocated storage.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "core/numerics/integrator_erk4.hpp"
#include "core/modes/mode.hpp"
#include "core/nlp/ocp.hpp"
#include "core/numerics/types.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

enum class TrackingReferenceKind { smooth_step, helix };
enum class TrackingControllerKind { nmpc, lqr };

// SPEC §5.2 (b): p(t) = (cx + R cos(φ0 + ωt), cy + R sin(φ0 + ωt), z0 + v_z t) for t ≤ length,
// then its last point is held. The centre is (−R cos φ0, −R sin φ0) so the helix starts right
// below the hover point (0, 0, ·): at (0, 0, z0).
struct TrackingHelix {
  double radius = tracking_defaults::kHelixRadius;              // R [m]
  double start_height = tracking_defaults::kHelixStartHeight;   // z0 [m]
  double climb_rate = tracking_defaults::kHelixClimbRate;       // v_z [m/s]
  double angular_rate = tracking_defaults::kHelixAngularRate;   // ω [rad/s]
  double phase = 0.0;                                           // φ0 [rad]
  double length = tracking_defaults::kHelixLength;              // [s]
};

struct TrackingReferenceSettings {
  TrackingReferenceKind kind = TrackingReferenceKind::smooth_step;
  std::string file;       // smooth_step: trajectory CSV (core/nlp/trajectory_io.hpp), as resolved
  TrackingHelix helix{};  // helix
};

struct TrackingControllerSettings {
  TrackingControllerKind kind = TrackingControllerKind::nmpc;
  int N = tracking_defaults::kHorizon;   // NMPC horizon
  double dt = tracking_defaults::kDt;    // control period [s]
  bool compensation = tracking_defaults::kCompensation;  // ERK4 predictor over τ_r
};

struct TrackingPlantSettings {
  double rate_hz = tracking_defaults::kPlantRateHz;  // RK4 substeps per second
  double rtt = tracking_defaults::kRtt;              // τ_r [s], a whole number of substeps
  // τ_m = round(measurement_fraction·n_r)·h, τ_c = τ_r − τ_m.
  double measurement_fraction = tracking_defaults::kMeasurementFraction;
  Eigen::Vector3d start{0.0, 0.0, 0.4};  // initial hover position [m] (SPEC §5.2)
};

struct TrackingScenario {
  std::string name;
  std::string source_path;
  double duration = tracking_defaults::kDuration;  // [s]
  TrackingReferenceSettings reference{};
  TrackingControllerSettings controller{};
  TrackingPlantSettings plant{};
  OcpTrajectory reference_trajectory;  // nodes every controller.dt (x: n+1, u: n)
};

// Reading `mode = "crazyflie_tracking"` scenarios (docs/scenario-format.md). On failure: nullopt
// and one `<file>:<line>:<col>: <key path>: <what was expected>` line per problem. The smooth
// step's CSV is resolved relative to the scenario's directory, then to the working directory.
std::optional<TrackingScenario> parse_tracking_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error);
std::optional<TrackingScenario> load_tracking_scenario(const std::string& path,
                                                       std::string& error);

// Reference nodes of the helix every dt over its length: position on the helix, hover attitude
// (q = identity) and inputs, body velocity = the derivative (q = identity), ω = 0. The last node
// is the held end point (zero velocity).
OcpTrajectory helix_reference(const TrackingHelix& helix, double dt, const models::Crazyflie& model);

// The ERK4 state predictor of SPEC §5.2 over τ_r = n_r substeps of h (control period = s
// substeps), with the inputs already sent. setup() allocates; the rest does not.
class DelayPredictor {
 public:
  using State = models::Crazyflie::State;
  using Input = models::Crazyflie::Input;

  void setup(const models::Crazyflie& model, int substeps_per_period, double h, int rtt_substeps);
  // Forgets the sent commands (next command is k = 0).
  void reset();
  // Command u_k was sent (call once per period, after predict()).
  void record_sent(const Input& u);
  // x(σ = t_k) from the measurement x(σ = t_k − τ_r), integrating from max(t_k − τ_r, 0) (the
  // vehicle rests before its first command) with the command in effect on each substep.
  void predict(const State& measured, State& predicted) const;
  int rtt_substeps() const { return n_r_; }

 private:
  IntegratorErk4<models::Crazyflie> erk4_{};
  int s_ = 1;      // substeps per control period
  double h_ = 0;   // substep [s]
  int n_r_ = 0;    // τ_r in substeps
  std::vector<Input> sent_;  // ring of the last commands, indexed k mod size
  long k_ = 0;               // commands sent so far
};

// Discrete LQR on the 12-state model (SPEC §5.2): the ERK4 map at hover over dt, with qw
// eliminated (∂qw/∂q_v = 0 at hover). State order (p, q_x q_y q_z, v_b, ω), matching
// Q = blkdiag(12.24e3, 10.2e3, 9e5, 0.102·I3, 71.4, 102, 408, 1.02e-3·I2, 1.02e3): it is
// 102·W_ξ of the NMPC with q_w dropped and the z weight raised to 9e5 (the thesis's "detuned
// for z"). Tracking law u = u_ref − K (x12 − x12_ref), clipped to [0, 22] krpm: the thesis's
// u = ū − K ξ around the reference instead of around hover (u_ref = ū on a hover reference and
// along the helix; on the smooth step it is the Ipopt input, a feedforward without which the
// saturated start of the step is lost).
class TrackingLqr {
 public:
  using State = models::Crazyflie::State;
  using Input = models::Crazyflie::Input;
  using Mat12 = Eigen::Matrix<double, 12, 12>;
  using Gain = Eigen::Matrix<double, 4, 12>;

  // false when the DARE iteration does not converge.
  bool setup(const models::Crazyflie& model, double dt);
  void control(const State& x, const State& x_ref, const Input& u_ref, Input& u) const;

  static Eigen::Matrix<double, 12, 1> q_diagonal();
  static double r_weight() { return tracking_defaults::kLqrR; }
  static Eigen::Matrix<double, 12, 1> reduce(const State& x);  // drops q_w

  const Mat12& A() const { return A_; }
  const Eigen::Matrix<double, 12, 4>& B() const { return B_; }
  const Mat12& P() const { return P_; }
  const Gain& K() const { return K_; }
  double dare_residual() const { return residual_; }  // ‖DARE(P)‖∞ / ‖P‖∞

 private:
  Mat12 A_ = Mat12::Zero();
  Eigen::Matrix<double, 12, 4> B_ = Eigen::Matrix<double, 12, 4>::Zero();
  Mat12 P_ = Mat12::Zero();
  Gain K_ = Gain::Zero();
  Input u_hover_ = Input::Zero();
  double u_min_ = 0, u_max_ = 0;
  double residual_ = 0;
};

// Per control step (optional log of a run).
struct TrackingLog {
  std::vector<double> t;               // σ = t_k [s]
  std::vector<Eigen::Vector3d> p;      // p(σ = t_k)
  std::vector<Eigen::Vector3d> p_ref;  // p_ref(t_k)
  std::vector<models::Crazyflie::State> x_true;  // x(σ = t_k): state when u_k starts acting
  std::vector<models::Crazyflie::State> x0;      // the controller's initial state for u_k
  std::vector<models::Crazyflie::Input> u;       // u_k
};

struct TrackingResult {
  bool ok = false;      // the run happened (false: setup failed; see error)
  std::string error;
  bool lost = false;    // the plant state stopped being finite or left a 100 m ball
  int steps = 0;
  double tracking_rms_m = 0;  // RMS over k of ‖e_k‖
  double max_error_m = 0;
  double final_error_m = 0;   // ‖e‖ at the end
  // Smooth step only: with d the unit step direction and L the step length, the overshoot is
  // max(0, max_k (p_k − p_start)·d − L), the progress past the target along the step; the
  // settle time is the first σ after which ‖p − target‖ ≤ kSettleRadius for good.
  double overshoot_m = 0;
  double settle_time_s = 0;
  double max_input_violation = 0;  // max over k of the applied input outside [0, 22] krpm
  double solve_median_us = 0;      // controller (RTI prepare + feedback, or LQR law)
  double solve_p99_us = 0;
  double predictor_median_us = 0;
  long fallbacks = 0;              // RTI fallbacks (SPEC §4)
  int rtt_substeps = 0;
  int measurement_substeps = 0;
  int command_substeps = 0;
};

// Flies the scenario. `log` (optional) receives one entry per control step.
TrackingResult run_tracking(const TrackingScenario& scenario, TrackingLog* log = nullptr);

// Mode runner (core/modes/mode.hpp): metrics tracking_rms_m, max_error_m, final_error_m,
// [overshoot_m, settle_time_s: smooth step], rti_median_us, rti_p99_us, fallbacks (NMPC) or
// lqr_median_us, lqr_p99_us (LQR), predictor_median_us, rtt_s, compensation, steps, lost.
ModeResult fly_crazyflie_tracking(const std::string& path, const ModeOptions& options);

}  // namespace mixpilot
