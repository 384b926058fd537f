#pragma once
// A session runs a scenario deterministically with a fixed step (issue 5): the plant (the model
// integrated with RK4 at ≥ 1 kHz, input held over the control period), the mixed-initiative
// controller at Δt, one pilot-input source, and a telemetry stream that every consumer (GUI,
// recorder, scorer) reads. The same code serves real-time runs (the caller paces step()) and
// as-fast-as-possible headless runs (run()).
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/numerics/integrator_erk4.hpp"
#include "core/control/mi_controller.hpp"
#include "core/control/pilot.hpp"
#include "core/scenario/scenario.hpp"

namespace mixpilot {

// One control step's worth of telemetry. Owned by the session and overwritten every step.
struct TelemetrySample {
  std::int64_t step = 0;
  double t = 0.0;                  // [s] at the start of the step
  Eigen::VectorXd x;               // nx: true plant state at t
  Eigen::VectorXd x_measured;      // nx: what the controller saw (with noise)
  PilotCommand pilot;              // the pilot's command ν^r
  const JoyInput* joy = nullptr;   // raw device input behind it, if any
  double lambda = 0.5;             // PH index used in this step
  Eigen::VectorXd u;               // nu: τ sent to the rotors
  PilotCommand applied;            // the MPC's stage-1 (φ, θ, Ω)
  Eigen::Vector3d reference{0, 0, 0};  // η^r(t)
  const Eigen::Matrix3Xd* predicted = nullptr;            // 3 x (N+1)
  const Eigen::Matrix3Xd* predicted_reference = nullptr;  // 3 x (N+1)
  RtiStats stats{};
};

class TelemetrySink {
 public:
  virtual ~TelemetrySink() = default;
  virtual void on_sample(const TelemetrySample& sample) = 0;
};

class Session {
 public:
  Session() = default;
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Prepares a session of `scenario` flown by `pilot` (both must outlive the session).
  // Returns false with a message when the scenario cannot be run.
  bool setup(const Scenario& scenario, PilotSource& pilot, std::string& error);
  void add_sink(TelemetrySink* sink) { sinks_.push_back(sink); }

  // One control step; false once the session is over (duration reached or pilot exhausted).
  bool step();
  // Steps until the session is over.
  void run();

  bool finished() const { return finished_; }
  // The plant state stopped being finite (the vehicle was lost); the session ended there.
  bool lost() const { return lost_; }
  std::int64_t steps_done() const { return step_; }
  std::int64_t steps_total() const { return steps_total_; }
  double dt() const { return dt_; }
  const Scenario& scenario() const { return *scenario_; }
  const TelemetrySample& last() const { return sample_; }
  const MiController& controller() const { return controller_; }
  const Eigen::VectorXd& state() const { return x_; }

 private:
  void plant_step(const Eigen::VectorXd& u);

  const Scenario* scenario_ = nullptr;
  PilotSource* pilot_ = nullptr;
  models::MikroKopter model_{};
  IntegratorErk4<models::MikroKopter> plant_{};
  MiController controller_;
  std::vector<TelemetrySink*> sinks_;
  TelemetrySample sample_;
  Eigen::VectorXd x_;                      // nx: true state
  std::vector<Eigen::VectorXd> u_delay_;   // ring buffer of commands in flight
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
  double dt_ = 0.015;
  int substeps_ = 15;
  std::int64_t step_ = 0;
  std::int64_t steps_total_ = 0;
  bool finished_ = false;
  bool lost_ = false;
};

}  // namespace mixpilot
