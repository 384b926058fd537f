#pragma once
// The obstacle-avoidance mode (SPEC §5.3): the NMPC of core/control/obstacle_avoidance.hpp
// flies a scenario's reference past its spheres and thrown balls. One RTI per Δt; the plant is
// the same Crazyflie model with RK4 at plant_rate_hz (≥ 1 kHz) substeps, the input held over Δt
// (core/modes/simulated_vehicle.hpp, without delays or noise).
// Distances to every obstacle are checked at every plant substep (thesis §6.3.2: between
// shooting nodes the path may cut the clearance sphere slightly) and at the control instants,
// where the constraint is imposed.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/obstacle_avoidance.hpp"
#include "core/control/tracking.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/safety_net.hpp"
#include "core/modes/simulated_vehicle.hpp"
#include "core/nlp/rti.hpp"
#include "core/numerics/reserved_vector.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/scenario/obstacle_scenario.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

// The run so far: what the metrics, the summary and run_obstacle_avoidance report.
struct ObstacleRunResult {
  std::string error;             // setup failed: why (nothing was flown)
  ObstacleForm form = ObstacleForm::lcl;
  int steps = 0;
  double min_distance_m = 0.0;   // min over plant substeps and obstacles of ‖p − o‖
  double min_margin_m = 0.0;     // min_distance_m − d_C
  // The same at the control instants only: where the constraint is imposed.
  double min_distance_control_m = 0.0;
  double min_distance_time = 0.0;  // when it happened [s]
  int closest_obstacle = -1;
  int violations = 0;            // control intervals with ‖p − o‖ < d_C − 1 mm at some substep
  double tracking_rms_m = 0.0;   // RMS of ‖p − p_ref‖ at the control instants
  double final_error_m = 0.0;    // ‖p − p_ref,last‖ at the end
  double rti_median_us = 0.0;    // prepare + feedback
  double rti_p99_us = 0.0;
  double rti_max_us = 0.0;
  int fallbacks = 0;
  bool lost = false;             // the plant state stopped being finite
  int qp_iterations_max = 0;
  // ObstacleRunOptions::keep_trajectory: per control step k (and positions[steps] = the final
  // one).
  std::vector<Eigen::Vector3d> positions;  // p at t_k
  std::vector<double> step_us;             // RTI prepare + feedback
  std::vector<int> step_qp_iterations;
  std::vector<int> step_status;            // RtiStatus
};

// Telemetry of step k: x = x_measured = the state at t_k (13), u (4), reference = p_ref(t_k)
// (3), predicted / predicted_reference = the RTI plan's positions and the reference positions at
// the N + 1 nodes, the RTI statistics; events kEventFallback, kEventViolation (a substep of the
// step came closer than d_C − 1 mm to an obstacle), kEventLost (the plant state stopped being
// finite: the run ends, state() keeps the last finite one); channels "min distance" (over the
// obstacles and the step's plant substeps, ∞ without obstacles), "clearance margin" (that − d_C),
// "tracking error" (‖p_k − p_ref(t_k)‖), "QP iterations".
class ObstacleMode final : public Mode {
 public:
  ObstacleMode() = default;
  ObstacleMode(const ObstacleMode&) = delete;  // the RTI solver points into problem_
  ObstacleMode& operator=(const ObstacleMode&) = delete;

  // Prepares a flight of `scenario` (its duration, its constraint form unless `form` is
  // given). Fails with the reason when it cannot be flown: a reference that is not a Crazyflie
  // trajectory, no whole number of plant substeps per Δt, an invalid OCP.
  SetupResult setup(ObstacleScenario scenario, std::optional<ObstacleForm> form = {});

  ModeKind kind() const override { return ModeKind::obstacle_avoidance; }
  const std::string& scenario_name() const override { return scenario_.name; }
  double dt() const override { return settings_.dt; }
  std::int64_t steps_total() const override { return steps_total_; }
  std::int64_t steps_done() const override { return run_.step; }
  [[nodiscard]] bool step() override;
  bool finished() const override { return run_.finished; }
  bool lost() const override { return run_.lost; }
  double lost_at() const override { return run_.lost_at; }
  const Telemetry& telemetry() const override { return run_.telemetry; }
  void set_deadline_us(double d) override { rti_.set_deadline_us(d); }
  RtiSolver* rti_solver() override { return &rti_; }
  // min_distance_m, min_margin_m, min_distance_control_m, clearance_m, violations,
  // tracking_rms_m, final_error_m, rti_median_us, rti_p99_us, fallbacks, form (0 lcl,
  // 1 squared), steps.
  InstructorStatus accepts(InstructorCommandKind kind) const override {
    if (kind == InstructorCommandKind::gust || kind == InstructorCommandKind::extra_delay)
      return InstructorStatus::applied;
    return Mode::accepts(kind);
  }
  Metrics metrics() const override;
  std::string summary() const override;
  ModeView view() const override;

