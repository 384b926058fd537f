#include "app/window_settings.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "input/settings.hpp"

namespace mixpilot::cli {

std::string default_window_settings_path() {
  const std::string dir = input::config_dir();
  return dir.empty() ? std::string() : dir + "/window.toml";
}

WindowSettings load_window_settings(const std::string& given, std::string& note) {
  WindowSettings s;
  const std::string path = given.empty() ? default_window_settings_path() : given;
  std::error_code ec;
  if (path.empty() || !std::filesystem::exists(path, ec)) return s;
  const std::string defaults = "; the window's defaults are used";
  if (!std::filesystem::is_regular_file(path, ec)) {
    note = path + ": not a settings file (a folder or a device)" + defaults;
    return s;
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) {
    note = path + ": cannot be read" + defaults;
    return s;
  }
  toml::table t;
  try {
    t = toml::parse(text.str(), path);
  } catch (const toml::parse_error& e) {
    note = path + ":" + std::to_string(e.source().begin.line) + ":" +
           std::to_string(e.source().begin.column) + ": " + std::string(e.description()) + defaults;
    return s;
  }
  const auto where = [&](const toml::node& n) {
    return path + ":" + std::to_string(n.source().begin.line) + ":" +
           std::to_string(n.source().begin.column) + ": ";
  };
  WindowSettings read;
  for (const auto& [key, node] : t) {
    const std::string k(key.str());
    if (k == "text_scale") {
      const std::optional<double> v = node.value<double>();
      if (!v || !std::isfinite(*v) || *v < kMinTextScale || *v > kMaxTextScale) {
        note = where(node) + "text_scale: expected a number from 0.5 to 3 (1: the display's)" +
               defaults;
        return s;
      }
      read.text_scale = float(*v);
    } else if (k == "welcome") {
      const std::optional<std::string> v = node.value<std::string>();
      if (!v || (*v != "dismissed" && *v != "show")) {
        note = where(node) + "welcome: expected \"dismissed\" or \"show\"" + defaults;
        return s;
      }
      read.welcome_dismissed = *v == "dismissed";
    } else {
      note = where(node) + k + ": not a window setting (text_scale, welcome)" + defaults;
      return s;
    }
  }
  return read;
}

bool save_window_settings(const std::string& given, const WindowSettings& s, std::string& error) {
  const std::string path = given.empty() ? default_window_settings_path() : given;
  char scale[32];
  std::snprintf(scale, sizeof scale, "%.3g", double(s.text_scale));
  const std::string text =
      "# mixpilot's window (written by the app)\n"
      "text_scale = " + std::string(scale) + (std::string(scale).find('.') == std::string::npos ? ".0" : "") +
      "   # the text size: a factor on the display's scale\n"
      "welcome = \"" + (s.welcome_dismissed ? "dismissed" : "show") +
      "\"   # the first launch's welcome\n";
  return input::save_user_file(path, text, error);
}

}  // namespace mixpilot::cli
