#include "ui/reason.hpp"

#include <cstdio>

#include "core/control/reason_words.hpp"

namespace mixpilot::ui {

bool reason_matters(const Telemetry& s) {
  if (s.mode != ModeKind::mixed_initiative) return false;
  if (s.reason.cap != LambdaCap::none) return true;
  return s.solved && s.reason.node >= 0 && s.lambda < kReasonLambda;
}

std::optional<std::size_t> shown_reason(const History& h) {
  if (h.empty()) return std::nullopt;
  const double now = h.newest().t;
  for (std::size_t i = h.size(); i-- > 0;) {
    if (h[i].t < now - kReasonHoldS) break;
    if (reason_matters(h[i])) return i;
  }
  return std::nullopt;
}

const Telemetry* reason_prediction(const History& h, std::size_t i) {
  if (i == 0 || i >= h.size()) return nullptr;
  const Telemetry& previous = h[i - 1];
  return previous.step == h[i].step - 1 && previous.predicted.cols() > 0 ? &previous : nullptr;
}

std::string reason_text(const Telemetry& s, double ball_radius) {
  const LambdaReason& r = s.reason;
  const double planner = 100.0 * (1.0 - s.lambda);
  char buf[160];
  switch (r.cap) {
    case LambdaCap::input_lost:
      if (s.pilot.input == InputState::lost) return "input lost: the planner flies";
      if (s.pilot.input == InputState::recentre) return "input back: centre the sticks to fly";
      std::snprintf(buf, sizeof buf, "input back: control returning, planner %.0f %%", planner);
      return buf;
    case LambdaCap::probe: return "probe flight: you fly alone";
    case LambdaCap::safe_hold: return "safe hold: the safe controller flies";
    case LambdaCap::instructor_ceiling:
      std::snprintf(buf, sizeof buf, "instructor's ceiling: the planner keeps %.0f %%", planner);
      return buf;
    case LambdaCap::instructor_floor:
      std::snprintf(buf, sizeof buf, "instructor's floor: you keep %.0f %%", 100.0 * s.lambda);
      return buf;
    case LambdaCap::none: break;
  }
  if (r.node < 0) {
    std::snprintf(buf, sizeof buf, "planner %.0f %% until the first prediction", planner);
    return buf;
  }
  const int n = std::snprintf(buf, sizeof buf, "planner %.0f %%: ", planner);
  prediction_words(r, ball_radius, buf + n, sizeof buf - std::size_t(n));
  return buf;
}

}  // namespace mixpilot::ui
