#pragma once
// Sticks → the pilot's command ν^r = (φ_h, θ_h, Ω_h) (SPEC §6, angle mode).
//
// A gamepad's two sticks are read through SDL's GameController axes, normalized to [-1, 1]
// with up and right positive. The stick mode assigns them to roll, pitch, thrust and yaw:
//   Mode 1: left = pitch (vertical) + yaw,   right = thrust (vertical) + roll
//   Mode 2: left = thrust (vertical) + yaw,  right = pitch (vertical) + roll   (default)
//   Mode 3: left = pitch (vertical) + roll,  right = thrust (vertical) + yaw
//   Mode 4: left = thrust (vertical) + roll, right = pitch (vertical) + yaw
// Each axis is shaped (AxisSettings), then
//   φ_h = roll · max_tilt        (stick right: roll right, φ > 0 accelerates toward −y_b)
//   θ_h = pitch · max_tilt       (stick forward: θ > 0 accelerates along +x_b)
//   F_z,h = F_hover · (1 + thrust_range · thrust),  Ω_h = √(F_z,h / 4 C_T) · 1₄
//         = Ω_hover · √(1 + thrust_range · thrust) · 1₄          (Remark 3)
// The thesis's ν has no yaw: the yaw axis is read, shaped and recorded (in the Joy message)
// but does not enter ν^r, whose heading reference stays ψ = 0 (SPEC §5.4's e), so a flight
// with a gamepad is the thesis formulation.
#include "core/control/pilot.hpp"
#include "input/settings.hpp"

namespace mixpilot::input {

// The four stick axes, [-1, 1], up and right positive.
struct StickAxes {
  double left_x = 0, left_y = 0, right_x = 0, right_y = 0;
};

// The four controls after the stick mode, each in [-1, 1].
struct Controls {
  double roll = 0, pitch = 0, thrust = 0, yaw = 0;
};

// Inversion, deadzone, expo, rate (settings.hpp); the result is clamped to [-1, 1].
double shape(double x, const AxisSettings& a);
// The raw value whose shape() is y (the inverse on the monotone part; for scripts that play
// a recorded command through the real mapping). y outside the reachable range is clamped.
double unshape(double y, const AxisSettings& a);

Controls assign(const StickAxes& s, int mode);
StickAxes unassign(const Controls& c, int mode);

// Raw sticks → shaped controls → command (authority and input state untouched).
Controls controls(const StickAxes& s, const InputSettings& settings);
void to_command(const Controls& c, const InputSettings& settings, double hover_speed,
                PilotCommand& out);
// The shaped controls that give command `c` (roll, pitch and the mean rotor speed).
Controls controls_for(const PilotCommand& c, const InputSettings& settings, double hover_speed);

// Every shaped control within `tolerance` of centre.
bool centred(const Controls& c, double tolerance);

// The haptic cue: intensity in [0, 1] for λ, growing linearly from 0 at the threshold to the
// strength at λ = 0; 0 when switched off.
double rumble_intensity(double lambda, const HapticSettings& h);

}  // namespace mixpilot::input
