#include "input/settings.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "core/base/output_file.hpp"
#include "core/scenario/data_files.hpp"
#include "core/base/toml_read.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot::input {

namespace {

using namespace toml_read;

// The documented ranges (docs/input-settings.md).
constexpr IntRange kMode{1, 4};
constexpr Range kMaxTilt = left_open(0, 60);         // [deg]
constexpr Range kThrustRange = left_open(0, 1);
constexpr Range kDeadzone = closed(0, 0.5);
constexpr Range kExpo = closed(0, 1);
constexpr Range kRate = closed(0.1, 2);
constexpr Range kTimeout = closed(0.02, 5);          // [s]
constexpr Range kRecentre = left_open(0, 0.5);
constexpr Range kReturnTime = closed(0, 10);         // [s]
constexpr Range kThreshold = left_open(0, 1);
constexpr Range kStrength = closed(0, 1);
constexpr Range kKeyboardRamp = closed(0.05, 5);     // [s]

void read_axis(Section a, AxisSettings& s) {
  a.num("deadzone", s.deadzone, kDeadzone);
  a.num("expo", s.expo, kExpo);
  a.num("rate", s.rate, kRate);
  a.boolean("invert", s.invert);
  a.finish();
}

}  // namespace

std::optional<InputSettings> parse_settings(std::string_view text, const std::string& source_name,
                                            std::string& error) {
  Diagnostics d(source_name);
  toml::table root;
  if (!parse_toml(text, source_name, d, root)) {
    error = d.str();
    return std::nullopt;
  }
  InputSettings s;
  Section top(d, &root, "", Pos{});
  top.integer("mode", s.mode, kMode);
  top.num("max_tilt_deg", s.max_tilt_deg, kMaxTilt);
  top.num("thrust_range", s.thrust_range, kThrustRange);
  top.num("input_timeout_s", s.input_timeout_s, kTimeout);
  top.num("recentre_tolerance", s.recentre_tolerance, kRecentre);
  top.num("return_time_s", s.return_time_s, kReturnTime);
  top.num("keyboard_ramp_s", s.keyboard_ramp_s, kKeyboardRamp);
  if (const toml::node* n = top.take("gamepad", false, "a string")) {
    if (!n->is_string())
      d.add(pos_of(n->source()), "gamepad", "expected a string, got " + describe(*n));
    else if (escape_controls(n->as_string()->get()) != n->as_string()->get())
      d.add(pos_of(n->source()), "gamepad",
            "expected a name without control characters, got " + describe(*n));
    else
      s.gamepad = n->as_string()->get();
  }
  Section axes = top.sub("axes");
  read_axis(axes.sub("roll"), s.roll);
  read_axis(axes.sub("pitch"), s.pitch);
  read_axis(axes.sub("thrust"), s.thrust);
  read_axis(axes.sub("yaw"), s.yaw);
  axes.finish();
  Section haptic = top.sub("haptic");
  haptic.boolean("enabled", s.haptic.enabled);
  haptic.num("threshold", s.haptic.threshold, kThreshold);
  haptic.num("strength", s.haptic.strength, kStrength);
  haptic.finish();
  top.finish();
  if (!d.empty()) {
    error = d.str();
    return std::nullopt;
  }
  return s;
}

std::optional<InputSettings> load_settings(const std::string& path, bool& exists,
                                           std::string& error) {
  // Only a name that is not there at all is "no file": a symbolic-link loop, a dangling link or
  // an unreadable folder is an error the reader names.
  struct stat st {};
  exists = !(::lstat(path.c_str(), &st) != 0 && (errno == ENOENT || errno == ENOTDIR) &&
             !path.empty());
  if (!exists) return InputSettings{};
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_settings(text, path, error);
}

std::string to_toml(const InputSettings& s) {
  std::string out =
      "# mixpilot input settings (docs/input-settings.md). Edited by the app's settings panel;\n"
      "# by hand works too: missing keys keep their defaults.\n";
  const auto line = [&](const char* key, const std::string& value) {
    out += std::string(key) + " = " + value + "\n";
  };
  const auto num = [](double v) { return fmt(v); };
  const auto flag = [](bool b) { return std::string(b ? "true" : "false"); };
  const auto quoted = [](const std::string& v) {
    std::string q = "\"";
    for (char c : v) {
      if (c == '"' || c == '\\') q += '\\';
      q += c;
    }
    return q + '"';
  };
  line("mode", std::to_string(s.mode));
  line("max_tilt_deg", num(s.max_tilt_deg));
  line("thrust_range", num(s.thrust_range));
  line("input_timeout_s", num(s.input_timeout_s));
  line("recentre_tolerance", num(s.recentre_tolerance));
  line("return_time_s", num(s.return_time_s));
  line("keyboard_ramp_s", num(s.keyboard_ramp_s));
  line("gamepad", quoted(s.gamepad));
  const std::pair<const char*, const AxisSettings*> axes[] = {
      {"roll", &s.roll}, {"pitch", &s.pitch}, {"thrust", &s.thrust}, {"yaw", &s.yaw}};
  for (const auto& [name, a] : axes) {
    out += std::string("\n[axes.") + name + "]\n";
    line("deadzone", num(a->deadzone));
    line("expo", num(a->expo));
    line("rate", num(a->rate));
    line("invert", flag(a->invert));
  }
  out += "\n[haptic]\n";
  line("enabled", flag(s.haptic.enabled));
  line("threshold", num(s.haptic.threshold));
  line("strength", num(s.haptic.strength));
  return out;
}

bool save_user_file(const std::string& path, const std::string& text, std::string& error) {
  if (path.empty()) {  // the user's config folder is unknown (no home folder)
    std::string why;
    config_dir(&why);
    error = "nowhere to save: " + why;
    return false;
  }
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  if (ec) {
    error = path + ": cannot create its folder (" + ec.message() + ")";
    return false;
  }
  OutputFile f;
  // Read-modify-write of the user's own file: replacing what was read is the point.
  if (!f.open(path, /*overwrite=*/true, error, InputReplacement::allowed)) return false;
  if (std::fwrite(text.data(), 1, text.size(), f.stream()) != text.size()) {
    error = path + ": cannot write (" + std::strerror(errno) + ")";
    f.discard();
    return false;
  }
  return f.commit(error);
}

bool save_settings(const std::string& path, const InputSettings& s, std::string& error) {
  return save_user_file(path, to_toml(s), error);
}

std::string config_dir(std::string* why) {
  const std::string base = xdg_dir("XDG_CONFIG_HOME", ".config", why);
  return base.empty() ? base : base + "/mixpilot";
}
std::string default_settings_path(std::string* why) {
  const std::string dir = config_dir(why);
  return dir.empty() ? dir : dir + "/input.toml";
}
std::string user_mappings_path(std::string* why) {
  const std::string dir = config_dir(why);
  return dir.empty() ? dir : dir + "/gamecontrollerdb.txt";
}

}  // namespace mixpilot::input
