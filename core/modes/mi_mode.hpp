#pragma once
// The mixed-initiative mode (SPEC §5.4): the MikroKopter plant (RK4 at plant.rate_hz, input held
// over the control period, optional input delay and position noise: core/modes/
// simulated_vehicle.hpp, hovering until the first command acts), the mixed-initiative
// controller at Δt, and one pilot-input source (emulated pilot, recording, device). Its metrics
// are the score (core/modes/score.hpp), kept up to date step by step.
//
// With a remote vehicle (set_vehicle(), core/modes/linked_vehicle.hpp) the plant runs elsewhere:
// each step starts from the vehicle's newest state predicted over the estimated round-trip
// time (SPEC §5.2 with the MikroKopter model), the command goes out at once (the link is the
// delay line). The prediction is what is known of the vehicle at t_k: the pilot sees it and
// the score takes it.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/hover_lqr.hpp"
#include "core/control/mi_controller.hpp"
#include "core/control/pilot.hpp"
#include "core/modes/linked_vehicle.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/safety_net.hpp"
#include "core/modes/score.hpp"
#include "core/modes/simulated_vehicle.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/scenario/scenario.hpp"

namespace mixpilot {

class MiMode final : public Mode {
 public:
  MiMode() = default;
  MiMode(const MiMode&) = delete;  // the controller and the scorer point into this object
  MiMode& operator=(const MiMode&) = delete;

  // Prepares a flight of `scenario` by `pilot`. Fails with the reason when the scenario cannot
  // be flown (wrong mode or model, substeps, an invalid OCP).
  SetupResult setup(Scenario scenario, std::unique_ptr<PilotSource> pilot);

  ModeKind kind() const override { return ModeKind::mixed_initiative; }
  const std::string& scenario_name() const override { return scenario_.name; }
  double dt() const override { return dt_; }
  std::int64_t steps_total() const override { return steps_total_; }
  std::int64_t steps_done() const override { return run_.step; }
  // Ends early (returning false) when the pilot source has nothing more to give.
  [[nodiscard]] bool step() override;
  bool finished() const override { return run_.finished; }
  bool lost() const override { return run_.lost; }
  double lost_at() const override { return run_.lost_at; }
  const Telemetry& telemetry() const override { return run_.telemetry; }
  void set_deadline_us(double d) override { controller_.rti().set_deadline_us(d); }
  RtiSolver* rti_solver() override { return &controller_.rti(); }
  // Before the first step the telemetry takes the new bounds and the λ they leave the first
  // step (what READY shows).
  [[nodiscard]] bool set_authority_bounds(const AuthorityBounds& bounds) override;
  AuthorityBounds authority_bounds() const override { return controller_.bounds(); }
  // The score; with a remote vehicle also rtt_s (the median round-trip sample) and
  // rtt_estimated_s (the final estimate).
  InstructorStatus accepts(InstructorCommandKind kind) const override {
    const bool plant = kind == InstructorCommandKind::gust || kind == InstructorCommandKind::extra_delay;
    return plant && remote_.attached() ? InstructorStatus::remote_vehicle : InstructorStatus::applied;
  }
  Metrics metrics() const override;
  std::string summary() const override;
  ModeView view() const override;
  ModeIdentity identity() const override;
  Metrics replayed_metrics(const std::vector<double>& recorded_solve_us) const override;

  [[nodiscard]] bool set_vehicle(VehicleLink* link) override {
    remote_.attach(link);
    return true;
  }
  VehicleStateSpec remote_state() const override;
  const VehicleFeed& vehicle_feed() const { return remote_.feed(); }

  Score score() const { return scorer_.finish(); }
  const Scenario& scenario() const { return scenario_; }
  const models::MikroKopter& model() const { return model_; }
  const PilotSource& pilot() const { return *pilot_; }
  const MiController& controller() const { return controller_; }
  const SafetyNet& safety_net() const { return run_.safety; }
  const Eigen::VectorXd& state() const { return run_.x; }

