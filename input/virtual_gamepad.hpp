#pragma once
// A gamepad made of software: an SDL virtual joystick of the GameController type, so the real
// SDL path (Gamepad's device thread, the mappings, hot-plug, rumble) runs without hardware or
// display. Tests, demos and bug reports drive it from a script (`--gamepad-script FILE.csv`).
//
// Script format (CSV, '#' starts a comment, an optional header line `t,left_x,...`):
//   t, left_x, left_y, right_x, right_y [, left_trigger, right_trigger]
//     time [s] from the start of the flight, then SDL's GameController axes in [-1, 1]
//     (sticks: y down positive, as SDL reports them; triggers 0 … 1)
//   t, unplug        the pad disappears (SDL removes the device)
//   t, plug          it comes back
// Values hold until the next row.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace mixpilot::input {

// A script's times are at most a day.
inline constexpr double kMaxScriptSeconds = 86400.0;

struct ScriptRow {
  double t = 0;
  enum Kind { axes, unplug, plug } kind = axes;
  float values[6] = {0, 0, 0, 0, 0, 0};
};

// Parses a script; errors read `<file>:<line>: <what was expected>`.
[[nodiscard]] std::optional<std::vector<ScriptRow>> parse_script(const std::string& text,
                                                                 const std::string& name,
                                                                 std::string& error);
[[nodiscard]] std::optional<std::vector<ScriptRow>> load_script(const std::string& path,
                                                                std::string& error);

struct RumbleEvent {
  std::int64_t at_ns = 0;   // steady clock
  double intensity = 0.0;   // low-frequency motor, [0, 1]
};

class VirtualGamepad {
 public:
  VirtualGamepad() = default;
  ~VirtualGamepad();
  VirtualGamepad(const VirtualGamepad&) = delete;
  VirtualGamepad& operator=(const VirtualGamepad&) = delete;

  // Creates the device (SDL's joystick subsystem is started here if needed).
  [[nodiscard]] bool plug(std::string& error);
  void unplug();
  bool plugged() const { return joystick_ != nullptr; }
  // Sets one GameController axis (SDL_CONTROLLER_AXIS_*) to v ∈ [-1, 1].
  void set_axis(int axis, double v);

  // Plays a script on its own thread, its t = 0 being `start_ns` (steady clock). Each row's
  // wall-clock time of application is kept (applied()).
  void play(std::vector<ScriptRow> rows, std::int64_t start_ns);
  void stop();
  bool playing_done() const { return done_.load(); }
  // (row index, steady ns when it was applied), in order.
  std::vector<std::pair<std::size_t, std::int64_t>> applied() const;
  std::vector<RumbleEvent> rumbles() const;

 private:
  static int rumble_callback(void* self, std::uint16_t low, std::uint16_t high);

  void* joystick_ = nullptr;  // SDL_Joystick*
  int device_index_ = -1;
  bool sdl_started_ = false;
  std::thread player_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> done_{false};
  mutable std::mutex mutex_;
  std::vector<std::pair<std::size_t, std::int64_t>> applied_;
  std::vector<RumbleEvent> rumbles_;
};

}  // namespace mixpilot::input
