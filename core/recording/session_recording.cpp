#include "core/recording/session_recording.hpp"

#include <cmath>

namespace mixpilot {

bool RecordingSink::open(const std::string& path, const Scenario& scenario,
                         const std::string& pilot_name, std::string& error) {
  SessionInfo info;
  info.scenario = scenario.source_text;
  info.scenario_path = scenario.source_path;
  info.seed = scenario.plant.seed;
  info.pilot = pilot_name;
  pilot_name_ = pilot_name;
  const auto period_ns = std::uint64_t(std::llround(scenario.controller.dt * 1e9));
  return recorder_.open(path, period_ns, info, error);
}

void RecordingSink::on_sample(const TelemetrySample& s) {
  const auto step = std::uint64_t(s.step);
  const RosTime stamp = ros_time_from_ns(recorder_.log_time_ns(step));
  if (s.joy) {
    joy_.stamp = stamp;
    joy_.axes.assign(s.joy->axes.begin(), s.joy->axes.begin() + s.joy->num_axes);
    joy_.buttons.assign(s.joy->buttons.begin(), s.joy->buttons.begin() + s.joy->num_buttons);
    recorder_.record_joy(step, joy_);
  }
  pilot_.stamp = stamp;
  pilot_.step = step;
  pilot_.roll = s.pilot.roll;
  pilot_.pitch = s.pilot.pitch;
  for (int i = 0; i < 4; ++i) pilot_.rotor_speed[std::size_t(i)] = s.pilot.rotor_speed(i);
  pilot_.source = pilot_name_;
  recorder_.record_pilot(pilot_);

  state_.stamp = stamp;
  state_.step = step;
  state_.x.assign(s.x.data(), s.x.data() + s.x.size());
  recorder_.record_state(state_);
  recorder_.record_lambda(step, s.lambda);

  applied_.stamp = stamp;
  applied_.step = step;
  applied_.u.assign(s.u.data(), s.u.data() + s.u.size());
  applied_.roll = s.applied.roll;
  applied_.pitch = s.applied.pitch;
  for (int i = 0; i < 4; ++i) applied_.rotor_speed[std::size_t(i)] = s.applied.rotor_speed(i);
  recorder_.record_applied(applied_);

  solver_.stamp = stamp;
  solver_.step = step;
  solver_.status = std::uint8_t(s.stats.status);
  solver_.qp_iterations = std::uint32_t(s.stats.qp_iterations);
  solver_.integration_us = s.stats.integration_us;
  solver_.linearization_us = s.stats.linearization_us;
  solver_.qp_us = s.stats.qp_us;
  solver_.total_us = s.stats.total_us;
  solver_.fallback = s.stats.status == RtiStatus::fallback;
  recorder_.record_solver(solver_);

  if (s.predicted && s.predicted_reference) {
    prediction_.stamp = stamp;
    prediction_.step = step;
    prediction_.position.assign(s.predicted->data(), s.predicted->data() + s.predicted->size());
    prediction_.reference.assign(s.predicted_reference->data(),
                                 s.predicted_reference->data() + s.predicted_reference->size());
    recorder_.record_prediction(prediction_);
  }
}

bool RecordingSink::close(std::string& error) { return recorder_.close(error); }

bool ReplayPilot::command(std::int64_t step, double, const Eigen::VectorXd&, PilotCommand& out) {
  if (step < 0 || step >= std::int64_t(commands_.size())) return false;
  const PilotCommandMsg& m = commands_[std::size_t(step)];
  if (m.step != std::uint64_t(step)) return false;  // a gap: the recording is not contiguous
  out.roll = m.roll;
  out.pitch = m.pitch;
  for (int i = 0; i < 4; ++i) out.rotor_speed(i) = m.rotor_speed[std::size_t(i)];
  return true;
}

}  // namespace mixpilot