 protected:
  // Snapshots (Mode::save, Mode::restore): the MPC's RTI state and outputs, the score's sums,
  // Run, the simulated vehicle and the pilot source's state. With a remote vehicle they refuse.
  void save_state(std::unique_ptr<ModeSnapshot::State>& state) const override;
  [[nodiscard]] RestoreStatus restore_state(const ModeSnapshot::State& state) override;
  // Fly from here: the same, but the pilot source takes over from the present
  // (PilotSource::take_over) and the score restarts at the snapshot's step.
  [[nodiscard]] RestoreStatus take_over_state(const ModeSnapshot::State& state) override;

  // The instructor (Mode::instruct, SPEC §10): a gust on the simulated plant; an extra delay
  // on the measurement the controller starts from (core/modes/simulated_vehicle.hpp; the
  // pilot sees the vehicle as it is); an input loss that the pilot source handles when it is a
  // device or a recording (PilotSource::lose_input), else the mode: lost (neutral command,
  // authority 0) for the duration, then the authority ramps back over kInputReturnS, as a
  // device's does once its sticks are centred (an emulated pilot has no sticks to centre).
  // With a remote vehicle the gust and the delay are refused.
  [[nodiscard]] InstructorStatus apply_gust(const Eigen::Vector3d& force, double duration) override;
  [[nodiscard]] InstructorStatus apply_extra_delay(double delay) override;
  [[nodiscard]] InstructorStatus apply_input_loss(double duration) override;
  InstructorInForce in_force(std::int64_t k) const override;

 private:
  struct Saved;
  // Whether a saved state can be put back into this mode (ok), or why not, its pilot's state
  // aside; put_back() then puts it back, all but the pilot's state.
  RestoreStatus check_saved(const Saved& s) const;
  void put_back(const Saved& s);
  bool left_the_world() const;
  void measure(double t);
  void measure_remote(double t);
  void set_reference(double t);
  void set_channels();
  // Before the first step: the telemetry says what the flight starts with (λ of its first
  // step, the initial λ within the instructor's bounds, and the bounds); nothing after.
  void preview_first_step();
  void lose_input(PilotCommand& pilot) const;

  Scenario scenario_;
  std::unique_ptr<PilotSource> pilot_;
  models::MikroKopter model_{};
  MiController controller_;
  // The safe controller: hover-hold at run_.hold while the MPC's plan is spent.
  HoverLqr hover_;
  ScoreAccumulator scorer_;  // sized in setup() for the whole flight
  double dt_ = 0.015;
  int substeps_ = 15;
  std::int64_t steps_total_ = 0;

  // What the flight changes step by step, besides the states of the controller, the score,
  // the pilot and the simulated vehicle: a snapshot copies it.
  struct Run {
    Telemetry telemetry;
    Eigen::VectorXd x;  // nx: the vehicle's state at t_k (simulated: true; remote: predicted)
    SafetyNet safety;
    Eigen::Vector3d hold = Eigen::Vector3d::Zero();  // where the safe controller holds
    models::MikroKopter::Input u_safe = models::MikroKopter::Input::Zero();  // nu
    Eigen::VectorXd command;  // nu: the step's command (the MPC's or the safe controller's)
    std::int64_t step = 0;
    bool finished = false;
    bool lost = false;
    double lost_at = -1.0;
    const char* lost_reason = "";
    // The instructor's input loss: lost before step loss_until (−1: none); loss_rule: the mode
    // applies SPEC §6's rule itself (the pilot source has no device).
    std::int64_t loss_until = -1;
    bool loss_rule = false;
  };
  Run run_;

  SimulatedVehicle<models::MikroKopter> simulated_;  // flown unless a remote one is attached
  LinkedVehicle<models::MikroKopter> remote_;        // flown when attached (set_vehicle())
};

// [s] how long the authority takes to come back after an instructor's input loss, for a pilot
// without a device (the input settings' default return time, docs/input-settings.md).
inline constexpr double kInputReturnS = 1.0;

// The scenario's emulated pilot of that name: a profile of the scenario's [pilots], or
// "reckless". Fails with the known names.
std::unique_ptr<PilotSource> make_scenario_pilot(const Scenario& scenario, const std::string& name,
                                                 std::string& error);

}  // namespace mixpilot
