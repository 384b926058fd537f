#pragma once
// Crazyflie position tracking under a communication round-trip delay (SPEC §5.2, thesis ch. 5):
// mode `crazyflie_tracking`. The delay model, the predictor and the controllers are in
// core/control/tracking.hpp; the scenario file in core/scenario/tracking_scenario.hpp.
//
// Clocks. On the controller's clock σ = t − τ_c (the time a command was sent), the plant state
// when u_k starts acting is x(σ = t_k), and the measurement at t_k is x(σ = t_k − τ_r): the
// closed loop depends on τ_r only. Tracking errors are taken on that clock, e_k = p(t_k + τ_c)
// − p_ref(t_k): the command link's transport lag itself is not an error (a reference on the
// controller's clock cannot reach the vehicle sooner), so runs with different splits agree. The
// telemetry is on the same clock: step k reports x(σ = t_k), the controller's initial state x0
// (the prediction of x(σ = t_k) when compensating, else the measurement), u_k and p_ref(t_k).
//
// Step k: measure the state of plant boundary k·s − n_m, predict it over τ_r (timed), run the
// NMPC (one RTI step) or the LQR law, send u_k, and simulate the plant to boundary (k+1)·s, where
// the loss check and the error samples are taken. After the last step the plant runs on to
// K·s + n_c, so the last command's effect is sampled (m = K). The plant is integrated ahead as
// far as the commands already sent determine it (to k·s + n_c at least), so that x(σ = t_k) is
// known when step k ends; integrating ahead changes no state.
//
// A remote vehicle (set_vehicle(), core/modes/linked_vehicle.hpp): the plant runs elsewhere and
// nothing is simulated here. Step k starts from the vehicle's newest state, which echoes the
// command j in effect when it was measured and how long that command had acted (a); each new
// state is one round-trip sample for the estimator (core/control/rtt_estimator.hpp) and one
// error sample at σ = t_j + a. With compensation the state is predicted over the estimated
// round-trip time plus the time it waited here since it arrived; the telemetry shows that
// prediction (what is known of the vehicle at t_k). The vehicle is lost when its
// state leaves the world or it stays silent past the link's timeout.
//
// setup() sizes everything; step() allocates nothing.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/crazyflie_tracking.hpp"
#include "core/control/tracking.hpp"
#include "core/modes/linked_vehicle.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/safety_net.hpp"
#include "core/modes/simulated_vehicle.hpp"
#include "core/nlp/rti.hpp"
#include "core/numerics/reserved_vector.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/scenario/tracking_scenario.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

// The run's results so far (TrackingMode::result()).
struct TrackingResult {
  bool ok = false;      // the run happened (false: setup failed; see error)
  std::string error;
  bool lost = false;    // the plant state stopped being finite or left a 100 m ball
  int steps = 0;
  double tracking_rms_m = 0;  // RMS over the samples m of ‖e_m‖
  double max_error_m = 0;
  double final_error_m = 0;   // ‖e‖ of the last sample
  // Smooth step only: with d the unit step direction and L the step length, the overshoot is
  // max(0, max_m (p_m − p_start)·d − L), the progress past the target along the step; the
  // settle time is the first σ after which ‖p − target‖ ≤ kSettleRadius for good.
  double overshoot_m = 0;
  double settle_time_s = 0;
  double max_input_violation = 0;  // max over k of the applied input outside [0, 22] krpm
  double solve_median_us = 0;      // controller (RTI prepare + feedback, or LQR law)
  double solve_p99_us = 0;
  double predictor_median_us = 0;  // 0 without compensation
  long fallbacks = 0;              // RTI fallbacks (SPEC §4)
  int rtt_substeps = 0;
  int measurement_substeps = 0;
  int command_substeps = 0;
  // Remote vehicle: the median of the round-trip samples and the estimator's final estimate.
  bool remote = false;
  double rtt_measured_s = 0;
  double rtt_estimated_s = 0;
  long rtt_samples = 0;
};

class TrackingMode final : public Mode {
 public:
  using State = models::Crazyflie::State;
  using Input = models::Crazyflie::Input;

  TrackingMode() = default;
  TrackingMode(const TrackingMode&) = delete;  // the RTI solver points into problem_
  TrackingMode& operator=(const TrackingMode&) = delete;

  // Prepares a flight of `scenario`. Fails with the reason when there is no reference or the
  // controller cannot be set up (invalid OCP, a Riccati equation that does not converge).
  SetupResult setup(TrackingScenario scenario);

  ModeKind kind() const override { return ModeKind::crazyflie_tracking; }
  const std::string& scenario_name() const override { return scenario_.name; }
  double dt() const override { return scenario_.controller.dt; }
  std::int64_t steps_total() const override { return steps_total_; }
  std::int64_t steps_done() const override { return run_.step; }
  [[nodiscard]] bool step() override;
  bool finished() const override { return run_.finished; }
  bool lost() const override { return run_.lost; }
  double lost_at() const override { return run_.lost_at; }  // σ of the boundary found lost, or −1
  const Telemetry& telemetry() const override { return run_.telemetry; }
  void set_deadline_us(double d) override {
    if (rti_) rti_->set_deadline_us(d);
  }
  RtiSolver* rti_solver() override { return rti_.get(); }
  // tracking_rms_m, max_error_m, final_error_m, [overshoot_m, settle_time_s: smooth step],
  // rti_median_us, rti_p99_us, fallbacks (NMPC) or lqr_median_us, lqr_p99_us (LQR),
  // predictor_median_us, max_input_violation, rtt_s, compensation, steps, lost.
  InstructorStatus accepts(InstructorCommandKind kind) const override {
    if (kind == InstructorCommandKind::gust || kind == InstructorCommandKind::extra_delay)
      return remote() ? InstructorStatus::remote_vehicle : InstructorStatus::applied;
    return Mode::accepts(kind);
  }
  Metrics metrics() const override;
  std::string summary() const override;
  ModeView view() const override;

