#include "input/device_pilot.hpp"

#include <algorithm>
#include <chrono>

namespace mixpilot::input {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

DevicePilot::DevicePilot(StickSource& source, const InputSettings& settings, double dt,
                         double hover_speed)
    : source_(source), settings_(settings), dt_(dt), hover_speed_(hover_speed) {}

bool DevicePilot::command(std::int64_t step, double, const Eigen::VectorXd&, PilotCommand& out) {
  source_.advance(dt_);
  read_ns_ = steady_ns();
  reading_ = source_.latest();
  source_.next_read_at(read_ns_ + std::int64_t(dt_ * 1e9));
  joy_ = reading_.joy;
  const std::int64_t timeout_ns = std::int64_t(settings_.input_timeout_s * 1e9);
  const bool present = reading_.connected && steady_ns() - reading_.alive_ns <= timeout_ns &&
                       step >= lost_until_;
  const Controls c = controls(reading_.sticks, settings_);

  if (!present) {
    state_ = InputState::lost;
    authority_ = 0.0;
  } else if (state_ == InputState::lost || state_ == InputState::recentre) {
    // Back: the sticks must read centred for kRecentreHoldS on end. A device's first reports
    // after it is plugged in can read centred before its sticks do, and a pilot still holding
    // a stick would then get the authority back deflected.
    if (state_ == InputState::lost) centred_steps_ = 0;
    centred_steps_ = centred(c, settings_.recentre_tolerance) ? centred_steps_ + 1 : 0;
    state_ = double(centred_steps_) * dt_ >= kRecentreHoldS - 1e-9 * dt_ ? InputState::returning
                                                                         : InputState::recentre;
    returning_steps_ = 0;
  }
  if (state_ == InputState::returning) {
    // A linear ramp counted in steps, so it ends exactly after return_time_s.
    ++returning_steps_;
    const double ramp = double(returning_steps_) * dt_;
    authority_ = ramp >= settings_.return_time_s - 1e-9 * dt_ ? 1.0 : ramp / settings_.return_time_s;
    if (authority_ >= 1.0) {
      authority_ = 1.0;
      state_ = InputState::ok;
    }
  }
  if (state_ == InputState::lost) {
    to_command(Controls{}, settings_, hover_speed_, out);  // neutral; carries no weight
  } else {
    to_command(c, settings_, hover_speed_, out);
  }
  out.authority = authority_;
  out.input = state_;
  return true;
}

}  // namespace mixpilot::input
