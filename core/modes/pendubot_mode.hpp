#pragma once
// Pendubot swing-up (SPEC §5.1, thesis ch. 4): mode `pendubot_swingup`, from down-down to up-up
// and balance. The controllers are core/control/pendubot.hpp; the scenario file
// core/scenario/pendubot_scenario.hpp.
//
// Step k, [t_k, t_k + Δt):
// - Sensor: the estimate x̂_k from the true state x_k: exact, or encoders (q1: 1/8192 turn, q2:
//   1/4096 turn) with velocities from differenced quantized angles through a first-order
//   low-pass, or from a model-based α-β observer driven by the quantized angles.
// - Switch rule (hysteresis) on x̂ with wrapped angles: NMPC → LQR when ‖wrap(q̂)‖ ≤
//   enter_angle, ‖q̂̇‖ ≤ enter_velocity and the LQR input |K x̂| ≤ u_max (unsaturated: inside the
//   LQR's linear region); LQR → NMPC when ‖wrap(q̂)‖ > exit_angle (> enter_angle), the NMPC then
//   restarting from x̂ towards up-up.
// - Controller: the LQR law, or one RTI step from x̂ tracking the reference from node k
//   (angles as measured while the reference lasts, wrapped after it, when the target is up-up).
// - Plant: the same model, RK4 at `rate_hz` (default 4 kHz: 0.25 ms substeps), u_k held over Δt;
//   a substep outside a velocity bound counts the step as a violation.
//
// Telemetry of step k: x = x_k, x_measured = x̂_k, u = u_k, reference = the swing-up reference's
// node k (up-up past its last node), solved = an RTI step ran (false on LQR steps), events
// kEventSwitch (the controller changed), kEventViolation (a substep beyond a velocity bound),
// kEventFallback (the RTI fell back); channels (PendubotChannel) with the wrapped state, its
// reference, u, the active controller and the bounds. Before the first step: x_0, u = 0.
//
// The instructor (Mode::instruct, SPEC §10): markers, pause, resume and end; a gust is refused
// (an arm on a fixed shoulder has no free body to push), as are an extra delay (its controller
// is wired to its encoders, no link) and bounds or an input loss (no pilot).
//
// setup() sizes everything; step() allocates nothing.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/pendubot.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/safety_net.hpp"
#include "core/nlp/rti.hpp"
#include "core/numerics/reserved_vector.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/scenario/pendubot_scenario.hpp"
#include "models/pendubot.hpp"

namespace mixpilot {

// Channel slots of the Pendubot telemetry (angles wrapped to (−π, π]).
enum PendubotChannel {
  kPendubotQ1,             // wrap(q1) [rad]
  kPendubotQ2,             // wrap(q2) [rad]
  kPendubotDq1,            // q̇1 [rad/s]
  kPendubotDq2,            // q̇2 [rad/s]
  kPendubotQ1Reference,    // the same of the reference node k
  kPendubotQ2Reference,
  kPendubotDq1Reference,
  kPendubotDq2Reference,
  kPendubotTorque,         // u [N m]
  kPendubotLqrActive,      // 1 on an LQR step, 0 on an NMPC step
  kPendubotAngleNorm,      // ‖wrap(q)‖ [rad]
  kPendubotDq1Bound,       // the soft bounds |q̇| ≤ velocity_bound [rad/s]
  kPendubotDq2Bound,
  kPendubotTorqueBound,    // |u| ≤ u_max [N m]
  kPendubotChannels,
};

// The run's results so far (PendubotMode::result()); per control step (when logging,
// simulate_pendubot_swingup()): t, true state, applied u, LQR active, and a last entry with the
// final state (u = 0).
struct PendubotRun {
  bool ok = false;     // the run happened (false: setup failed; see error)
  std::string error;
  int steps = 0;
  std::optional<double> swingup_time;  // first t after which ‖wrap(q)‖ ≤ tolerance to the end
  double final_angle_norm = 0.0;       // ‖wrap(q)‖ at the end [rad]
  double max_abs_u = 0.0;              // applied input [N·m]
  int velocity_violations = 0;         // control intervals with a plant substep outside bounds
  double worst_velocity_violation = 0.0;  // max excess over the bound [rad/s]
  double tracking_rms = 0.0;  // RMS of ‖q − q_ref‖ over the reference span, NMPC steps [rad]
  double rti_median_us = 0.0;  // RTI time per step: prepare + feedback (RtiStats::total_us)
  double rti_p99_us = 0.0;
  double rti_max_us = 0.0;
  int nmpc_steps = 0;
  std::int64_t fallbacks = 0;
  double lqr_time = 0.0;  // time under LQR [s]
  int lqr_entries = 0;
  double lqr_entry_time = -1.0;  // first switch to LQR [s], −1 if none

  std::vector<double> t;
  std::vector<Eigen::Vector4d> x;
  std::vector<double> u;
  std::vector<std::uint8_t> lqr;
};

class PendubotMode final : public Mode {
 public:
  using State = models::Pendubot::State;

  PendubotMode() = default;
  PendubotMode(const PendubotMode&) = delete;  // the RTI solver points into problem_
  PendubotMode& operator=(const PendubotMode&) = delete;

