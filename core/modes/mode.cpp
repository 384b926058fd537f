#include "core/modes/mode.hpp"

#include "core/modes/obstacles.hpp"
#include "core/modes/pendubot_mode.hpp"
#include "core/modes/tracking.hpp"


namespace mixpilot {

const char* to_string(ModeKind kind) {
  switch (kind) {
    case ModeKind::mixed_initiative: return "mixed_initiative";
    case ModeKind::pendubot_swingup: return "pendubot_swingup";
    case ModeKind::crazyflie_tracking: return "crazyflie_tracking";
    case ModeKind::obstacle_avoidance: return "obstacle_avoidance";
  }
  return "unknown";
}

namespace {
constexpr ModeKind kModeKinds[] = {ModeKind::mixed_initiative, ModeKind::pendubot_swingup,
                                   ModeKind::crazyflie_tracking, ModeKind::obstacle_avoidance};
}  // namespace

std::optional<ModeKind> mode_kind_from_string(std::string_view name) {
  for (ModeKind k : kModeKinds)
    if (name == to_string(k)) return k;
  return std::nullopt;
}

std::string mode_kind_names() {
  std::string names;
  for (ModeKind k : kModeKinds) names += std::string(names.empty() ? "" : ", ") + to_string(k);
  return names;
}

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
