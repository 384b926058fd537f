#pragma once
// Scenario files of mode `crazyflie_tracking` (docs/scenario-format.md) → TrackingScenario:
// the controller, plant and reference settings of core/control/tracking.hpp and the reference
// nodes the loop tracks.
#include <optional>
#include <string>
#include <string_view>

#include "core/control/tracking.hpp"
#include "core/nlp/ocp.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

struct TrackingScenario {
  std::string name;
  std::string source_path;
  double duration = tracking_defaults::kDuration;  // [s]
  TrackingReferenceSettings reference{};
  TrackingControllerSettings controller{};
  TrackingPlantSettings plant{};
  OcpTrajectory reference_trajectory;  // nodes every controller.dt (x: n+1, u: n)
};

// Reading `mode = "crazyflie_tracking"` scenarios. On failure: nullopt and one
// `<file>:<line>:<col>: <key path>: <what was expected>` line per problem. The smooth step's CSV
// is resolved relative to the scenario's directory, then to the working directory.
std::optional<TrackingScenario> parse_tracking_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error);
std::optional<TrackingScenario> load_tracking_scenario(const std::string& path,
                                                       std::string& error);

}  // namespace mixpilot