  // Prepares a run of `scenario`. Fails with the reason when the reference does not fit, the
  // settings are out of range (weights, LQR, plant rate, sensor) or the controllers cannot be
  // set up (an invalid OCP, a Riccati equation that does not converge); then step() does nothing.
  SetupResult setup(PendubotScenario scenario);

  ModeKind kind() const override { return ModeKind::pendubot_swingup; }
  const std::string& scenario_name() const override { return scenario_.name; }
  double dt() const override { return scenario_.controller.dt; }
  std::int64_t steps_total() const override { return steps_total_; }
  std::int64_t steps_done() const override { return run_.step; }
  [[nodiscard]] bool step() override;
  bool finished() const override { return run_.finished; }
  bool lost() const override { return false; }  // the arm is mounted: never lost
  double lost_at() const override { return -1.0; }
  const Telemetry& telemetry() const override { return run_.telemetry; }
  void set_deadline_us(double d) override { rti_.set_deadline_us(d); }
  RtiSolver* rti_solver() override { return &rti_; }
  // duration_s, swingup_time_s, hold_time_s, final_angle_norm, max_abs_u, velocity_violations,
  // worst_velocity_violation, tracking_rms, rti_median_us, rti_p99_us, rti_max_us, nmpc_steps,
  // fallbacks, lqr_entry_time_s, lqr_time_s, lqr_entries, quantization.
  Metrics metrics() const override;
  std::string summary() const override;
  ModeView view() const override;

  // The results so far, without the per-step log.
  PendubotRun result() const;
  const PendubotScenario& scenario() const { return scenario_; }
  const PendubotLqr& lqr() const { return lqr_; }
  // The true plant state now, x(t = steps_done·Δt): after the last step, the final state.
  const State& state() const { return run_.x; }
  bool lqr_active() const { return run_.lqr_active; }
  const SafetyNet& safety_net() const { return run_.safety; }

 protected:
  // Snapshots (Mode::save, Mode::restore): the NMPC's RTI state and Run.
  void save_state(std::unique_ptr<ModeSnapshot::State>& state) const override;
  [[nodiscard]] RestoreStatus restore_state(const ModeSnapshot::State& state) override;

 private:
  struct Saved;
  SetupResult check_settings() const;
  void warm_start();
  void measure();
  bool switch_controller();
  double control();
  double nmpc();
  double integrate(double u);
  void record_angle_norm();
  void set_telemetry(double u, bool switched, double worst_violation);
  void set_channels();

  PendubotScenario scenario_;
  std::unique_ptr<PendubotSwingup> problem_;
  RtiSolver rti_;
  PendubotLqr lqr_;  // zero gain when the scenario's LQR is disabled

  std::int64_t steps_total_ = 0;
  int substeps_ = 1;      // plant RK4 substeps per control step
  double h_ = 0.0;        // substep [s]
  int ref_steps_ = 0;     // reference intervals: the NMPC tracks it while k < ref_steps_
  double lowpass_ = 1.0;  // velocity low-pass gain per step, 1 − exp(−2π f_c Δt) (1: none)
  bool observer_ = false;
  bool ok_ = false;  // setup succeeded
  State xn_ = State::Zero();  // ERK4 output (scratch)

  // What the flight changes step by step, besides the NMPC's state: a snapshot copies it.
  struct Run {
    // Plant and sensor.
    State x = State::Zero();                         // true state x_k
    Eigen::Vector4d xm = Eigen::Vector4d::Zero();      // estimate x̂_k (angles as measured)
    Eigen::Vector4d xw = Eigen::Vector4d::Zero();      // x̂_k with wrapped angles
    Eigen::Vector2d q_prev = Eigen::Vector2d::Zero();  // previous encoder angles
    Eigen::Vector2d v_filt = Eigen::Vector2d::Zero();  // low-passed differenced velocities
    Eigen::VectorXd x0;                               // 4: the NMPC's initial state
    double u_prev = 0.0;                              // u_{k−1}, the observer's prediction input
    bool lqr_active = false;
    // The NMPC's safety net: the LQR near the top, no torque elsewhere, once its plan is spent.
    SafetyNet safety;

    // Metrics so far.
    double max_abs_u = 0.0;
    int velocity_violations = 0;
    double worst_velocity_violation = 0.0;
    double err2 = 0.0;  // Σ ‖q_k − q_ref,k‖² over NMPC steps inside the reference
    int err_n = 0;
    int nmpc_steps = 0;
    double lqr_time = 0.0;
    int lqr_entries = 0;
    double lqr_entry_time = -1.0;
    double angle_norm = 0.0;          // ‖wrap(q)‖ of x (the state now)
    std::int64_t last_outside = -1;   // last k with ‖wrap(q_k)‖ > angle_tolerance
    ReservedVector<double> rti_us;    // per NMPC step, reserved for steps_total

    Telemetry telemetry;
    std::int64_t step = 0;
    bool finished = true;
  };
  Run run_;
};

// Runs the scenario to its end. With `log`, one entry per control step and the final state.
// An empty run (steps = 0) when setup fails.
PendubotRun simulate_pendubot_swingup(const PendubotScenario& scenario, bool log = false);

}  // namespace mixpilot
