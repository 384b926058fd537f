#include "input/keyboard.hpp"

#include <algorithm>

namespace mixpilot::input {

KeyboardSource::KeyboardSource(const InputSettings& settings)
    : rate_(1.0 / settings.keyboard_ramp_s), mode_(settings.mode) {
  reading_.connected = true;
  reading_.joy.num_axes = 4;
  reading_.alive_ns = steady_ns();
}

void KeyboardSource::advance(double dt) {
  const auto toward = [&](double& v, Key plus, Key minus) {
    const double target = double(key(plus)) - double(key(minus));
    const double step = rate_ * dt;
    v = v < target ? std::min(target, v + step) : std::max(target, v - step);
  };
  const Controls before = held_;
  toward(held_.thrust, Key::thrust_up, Key::thrust_down);
  toward(held_.yaw, Key::yaw_right, Key::yaw_left);
  toward(held_.pitch, Key::pitch_forward, Key::pitch_back);
  toward(held_.roll, Key::roll_right, Key::roll_left);
  const StickAxes& s = reading_.sticks = unassign(held_, mode_);
  const std::int64_t now = steady_ns();
  reading_.alive_ns = now;
  if (held_.roll != before.roll || held_.pitch != before.pitch ||
      held_.thrust != before.thrust || held_.yaw != before.yaw) {
    reading_.changed_ns = now;
    ++reading_.serial;
  }
  // Joy axes as a gamepad reports them (SDL: y down positive).
  reading_.joy.axes = {float(s.left_x), float(-s.left_y), float(s.right_x), float(-s.right_y)};
}

}  // namespace mixpilot::input
