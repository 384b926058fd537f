#pragma once
// The keyboard as a pair of sticks (SPEC §6: for people without a gamepad). Keys ramp the
// sticks instead of stepping them: a held key moves its stick toward full deflection at
// 1 / keyboard_ramp_s per second, a released one back to centre at the same rate.
//   W / S        thrust up / down      A / D       yaw left / right
//   ↑ / ↓        pitch forward / back  ← / →       roll left / right
// The keys name controls, so they work in every stick mode: the ramped controls are placed on
// the sticks of the chosen mode, and the mapping then reads them back as for a gamepad.
// The UI thread reports key changes with set_key(); the control thread advances the ramp once
// per control step, so the same key timeline gives the same commands.
#include <atomic>

#include "input/settings.hpp"
#include "input/source.hpp"

namespace mixpilot::input {

enum class Key { thrust_up, thrust_down, yaw_left, yaw_right, pitch_forward, pitch_back,
                 roll_left, roll_right, count };

class KeyboardSource final : public StickSource {
 public:
  explicit KeyboardSource(const InputSettings& settings);
  std::string name() const override { return "keyboard"; }
  // Any thread: a key went down or up.
  void set_key(Key k, bool down) { keys_[int(k)].store(down, std::memory_order_relaxed); }
  bool key(Key k) const { return keys_[int(k)].load(std::memory_order_relaxed); }
  // Control thread.
  void advance(double dt) override;
  const StickReading& latest() override { return reading_; }

 private:
  std::atomic<bool> keys_[int(Key::count)]{};
  double rate_;  // stick units per second
  int mode_;
  Controls held_;  // the ramped controls, before shaping
  StickReading reading_;
};

}  // namespace mixpilot::input
