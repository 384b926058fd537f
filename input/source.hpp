#pragma once
// A device that yields stick positions: a gamepad (SDL), the keyboard, a network peer. The
// control thread reads it through latest(), which never waits (SPEC §6, the real-time rule).
#include <cstdint>
#include <string>

#include "core/control/pilot.hpp"
#include "input/mapping.hpp"

namespace mixpilot::input {

struct StickReading {
  JoyInput joy;                // the raw axes and buttons, as recorded (sensor_msgs/Joy)
  StickAxes sticks;            // the four stick axes, up and right positive
  std::int64_t changed_ns = 0;  // steady clock when the input last changed
  std::int64_t alive_ns = 0;    // steady clock of the device's last sign of life
  std::uint64_t serial = 0;     // counts changes
  std::int64_t stamp_ns = 0;    // the sender's stamp (system clock; network peers), 0 none
  bool connected = false;
};

class StickSource {
 public:
  virtual ~StickSource() = default;
  virtual std::string name() const = 0;  // "gamepad", "keyboard", ...
  // Called by the control thread once per step, before latest(): sources that integrate
  // something per step (the keyboard's ramp) do it here. Never blocks.
  virtual void advance(double dt) { (void)dt; }
  // The newest reading; never blocks.
  virtual const StickReading& latest() = 0;
  // Control thread, after each read: when the next read is due (steady ns), so a polled device
  // can take a fresh sample just before it. Never blocks.
  virtual void next_read_at(std::int64_t ns) { (void)ns; }
};

std::int64_t steady_ns();

}  // namespace mixpilot::input
