#include "input/mapping.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mixpilot::input {

double shape(double x, const AxisSettings& a) {
  x = std::clamp(a.invert ? -x : x, -1.0, 1.0);
  const double m = std::abs(x);
  if (m <= a.deadzone) return 0.0;
  const double r = (m - a.deadzone) / (1.0 - a.deadzone);
  const double e = (1.0 - a.expo) * r + a.expo * r * r * r;
  return std::clamp(std::copysign(e * a.rate, x), -1.0, 1.0);
}

double unshape(double y, const AxisSettings& a) {
  // shape() is odd and non-decreasing in |x| (strictly past the deadzone, until the clamp):
  // bisection on [0, 1] for |y|.
  const double target = std::abs(y);
  if (target == 0.0) return 0.0;
  AxisSettings plain = a;
  plain.invert = false;
  double lo = 0.0, hi = 1.0;
  if (shape(1.0, plain) <= target) {
    lo = hi;
  } else {
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (shape(mid, plain) < target ? lo : hi) = mid;
    }
  }
  const double x = std::copysign(hi, y);
  return a.invert ? -x : x;
}

Controls assign(const StickAxes& s, int mode) {
  switch (mode) {
    case 1: return {s.right_x, s.left_y, s.right_y, s.left_x};
    case 3: return {s.left_x, s.left_y, s.right_y, s.right_x};
    case 4: return {s.left_x, s.right_y, s.left_y, s.right_x};
    default: return {s.right_x, s.right_y, s.left_y, s.left_x};  // Mode 2
  }
}

StickAxes unassign(const Controls& c, int mode) {
  switch (mode) {
    case 1: return {c.yaw, c.pitch, c.roll, c.thrust};
    case 3: return {c.roll, c.pitch, c.yaw, c.thrust};
    case 4: return {c.roll, c.thrust, c.yaw, c.pitch};
    default: return {c.yaw, c.thrust, c.roll, c.pitch};  // Mode 2
  }
}

Controls controls(const StickAxes& s, const InputSettings& settings) {
  const Controls raw = assign(s, settings.mode);
  return {shape(raw.roll, settings.roll), shape(raw.pitch, settings.pitch),
          shape(raw.thrust, settings.thrust), shape(raw.yaw, settings.yaw)};
}

void to_command(const Controls& c, const InputSettings& settings, double hover_speed,
                PilotCommand& out) {
  const double tilt = settings.max_tilt_deg * std::numbers::pi / 180.0;
  out.roll = c.roll * tilt;
  out.pitch = c.pitch * tilt;
  out.rotor_speed.setConstant(hover_speed *
                              std::sqrt(std::max(0.0, 1.0 + settings.thrust_range * c.thrust)));
}

Controls controls_for(const PilotCommand& c, const InputSettings& settings, double hover_speed) {
  const double tilt = settings.max_tilt_deg * std::numbers::pi / 180.0;
  const double w = c.rotor_speed.mean() / hover_speed;
  return {std::clamp(c.roll / tilt, -1.0, 1.0), std::clamp(c.pitch / tilt, -1.0, 1.0),
          std::clamp((w * w - 1.0) / settings.thrust_range, -1.0, 1.0), 0.0};
}

bool centred(const Controls& c, double tolerance) {
  return std::abs(c.roll) <= tolerance && std::abs(c.pitch) <= tolerance &&
         std::abs(c.thrust) <= tolerance && std::abs(c.yaw) <= tolerance;
}

double rumble_intensity(double lambda, const HapticSettings& h) {
  if (!h.enabled || !(lambda < h.threshold)) return 0.0;
  return h.strength * std::clamp((h.threshold - lambda) / h.threshold, 0.0, 1.0);
}

}  // namespace mixpilot::input
