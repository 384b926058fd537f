#include "core/control/pilot.hpp"

namespace mixpilot {

const char* to_string(InputState s) {
  switch (s) {
    case InputState::ok: return "ok";
    case InputState::lost: return "lost";
    case InputState::recentre: return "recentre";
    case InputState::returning: return "returning";
  }
  return "lost";
}

}  // namespace mixpilot
