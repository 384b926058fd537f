#include "core/modes/instructor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mixpilot {

const char* to_string(InstructorCommandKind kind) {
  switch (kind) {
    case InstructorCommandKind::bounds: return "bounds";
    case InstructorCommandKind::gust: return "gust";
    case InstructorCommandKind::extra_delay: return "extra delay";
    case InstructorCommandKind::input_loss: return "input loss";
    case InstructorCommandKind::marker: return "marker";
    case InstructorCommandKind::pause: return "pause";
    case InstructorCommandKind::resume: return "resume";
    case InstructorCommandKind::end: return "end";
  }
  return "?";
}

std::optional<InstructorCommandKind> instructor_command_kind(std::uint8_t value) {
  if (value >= kInstructorCommandKindCount) return std::nullopt;
  return InstructorCommandKind(value);
}

}  // namespace mixpilot

namespace mixpilot {

const char* to_string(InstructorStatus status) {
  switch (status) {
    case InstructorStatus::applied: return "applied";
    case InstructorStatus::bad_value: return "a value is not finite or out of range";
    case InstructorStatus::no_authority:
      return "this mode shares no authority with a pilot: no bounds on λ";
    case InstructorStatus::no_pilot: return "this mode has no pilot whose input could be lost";
    case InstructorStatus::fixed_base:
      return "the Pendubot is an arm on a fixed shoulder: there is no body for a gust to push";
    case InstructorStatus::no_link:
      return "the Pendubot's controller is wired to its encoders: there is no link to delay";
    case InstructorStatus::remote_vehicle:
      return "the vehicle flies in another process (--vehicle dds): its plant is not here";
    case InstructorStatus::busy: return "the step's commands are full: it waits for the next step";
    case InstructorStatus::over: return "the flight is over";
  }
  return "?";
}

const char* invalid_reason(const InstructorCommand& c) {
  if (!instructor_command_kind(static_cast<std::uint8_t>(c.kind))) return "an unknown kind";
  switch (c.kind) {
    case InstructorCommandKind::bounds:
      if (!std::isfinite(c.bounds.floor) || !std::isfinite(c.bounds.ceiling))
        return "the bounds are not finite";
      if (!c.bounds.valid()) return "the bounds are not 0 <= floor <= ceiling <= 1";
      return nullptr;
    case InstructorCommandKind::gust:
      if (!c.force.allFinite() || !std::isfinite(c.duration))
        return "the gust's force or duration is not finite";
      if (c.force.norm() > kMaxGustForce) return "the gust's force is above 20 N";
      if (!(c.duration > 0.0 && c.duration <= kMaxCommandDuration))
        return "the gust's duration is not in (0, 10] s";
      return nullptr;
    case InstructorCommandKind::extra_delay:
      if (!std::isfinite(c.delay)) return "the extra delay is not finite";
      if (!(c.delay >= 0.0 && c.delay <= kMaxExtraDelay))
        return "the extra delay is not in [0, 0.5] s";
      return nullptr;
    case InstructorCommandKind::input_loss:
      if (!std::isfinite(c.duration)) return "the input loss's duration is not finite";
      if (!(c.duration > 0.0 && c.duration <= kMaxCommandDuration))
        return "the input loss's duration is not in (0, 10] s";
      return nullptr;
    case InstructorCommandKind::marker:
    case InstructorCommandKind::pause:
    case InstructorCommandKind::resume:
    case InstructorCommandKind::end: return nullptr;
  }
  return "an unknown kind";
}

std::size_t describe(const InstructorCommand& c, char* out, std::size_t size) {
  if (size == 0) return 0;
  int n = 0;
  switch (c.kind) {
    case InstructorCommandKind::bounds: {
      const AuthorityBounds& b = c.bounds;
      if (b == AuthorityBounds{}) n = std::snprintf(out, size, "bounds lifted");
      else if (b.floor == 0.0) n = std::snprintf(out, size, "ceiling %.2f", b.ceiling);
      else if (b.ceiling == 1.0) n = std::snprintf(out, size, "floor %.2f", b.floor);
      else n = std::snprintf(out, size, "floor %.2f, ceiling %.2f", b.floor, b.ceiling);
      break;
    }
    case InstructorCommandKind::gust:
      n = std::snprintf(out, size, "gust %.1f N for %.2f s", c.force.norm(), c.duration);
      break;
    case InstructorCommandKind::extra_delay:
      n = c.delay > 0.0 ? std::snprintf(out, size, "extra delay %.3f s", c.delay)
                        : std::snprintf(out, size, "extra delay removed");
      break;
    case InstructorCommandKind::input_loss:
      n = std::snprintf(out, size, "input loss for %.1f s", c.duration);
      break;
    case InstructorCommandKind::marker: {
      const std::string_view t = c.text.view();
      n = std::snprintf(out, size, "marker: %.*s", int(t.size()), t.data());
      break;
    }
    case InstructorCommandKind::pause: n = std::snprintf(out, size, "pause"); break;
    case InstructorCommandKind::resume: n = std::snprintf(out, size, "resume"); break;
    case InstructorCommandKind::end: n = std::snprintf(out, size, "end"); break;
  }
  if (n < 0) {
    out[0] = '\0';
    return 0;
  }
  return std::min(std::size_t(n), size - 1);
}

std::string describe(const InstructorCommand& c) {
  char buf[160];
  return std::string(buf, describe(c, buf, sizeof buf));
}

}  // namespace mixpilot
