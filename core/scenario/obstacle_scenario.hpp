#pragma once
// Scenario files of the obstacle-avoidance mode (SPEC §5.3; docs/scenario-format.md, "Obstacle
// avoidance"): the controller settings, the world and the reference trajectory.
#include <optional>
#include <string>
#include <string_view>

#include "core/control/obstacle_avoidance.hpp"
#include "core/nlp/trajectory_io.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

struct ObstacleScenario {
  std::string name;
  std::string source_path;
  double duration = 4.0;       // [s]
  std::string reference_file;  // resolved against the scenario file's directory
  TrajectoryFile reference;    // read and checked by the loader (13 states, 4 inputs, Δt)
  ObstacleControllerSettings controller;
  ObstacleWorld world;
  double plant_rate_hz = obstacle_defaults::kPlantRateHz;
};

// On failure: nullopt and one `<file>:<line>:<col>: <key path>: <what was expected>` line per
// problem. Never throws.
std::optional<ObstacleScenario> parse_obstacle_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error);
std::optional<ObstacleScenario> load_obstacle_scenario(const std::string& path,
                                                       std::string& error);

}  // namespace mixpilot