  // The scenario flown; its world at telemetry().t is where the obstacles are.
  const ObstacleScenario& scenario() const { return scenario_; }
  const ObstacleWorld& world() const { return scenario_.world; }
  // The scenario's controller settings with the form override applied.
  const ObstacleControllerSettings& settings() const { return settings_; }
  const RtiSolver& rti() const { return rti_; }
  // True plant state now (13): at t_{steps_done()}.
  const models::Crazyflie::State& state() const { return run_.x; }
  // The run so far (allocates: for reports, not for the loop); trajectories left empty.
  ObstacleRunResult result() const;

 protected:
  // Snapshots (Mode::save, Mode::restore): the NMPC's RTI state, the simulated vehicle and Run.
  void save_state(std::unique_ptr<ModeSnapshot::State>& state) const override;
  [[nodiscard]] RestoreStatus restore_state(const ModeSnapshot::State& state) override;
  // The instructor (Mode::instruct, SPEC §10): a gust on the simulated plant; an extra delay
  // between the vehicle and the NMPC, which then starts from the state that old (without one
  // it starts from the true state, as SPEC §5.3 does).
  [[nodiscard]] InstructorStatus apply_gust(const Eigen::Vector3d& force, double duration) override;
  [[nodiscard]] InstructorStatus apply_extra_delay(double delay) override;
  InstructorInForce in_force(std::int64_t k) const override;

 private:
  struct Saved;
  SetupResult check_scenario() const;
  void warm_start();
  void reset_telemetry();
  double plant_step(const models::Crazyflie::Input& u, double t, bool& violated);
  double check_distances(double t, bool& violated);
  void check_control_instant(double t);
  void set_reference_position(int k);
  void set_predictions();
  void set_channels(double step_min_distance, double tracking_error);

  ObstacleScenario scenario_;
  ObstacleControllerSettings settings_;
  std::optional<ObstacleAvoidanceOcp> problem_;  // rebuilt by setup(); rti_ points into it
  RtiSolver rti_;
  // The safe controller: hover-hold at run_.hold while the NMPC's plan is spent.
  models::Crazyflie model_{};
  TrackingLqr safe_lqr_;
  SimulatedVehicle<models::Crazyflie> simulated_;  // the plant
  int substeps_ = 15;           // plant RK4 steps per Δt
  int last_x_ = 0;              // last index of the reference states
  std::int64_t steps_total_ = 0;
  bool ready_ = false;  // setup() succeeded

  // What the flight changes step by step, besides the NMPC's state and the simulated
  // vehicle: a snapshot copies it.
  struct Run {
    Telemetry telemetry;
    models::Crazyflie::State x;  // 13: true plant state (the simulated vehicle's, at t_k)
    models::Crazyflie::State y;  // 13: what the NMPC starts from (x, or x delayed)
    SafetyNet safety;
    models::Crazyflie::State hold = models::Crazyflie::State::Zero();  // 13
    ReservedVector<double> rti_us;  // per step, RTI prepare + feedback [us]
    std::int64_t step = 0;
    bool finished = true;
    bool lost = false;
    double lost_at = -1.0;

    // Distances and tracking so far.
    double min_distance = 0.0;          // over substeps and obstacles
    double min_distance_time = 0.0;     // [s]
    int closest_obstacle = -1;
    double min_distance_control = 0.0;  // at the control instants
    int violations = 0;
    double sq_tracking = 0.0;           // Σ_k ‖p_k − p_ref,k‖²
    int qp_iterations_max = 0;
  };
  Run run_;
};

struct ObstacleRunOptions {
  std::optional<double> duration;        // overrides the scenario's
  std::optional<ObstacleForm> form;      // overrides the scenario's constraint_form
  bool keep_trajectory = false;          // fill ObstacleRunResult::positions
};

// Flies a loaded scenario along its reference to the end, through ObstacleMode. A failed setup
// returns steps = 0 and the reason in error.
ObstacleRunResult run_obstacle_avoidance(const ObstacleScenario& scenario,
                                         const ObstacleRunOptions& options = {});

}  // namespace mixpilot
