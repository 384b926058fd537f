#pragma once
// A person's device as the mixed-initiative pilot (SPEC §6): sticks → ν^r through the input
// settings, and the input-loss rule. The device is lost when it is disconnected or shows no
// sign of life for longer than the timeout; from that step the command grants no authority
// (the controller uses min(λ, 0): the planner flies). When the device is back, the authority
// stays 0 until the sticks have read centred for kRecentreHoldS, then ramps linearly to 1 over
// return_time_s, so the commanded attitude never jumps. The state and the authority are part of every command, so
// recordings replay them exactly.
#include <cstdint>
#include <string>

#include "core/control/pilot.hpp"
#include "input/settings.hpp"
#include "input/source.hpp"

namespace mixpilot::input {

// How long the sticks must read centred, without a break, before a device that is back gets
// the authority again [s].
inline constexpr double kRecentreHoldS = 0.1;

class DevicePilot final : public PilotSource {
 public:
  // `source` outlives the pilot. `dt`: the control period; `hover_speed`: Ω_hover.
  DevicePilot(StickSource& source, const InputSettings& settings, double dt, double hover_speed);

  std::string name() const override { return source_.name(); }
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override;
  const JoyInput* joy() const override { return &joy_; }
  // The instructor's input loss: the device counts as absent before `until_step`.
  [[nodiscard]] bool lose_input(std::int64_t until_step) override {
    lost_until_ = until_step;
    return true;
  }

  InputState state() const { return state_; }
  // The reading behind the last command (what the test of latency correlates).
  const StickReading& reading() const { return reading_; }
  // Steady ns of the last read (the controller uses that reading in this step).
  std::int64_t read_ns() const { return read_ns_; }

 private:
  StickSource& source_;
  InputSettings settings_;
  double dt_;
  double hover_speed_;
  JoyInput joy_;
  StickReading reading_;
  InputState state_ = InputState::ok;
  double authority_ = 1.0;
  std::int64_t returning_steps_ = 0;  // steps since the sticks were re-centred
  std::int64_t centred_steps_ = 0;    // consecutive steps the sticks have read centred
  std::int64_t read_ns_ = 0;
  std::int64_t lost_until_ = -1;  // the instructor's input loss: absent before this step
};

}  // namespace mixpilot::input
