#pragma once
// Gamepads through SDL2's GameController API (SPEC §6): SDL's built-in mappings plus the
// user's (gamecontrollerdb.txt in the config folder), hot-plug, the first connected pad unless
// another is chosen. A device thread owns SDL's joystick state and hands the newest reading
// over wait-free. It samples the pad every millisecond and, in a flight, once more just before
// each control step reads it (the pilot says when: next_read_at()), so the reading a step
// uses is a fraction of a millisecond old: an axis change reaches the controller within one
// control period, without the CPU cost of polling that fast all the time. It also plays the
// haptic cue.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <vector>

#include "core/base/latest.hpp"
#include "input/mapping_wizard.hpp"
#include "input/source.hpp"

namespace mixpilot::input {

// The user's SDL mapping lines (gamecontrollerdb.txt) for this platform, by GUID.
struct MappingFile {
  std::unordered_map<std::string, std::string> by_guid;
  int malformed = 0;  // lines that are neither comments nor "GUID,name,..."
};
MappingFile parse_mappings(std::string_view text);

struct GamepadInfo {
  std::int32_t instance = -1;  // SDL joystick instance id
  std::string name;
  bool controller = false;  // SDL knows a mapping for it (else the mapping wizard can make one)
  std::string guid;
};

class Gamepad final : public StickSource {
 public:
  struct Options {
    std::string preferred;      // a device name to prefer ("" = the first connected)
    std::string mappings_file;  // SDL mapping lines to add ("" or missing = none)
    double poll_interval_s = 1e-3;
    double read_lead_s = 100e-6;  // the extra sample this long before a control read
  };

  Gamepad() = default;
  ~Gamepad() override { stop(); }
  Gamepad(const Gamepad&) = delete;
  Gamepad& operator=(const Gamepad&) = delete;

  // Initializes SDL's game controller subsystem and starts the device thread. A mappings file
  // that cannot be used (not a regular file, too large, unreadable) does not stop the pads:
  // SDL's built-in mappings still apply, and mappings_note() says why the file was left out.
  [[nodiscard]] bool start(const Options& options, std::string& error);
  const std::string& mappings_note() const { return mappings_note_; }
  void stop();

  std::string name() const override { return "gamepad"; }
  // The control thread's view (one reader).
  const StickReading& latest() override { return for_control_.read(); }
  void next_read_at(std::int64_t ns) override { next_read_ns_.store(ns, std::memory_order_relaxed); }
  // The UI's view (another reader).
  const StickReading& latest_for_ui() { return for_ui_.read(); }

  // Any thread: the rumble intensity in [0, 1] the pad should play. A cue not renewed for
  // kRumbleHoldNs stops, so a paused, ended or stalled flight never leaves the pad rumbling.
  void set_rumble(double intensity) {
    rumble_.store(float(intensity), std::memory_order_relaxed);
    rumble_set_ns_.store(steady_ns(), std::memory_order_relaxed);
  }
  static constexpr std::int64_t kRumbleHoldNs = 200'000'000;
  // Any thread: use this SDL instance from now on (-1: the first connected).
  void choose(std::int32_t instance) { wanted_.store(instance, std::memory_order_relaxed); }

  // The mapping wizard's view: the raw joystick `instance` (-1: none) as SDL's Joystick API
  // reports it, read with raw() by one reader (the UI).
  void watch(std::int32_t instance) { watched_.store(instance, std::memory_order_relaxed); }
  const RawJoystick& raw() { return raw_.read(); }
  // Adds an SDL mapping line now (the device thread applies it; a pad it names becomes usable
  // at once). mapping_status(): 0 nothing asked or pending, 1 added, -1 refused (with SDL's
  // reason in `error`).
  void add_mapping(const std::string& line);
  int mapping_status(std::string& error) const;

  // UI: every joystick SDL sees, and the one in use.
  std::vector<GamepadInfo> devices() const;
  std::string active_name() const;
  bool connected() const { return connected_.load(std::memory_order_relaxed); }
  // How many polls the device thread has made (tests wait for it to come up).
  std::uint64_t polls() const { return polls_.load(std::memory_order_relaxed); }

 private:
  void run();
  bool open_device(std::int32_t wanted);
  void close_device();
  void refresh_devices();
  void update_watch();
  bool apply_pending_mapping();  // true when one was applied
  void apply_user_mapping(int device_index);  // the user's line for its GUID, once

  Options options_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> connected_{false};
  std::atomic<float> rumble_{0.0f};
  std::atomic<std::int64_t> rumble_set_ns_{0};
  std::atomic<std::int64_t> next_read_ns_{0};
  std::atomic<std::int32_t> wanted_{-1};
  std::atomic<std::uint64_t> polls_{0};
  Latest<StickReading> for_control_, for_ui_;
  std::atomic<std::int32_t> watched_{-1};
  Latest<RawJoystick> raw_;
  mutable std::mutex mapping_mutex_;  // the UI's requests; never taken by the control thread
  std::string pending_mapping_, mapping_error_;
  int mapping_status_ = 0;

  // Device thread only.
  void* controller_ = nullptr;  // SDL_GameController*
  void* joystick_ = nullptr;    // SDL_Joystick* the wizard watches
  RawJoystick raw_reading_;
  std::int32_t instance_ = -1;
  StickReading reading_;
  float rumble_sent_ = 0.0f;
  std::int64_t rumble_sent_ns_ = 0;

  // The user's mapping lines by GUID, read once by start(); each is handed to SDL only when a
  // joystick with that GUID appears (SDL's own file loader searches its list for every line:
  // quadratic in the file's length).
  std::unordered_map<std::string, std::string> user_mappings_;
  std::string mappings_note_;

  mutable std::mutex devices_mutex_;  // the UI's list; never taken by the control thread
  std::vector<GamepadInfo> devices_;
  std::string active_;
};

}  // namespace mixpilot::input