  // Flies the vehicle behind `link` instead of the simulated plant (after setup(), before the
  // first step; nullptr: the simulated plant). The link outlives the flight.
  [[nodiscard]] bool set_vehicle(VehicleLink* link) override;
  VehicleStateSpec remote_state() const override;
  bool remote() const { return remote_.attached(); }
  const RttEstimator& rtt_estimator() const { return remote_.rtt(); }
  // Why the vehicle was lost ("" while it is not): left the world, or silent.
  const char* lost_reason() const { return run_.lost_reason; }

  TrackingResult result() const;
  const TrackingScenario& scenario() const { return scenario_; }
  bool nmpc() const { return problem_ != nullptr; }
  const SafetyNet& safety_net() const { return run_.safety; }

 protected:
  // Snapshots (Mode::save, Mode::restore): the NMPC's RTI state, the predictor's sent
  // commands, the simulated vehicle and Run. With a remote vehicle they refuse.
  void save_state(std::unique_ptr<ModeSnapshot::State>& state) const override;
  [[nodiscard]] RestoreStatus restore_state(const ModeSnapshot::State& state) override;
  // The instructor (Mode::instruct, SPEC §10): a gust on the simulated plant; an extra delay
  // on the measurement y, which the delay compensation does not know of (it predicts over the
  // scenario's rtt alone). With a remote vehicle both are refused.
  [[nodiscard]] InstructorStatus apply_gust(const Eigen::Vector3d& force, double duration) override;
  [[nodiscard]] InstructorStatus apply_extra_delay(double delay) override;
  InstructorInForce in_force(std::int64_t k) const override;

 private:
  struct Saved;
  void measure();
  void control();
  void send();
  bool process_to(long end);
  void sample(long m, const State& x);
  void sample_at(double sigma, const State& x);
  void add_sample(long m, const Eigen::Vector3d& p, const Eigen::Vector3d& pr);
  bool step_remote();
  void lose(double at, const char* reason);
  void init_telemetry();
  void set_telemetry();
  void set_channels(double predictor_us, double controller_us);

  TrackingScenario scenario_;
  models::Crazyflie model_{};
  std::unique_ptr<CrazyflieTracking> problem_;  // NMPC only
  std::unique_ptr<RtiSolver> rti_;              // NMPC only
  TrackingLqr lqr_;  // the LQR law, or the NMPC's safe controller
  CrazyflieDelayPredictor predictor_;

  // Delay model in plant substeps (core/control/tracking.hpp).
  long s_ = 1;    // substeps per control period
  double h_ = 0;  // substep [s]
  long n_r_ = 0, n_m_ = 0, n_c_ = 0;  // τ_r, τ_m, τ_c
  long last_x_ = 0, last_u_ = 0;      // last reference node of x, of u
  State x_init_ = State::Zero();

  // Error samples m = 0..K at boundaries m·s + n_c (σ = t_m).
  Eigen::Vector3d ref_start_ = Eigen::Vector3d::Zero();   // p_ref of the first node
  Eigen::Vector3d ref_target_ = Eigen::Vector3d::Zero();  // p_ref of the last node
  Eigen::Vector3d step_dir_ = Eigen::Vector3d::Zero();    // unit (target − start), or 0
  double step_len_ = 0;

  // The plant with its delay lines (n_c, n_m), at rest until the first command acts.
  SimulatedVehicle<models::Crazyflie> simulated_;
  LinkedVehicle<models::Crazyflie> remote_;  // flown when attached (set_vehicle())

  std::int64_t steps_total_ = 0;
  bool ok_ = false;  // setup succeeded

  // What the flight changes step by step, besides the states of the NMPC, the predictor and
  // the simulated vehicle: a snapshot copies it.
  struct Run {
    // The simulated vehicle's boundaries checked and sampled up to j.
    long j = 0;
    long j_lost = -1;  // boundary found lost

    // Step k: the measurement, the controller's initial state, the command.
    State y = State::Zero();
    State x0 = State::Zero();
    State predicted = State::Zero();  // remote: the newest state predicted to t_k
    Input u = Input::Zero();
    SafetyNet safety;
    double compute_us = 0.0;  // the step's measurement and control time

    // Error samples and metrics so far.
    ReservedVector<double> err2;  // ‖e_m‖² per sample, reserved for K + 1
    double max_error = 0, final_error = 0;
    double max_progress = 0;  // max_m (p_m − start)·dir
    long last_outside = -1;   // last m outside the settle radius
    double max_input_violation = 0;
    ReservedVector<double> solve_us;    // per step, reserved for steps_total
    ReservedVector<double> predict_us;  // per step, reserved for steps_total

    const char* lost_reason = "";
    Telemetry telemetry;
    std::int64_t step = 0;
    bool finished = true;
    bool lost = false;
    double lost_at = -1.0;
  };
  Run run_;
};

// Per control step k (optional log of a run), from the telemetry.
struct TrackingLog {
  std::vector<double> t;               // σ = t_k [s]
  std::vector<Eigen::Vector3d> p;      // p(σ = t_k)
  std::vector<Eigen::Vector3d> p_ref;  // p_ref(t_k)
  std::vector<models::Crazyflie::State> x_true;  // x(σ = t_k): state when u_k starts acting
  std::vector<models::Crazyflie::State> x0;      // the controller's initial state for u_k
  std::vector<models::Crazyflie::Input> u;       // u_k
};

// Flies the scenario to its end. `log` (optional) receives one entry per control step.
TrackingResult run_tracking(const TrackingScenario& scenario, TrackingLog* log = nullptr);

}  // namespace mixpilot
