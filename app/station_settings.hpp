#pragma once
// The station's own settings (SPEC §10, docs/instructor-security.md):
// $XDG_CONFIG_HOME/mixpilot/station.toml, which a training centre installs once per station so
// every flight that publishes is announced under its name, obeys an instructor and authenticates
// with its DDS Security files:
//   name = "sim3"                                  # --station
//   instructor = true                              # --instructor
//   dds_security = "/etc/mixpilot/dds-security/sim3"   # --dds-security
// The command line overrides each. A missing file is the defaults.
#include <optional>
#include <string>

namespace mixpilot::cli {

struct StationSettings {
  std::string name;
  bool instructor = false;
  std::string dds_security;
};

// The user's station settings (`path`, or the default file when ""); nullopt with the reason
// ("FILE:LINE:COL: key: expected ...") when the file cannot be read or holds something else.
std::optional<StationSettings> load_station_settings(const std::string& path, std::string& error);
std::string default_station_settings_path();

}  // namespace mixpilot::cli
