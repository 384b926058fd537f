#include "core/control/reason_words.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace mixpilot {

namespace {

// "too low" or "too high" when the gap points mostly down or up; "" otherwise (a direction
// across the arena means little to a pilot looking from the chase camera).
const char* vertical(const LambdaReason& r) {
  if (r.direction.z() < -0.7) return "too low";
  if (r.direction.z() > 0.7) return "too high";
  return "";
}

}  // namespace

std::size_t prediction_words(const LambdaReason& r, double ball_radius, char* out,
                             std::size_t size) {
  if (size == 0) return 0;
  // Node 0 is where the vehicle was at the previous step: "now" to the pilot.
  char when[32] = "";
  if (r.node > 0) std::snprintf(when, sizeof when, " in %.3g s", r.ahead);
  const char* v = vertical(r);
  const char* open = *v ? " (" : "";
  const char* close = *v ? ")" : "";
  const double gap = r.d_res - ball_radius;
  int n = 0;
  if (std::abs(gap) < 0.005) {  // on the edge, to the centimetre shown
    n = std::snprintf(out, size, "you %s the ball's edge%s%s%s%s",
                      r.node > 0 ? "would reach" : "are on", when, open, v, close);
  } else if (gap > 0.0) {
    n = std::snprintf(out, size, "you %s the ball by %.2f m%s%s%s%s",
                      r.node > 0 ? "would leave" : "are out of", gap, when, open, v, close);
  } else {
    n = std::snprintf(out, size, "you %s %.2f m off the reference%s%s%s%s",
                      r.node > 0 ? "would be" : "are", r.d_res, when, open, v, close);
  }
  return n < 0 ? 0 : std::strlen(out);
}

}  // namespace mixpilot
