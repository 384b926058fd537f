#include "ui/reason.hpp"

#include <cmath>
#include <cstdio>

namespace mixpilot::ui {

bool reason_matters(const Telemetry& s) {
  if (s.mode != ModeKind::mixed_initiative || !s.solved) return false;
  if (s.reason.cap != LambdaCap::none) return true;
  return s.reason.node >= 0 && s.lambda < kReasonLambda;
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

namespace {

// "too low" or "too high" when the gap points mostly down or up; "" otherwise (a direction
// across the arena means little to a pilot looking from the chase camera).
const char* vertical(const LambdaReason& r) {
  if (r.direction.z() < -0.7) return "too low";
  if (r.direction.z() > 0.7) return "too high";
  return "";
}

}  // namespace

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
    case LambdaCap::none: break;
  }
  if (r.node < 0) {
    std::snprintf(buf, sizeof buf, "planner %.0f %% until the first prediction", planner);
    return buf;
  }
  // Node 0 is where the vehicle was at the previous step: "now" to the pilot.
  char when[32] = "";
  if (r.node > 0) std::snprintf(when, sizeof when, " in %.3g s", r.ahead);
  const char* v = vertical(r);
  const double out = r.d_res - ball_radius;
  if (std::abs(out) < 0.005) {  // on the edge, to the centimetre shown
    std::snprintf(buf, sizeof buf, "planner %.0f %%: you %s the ball's edge%s%s%s%s", planner,
                  r.node > 0 ? "would reach" : "are on", when, *v ? " (" : "", v, *v ? ")" : "");
  } else if (out > 0.0) {
    std::snprintf(buf, sizeof buf, "planner %.0f %%: you %s the ball by %.2f m%s%s%s%s", planner,
                  r.node > 0 ? "would leave" : "are out of", out, when, *v ? " (" : "", v,
                  *v ? ")" : "");
  } else {
    std::snprintf(buf, sizeof buf, "planner %.0f %%: you %s %.2f m off the reference%s%s%s%s",
                  planner, r.node > 0 ? "would be" : "are", r.d_res, when, *v ? " (" : "", v,
                  *v ? ")" : "");
  }
  return buf;
}

}  // namespace mixpilot::ui
