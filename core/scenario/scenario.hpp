#pragma once
// A scenario: everything a session needs besides its pilot-input source (SPEC §5.4).
// Plain data with the defaults of SPEC Table 7.1; loaded from TOML by core/scenario/scenario_toml.hpp.
// The controller and pilot settings it holds are core/control/mi_settings.hpp's.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/mi_settings.hpp"

namespace mixpilot {

struct PlantOptions {
  double rate_hz = 1000.0;       // RK4 substeps per second (≥ 1 kHz)
  double input_delay = 0.0;      // [s] applied command reaches the rotors this late
  double position_noise = 0.0;   // [m] std of noise on the controller's position measurement
  std::uint64_t seed = 1;        // noise seed
};

struct Scenario {
  std::string name;
  std::string mode = "mixed_initiative";
  std::string model = "mikrokopter";
  double duration = 30.0;  // [s]
  MiControllerSettings controller{};
  HelixReference reference{};
  Arena arena{};
  std::map<std::string, PilotProfile> pilots;  // by profile name ("novice", "experienced", ...)
  std::string default_pilot = "novice";
  PlantOptions plant{};

  std::string source_path;  // the file it was loaded from, if any
  std::string source_text;  // its full text (recorded with sessions)
};

}  // namespace mixpilot
