#include "core/mode.hpp"

#include "core/obstacles.hpp"
#include "core/pendubot_swingup.hpp"
#include "core/tracking.hpp"


namespace mixpilot {

namespace {

struct Entry {
  const char* name;
  ModeRunner runner;
};

// One line per mode (issue 6), e.g. {"pendubot_swingup", &fly_pendubot_swingup}.
const std::vector<Entry>& modes() {
  static const std::vector<Entry> kModes = {
      {"pendubot_swingup", &fly_pendubot_swingup},
      {"obstacle_avoidance", &fly_obstacle_avoidance},
      {"crazyflie_tracking", &fly_crazyflie_tracking},
  };
  return kModes;
}

}  // namespace

ModeRunner find_mode_runner(const std::string& mode) {
  for (const Entry& e : modes())
    if (mode == e.name) return e.runner;
  return nullptr;
}

std::vector<std::string> mode_runner_names() {
  std::vector<std::string> names;
  for (const Entry& e : modes()) names.emplace_back(e.name);
  return names;
}

}  // namespace mixpilot
