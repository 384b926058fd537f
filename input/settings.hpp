#pragma once
// How a person's device becomes a pilot command (SPEC §6): stick mode, angle mode, per-axis
// shaping, input loss, the haptic cue and the keyboard's ramp. Stored as TOML in the user's
// config directory (docs/input-settings.md); every value has a documented range and errors
// read `<file>:<line>:<col>: <key>: <what was expected>`.
#include <optional>
#include <string>
#include <string_view>

namespace mixpilot::input {

// One stick axis, applied in this order to a raw value in [-1, 1]: inversion, deadzone (the
// rest rescaled to [0, 1]), expo (x ↦ (1 − e)·x + e·x³), rate (a gain, clamped to [-1, 1]).
struct AxisSettings {
  double deadzone = 0.05;  // [0, 0.5]
  double expo = 0.3;       // [0, 1]
  double rate = 1.0;       // [0.1, 2]
  bool invert = false;
};

struct HapticSettings {
  bool enabled = true;
  double threshold = 0.5;  // λ ∈ (0, 1] below which the pad rumbles
  double strength = 0.8;   // [0, 1]: the intensity at λ = 0
};

struct InputSettings {
  int mode = 2;                    // stick mode 1–4 (Mode 2: thrust and yaw on the left stick)
  double max_tilt_deg = 30.0;      // angle mode: full stick = this roll / pitch, (0, 60]
  double thrust_range = 0.5;       // full thrust stick = hover thrust × (1 ± this), (0, 1]
  AxisSettings roll, pitch, thrust{0.05, 0.0, 1.0, false}, yaw;
  double input_timeout_s = 0.1;    // no sign of the device for longer: input lost, [0.02, 5]
  double recentre_tolerance = 0.1; // |stick| ≤ this on every axis counts as centred, (0, 0.5]
  double return_time_s = 1.0;      // the authority ramps 0 → 1 over this after re-centring
  HapticSettings haptic;
  double keyboard_ramp_s = 0.4;    // a held key reaches full deflection in this, [0.05, 5]
  std::string gamepad;             // preferred gamepad name ("" = the first connected)
};

// Reads settings from TOML text; missing keys keep their defaults. On failure returns nullopt
// with one line per problem in `error`.
[[nodiscard]] std::optional<InputSettings> parse_settings(std::string_view text,
                                                          const std::string& source_name,
                                                          std::string& error);
// The file at `path`; a missing file is not an error (defaults, `exists` false).
[[nodiscard]] std::optional<InputSettings> load_settings(const std::string& path, bool& exists,
                                                         std::string& error);
// TOML text that parse_settings() reads back to `s`.
std::string to_toml(const InputSettings& s);
// Writes `s` to `path` (a temporary file renamed over it, so a crash never leaves half a file).
// Replaces the user's file at `path` with `text`, atomically (a temporary beside it, then a
// rename), creating its folder when missing. The user's own config files only.
[[nodiscard]] bool save_user_file(const std::string& path, const std::string& text,
                                  std::string& error);
[[nodiscard]] bool save_settings(const std::string& path, const InputSettings& s,
                                 std::string& error);

// $XDG_CONFIG_HOME/mixpilot (default ~/.config/mixpilot): input.toml, gamecontrollerdb.txt.
// "" with `why` when the user has no home folder (core/scenario/data_files.hpp: never the
// current folder); the paths below are "" then too.
std::string config_dir(std::string* why = nullptr);
std::string default_settings_path(std::string* why = nullptr);
std::string user_mappings_path(std::string* why = nullptr);

}  // namespace mixpilot::input
