#include "core/modes/session.hpp"

#include <cmath>

namespace mixpilot {

bool Session::setup(const Scenario& scenario, PilotSource& pilot, std::string& error) {
  scenario_ = &scenario;
  pilot_ = &pilot;
  if (scenario.mode != "mixed_initiative" || scenario.model != "mikrokopter") {
    error = "session: only mode 'mixed_initiative' on model 'mikrokopter' is supported";
    return false;
  }
  dt_ = scenario.controller.dt;
  const double substeps = scenario.plant.rate_hz * dt_;
  substeps_ = int(std::lround(substeps));
  if (substeps_ < 1 || std::abs(substeps - substeps_) > 1e-9) {
    error = "session: plant.rate_hz × controller.dt must be a whole number of substeps";
    return false;
  }
  model_ = models::MikroKopter{};
  plant_ = IntegratorErk4<models::MikroKopter>(model_);
  if (!controller_.setup(model_, scenario.controller, scenario.arena, scenario.reference)) {
    error = "session: the controller settings do not form a valid OCP";
    return false;
  }
  x_ = model_.hover_state(scenario.reference.position(0.0));
  controller_.reset(x_);
  const int delay_steps = int(std::lround(scenario.plant.input_delay / dt_));
  u_delay_.assign(delay_steps + 1, model_.hover_input());
  rng_.seed(scenario.plant.seed);
  noise_.reset();
  step_ = 0;
  steps_total_ = std::int64_t(std::lround(scenario.duration / dt_));
  finished_ = false;
  lost_ = false;

  sample_ = TelemetrySample{};
  sample_.x = x_;
  sample_.x_measured = x_;
  sample_.u = model_.hover_input();
  sample_.predicted = &controller_.predicted_positions();
  sample_.predicted_reference = &controller_.reference_positions();
  return true;
}

// RK4 at the plant rate with the input held (ZOH) over the control period.
void Session::plant_step(const Eigen::VectorXd& u) {
  models::MikroKopter::State x = x_, xn;
  const models::MikroKopter::Input us = u;
  const double h = dt_ / substeps_;
  for (int s = 0; s < substeps_; ++s) {
    plant_.step(x, us, h, xn);
    x = xn;
  }
  x_ = x;
}

bool Session::step() {
  if (finished_) return false;
  const double t = step_ * dt_;
  TelemetrySample& s = sample_;
  s.step = step_;
  s.t = t;
  s.x = x_;
  s.x_measured = x_;
  if (scenario_->plant.position_noise > 0.0) {
    for (int i = 0; i < 3; ++i) s.x_measured(i) += scenario_->plant.position_noise * noise_(rng_);
  }
  if (!pilot_->command(step_, t, x_, s.pilot)) {
    finished_ = true;
    return false;
  }
  s.joy = pilot_->joy();
  controller_.step(t, s.x_measured, s.pilot);
  s.lambda = controller_.lambda();
  s.applied = controller_.applied_command();
  s.reference = scenario_->reference.position(t);
  s.stats = controller_.rti().stats();

  // The command enters the delay line; the rotors get the one sent input_delay ago.
  const std::size_t n = u_delay_.size();
  u_delay_[std::size_t(step_) % n] = controller_.control();
  s.u = u_delay_[std::size_t(step_ + 1) % n];
  for (TelemetrySink* sink : sinks_) sink->on_sample(s);

  plant_step(s.u);
  ++step_;
  if (!x_.allFinite()) {  // never hand a non-finite state to anyone
    x_ = s.x;
    lost_ = finished_ = true;
  }
  if (step_ >= steps_total_) finished_ = true;
  return true;
}

void Session::run() {
  while (step()) {
  }
}

}  // namespace mixpilot
