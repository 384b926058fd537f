#include "core/modes/mode.hpp"

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

}  // namespace mixpilot
