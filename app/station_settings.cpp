#include "app/station_settings.hpp"

#include <toml++/toml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "input/net/instructor_link.hpp"
#include "input/settings.hpp"

namespace mixpilot::cli {

std::string default_station_settings_path() {
  const std::string dir = input::config_dir();
  return dir.empty() ? std::string() : dir + "/station.toml";
}

std::optional<StationSettings> load_station_settings(const std::string& given,
                                                     std::string& error) {
  StationSettings s;
  const std::string path = given.empty() ? default_station_settings_path() : given;
  std::error_code ec;
  if (path.empty() || !std::filesystem::exists(path, ec)) return s;
  if (!std::filesystem::is_regular_file(path, ec)) {
    error = path + ": not a settings file (a folder or a device)";
    return std::nullopt;
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) {
    error = path + ": cannot be read";
    return std::nullopt;
  }
  toml::table t;
  try {
    t = toml::parse(text.str(), path);
  } catch (const toml::parse_error& e) {
    error = path + ":" + std::to_string(e.source().begin.line) + ":" +
            std::to_string(e.source().begin.column) + ": " + std::string(e.description());
    return std::nullopt;
  }
  const auto where = [&](const toml::node& n) {
    return path + ":" + std::to_string(n.source().begin.line) + ":" +
           std::to_string(n.source().begin.column) + ": ";
  };
  for (const auto& [key, node] : t) {
    const std::string k(key.str());
    if (k == "name") {
      const auto v = node.value<std::string>();
      if (!v) {
        error = where(node) + "name: expected the station's name as a string";
        return std::nullopt;
      }
      if (const std::string why = net::check_station_name(*v); !why.empty()) {
        error = where(node) + "name: " + why;
        return std::nullopt;
      }
      s.name = *v;
    } else if (k == "instructor") {
      const auto v = node.value<bool>();
      if (!v) {
        error = where(node) + "instructor: expected true or false";
        return std::nullopt;
      }
      s.instructor = *v;
    } else if (k == "dds_security") {
      const auto v = node.value<std::string>();
      if (!v || v->empty()) {
        error = where(node) + "dds_security: expected the folder of this station's DDS "
                              "Security files as a string";
        return std::nullopt;
      }
      s.dds_security = *v;
    } else {
      error = where(node) + k + ": not a station setting (name, instructor, dds_security)";
      return std::nullopt;
    }
  }
  return s;
}

}  // namespace mixpilot::cli
