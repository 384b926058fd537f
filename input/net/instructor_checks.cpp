#include "input/net/instructor_checks.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace mixpilot::net {

namespace {

CommandRefusal refuse(RefusalNote& note, CommandRefusal why, const char* format, double a = 0,
                      double b = 0, double c = 0) {
  note = RefusalNote{why, format, a, b, c};
  return why;
}

}  // namespace

const char* to_string(CommandRefusal r) {
  switch (r) {
    case CommandRefusal::none: return "accepted";
    case CommandRefusal::not_allowed: return "instructor not allowed";
    case CommandRefusal::unauthenticated: return "unauthenticated";
    case CommandRefusal::bad_value: return "bad value";
    case CommandRefusal::stale: return "stale";
    case CommandRefusal::replayed: return "replayed";
    case CommandRefusal::busy: return "busy";
  }
  return "?";
}

void describe(const RefusalNote& note, char* out, std::size_t size) {
  if (size == 0) return;
  char what[192];
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
  std::snprintf(what, sizeof what, note.format, note.a, note.b, note.c);
#pragma GCC diagnostic pop
  std::snprintf(out, size, "%s: %s", to_string(note.why), what);
}

bool printable_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b = static_cast<unsigned char>(s[i]);
    if (b < 0x80) {
      if (b < 0x20 || b == 0x7f) return false;
      ++i;
      continue;
    }
    int n = 0;
    std::uint32_t cp = 0;
    if ((b & 0xe0) == 0xc0) n = 1, cp = b & 0x1f;
    else if ((b & 0xf0) == 0xe0) n = 2, cp = b & 0x0f;
    else if ((b & 0xf8) == 0xf0) n = 3, cp = b & 0x07;
    else return false;
    if (i + std::size_t(n) >= s.size()) return false;  // cut short
    for (int k = 1; k <= n; ++k) {
      const auto c = static_cast<unsigned char>(s[i + std::size_t(k)]);
      if ((c & 0xc0) != 0x80) return false;
      cp = (cp << 6) | (c & 0x3f);
    }
    // Overlong forms, surrogates, beyond U+10FFFF, C1 controls.
    if ((n == 1 && cp < 0x80) || (n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) ||
        (cp >= 0xd800 && cp <= 0xdfff) || cp > 0x10ffff || (cp >= 0x80 && cp <= 0x9f))
      return false;
    i += std::size_t(n) + 1;
  }
  return true;
}

void InstructorCheck::setup(const Limits& limits) {
  limits_ = limits;
  issuers_ = {};
}

CommandRefusal InstructorCheck::check(const InstructorFields& c, std::int64_t now,
                                   InstructorCommand& out, RefusalNote& note) {
  // Who and what.
  if (c.issuer.empty() || c.issuer.size() > kMaxIssuer || !printable_utf8(c.issuer))
    return refuse(note, CommandRefusal::bad_value,
                  "an issuer's name of %.0f bytes that is not 1 to %.0f bytes of printable UTF-8",
                  double(c.issuer.size()), double(kMaxIssuer));
  const std::optional<InstructorCommandKind> kind = instructor_command_kind(c.kind);
  if (!kind)
    return refuse(note, CommandRefusal::bad_value, "kind %.0f (0 to %.0f are known)", c.kind,
                  kInstructorCommandKindCount - 1);
  const double numbers[] = {c.floor, c.ceiling, c.force[0], c.force[1], c.force[2], c.duration,
                            c.delay};
  for (std::size_t i = 0; i < std::size(numbers); ++i)
    if (!std::isfinite(numbers[i]))
      return refuse(note, CommandRefusal::bad_value, "field %.0f is %g, not a finite number",
                    double(i), numbers[i]);
  InstructorCommand cmd;
  cmd.kind = *kind;
  switch (*kind) {
    case InstructorCommandKind::bounds:
      if (!(c.floor >= 0.0 && c.floor <= c.ceiling && c.ceiling <= 1.0))
        return refuse(note, CommandRefusal::bad_value,
                      "bounds floor %.3g, ceiling %.3g (0 <= floor <= ceiling <= 1)", c.floor,
                      c.ceiling);
      cmd.bounds = {c.floor, c.ceiling};
      break;
    case InstructorCommandKind::gust: {
      const double f = std::sqrt(c.force[0] * c.force[0] + c.force[1] * c.force[1] +
                                 c.force[2] * c.force[2]);
      if (f > kMaxForce)
        return refuse(note, CommandRefusal::bad_value, "a gust of %.3g N (at most %.3g N)", f,
                      kMaxForce);
      if (!(c.duration > 0.0 && c.duration <= kMaxDuration))
        return refuse(note, CommandRefusal::bad_value,
                      "a gust lasting %.3g s (more than 0, at most %.3g s)", c.duration,
                      kMaxDuration);
      cmd.force = Eigen::Vector3d(c.force[0], c.force[1], c.force[2]);
      cmd.duration = c.duration;
      break;
    }
    case InstructorCommandKind::input_loss:
      if (!(c.duration > 0.0 && c.duration <= kMaxDuration))
        return refuse(note, CommandRefusal::bad_value,
                      "an input loss lasting %.3g s (more than 0, at most %.3g s)", c.duration,
                      kMaxDuration);
      cmd.duration = c.duration;
      break;
    case InstructorCommandKind::extra_delay:
      if (!(c.delay >= 0.0 && c.delay <= kMaxDelay))
        return refuse(note, CommandRefusal::bad_value, "an extra delay of %.3g s (0 to %.3g s)",
                      c.delay, kMaxDelay);
      cmd.delay = c.delay;
      break;
    case InstructorCommandKind::marker:
      if (c.text.empty() || c.text.size() > DebriefNote::kCapacity || !printable_utf8(c.text))
        return refuse(note, CommandRefusal::bad_value,
                      "a marker of %.0f bytes that is not 1 to %.0f bytes of printable UTF-8",
                      double(c.text.size()), double(DebriefNote::kCapacity));
      cmd.text.assign(c.text);
      break;
    case InstructorCommandKind::pause:
    case InstructorCommandKind::resume:
    case InstructorCommandKind::end: break;
  }
  // When.
  const double age = 1e-9 * double(now - c.issued_ns);
  if (age > limits_.max_age_s)
    return refuse(note, CommandRefusal::stale, "issued %.3g s ago (older than %.3g s is refused)",
                  age, limits_.max_age_s);
  if (-age > limits_.clock_tolerance_s)
    return refuse(note, CommandRefusal::stale,
                  "issued %.3g s ahead of this station's clock (more than %.3g s ahead is "
                  "refused: are both clocks synchronised?)",
                  -age, limits_.clock_tolerance_s);
  // In order, per issuer.
  Issuer* slot = nullptr;
  for (Issuer& i : issuers_)
    if (i.used && std::string_view(i.name.data(), i.size) == c.issuer) slot = &i;
  if (slot && c.sequence <= slot->last_sequence)
    return refuse(note, CommandRefusal::replayed,
                  "number %.0f from this issuer, not above the last one taken (%.0f)",
                  double(c.sequence), double(slot->last_sequence));
  if (!slot) {
    // A new issuer takes a free slot, or that of an issuer whose last command is so old that
    // any replay of it would be stale anyway.
    const std::int64_t forget = now - std::int64_t(1e9 * (limits_.max_age_s +
                                                          limits_.clock_tolerance_s));
    for (Issuer& i : issuers_)
      if (!i.used || i.last_ns < forget) {
        slot = &i;
        break;
      }
    if (!slot)
      return refuse(note, CommandRefusal::busy,
                    "%.0f issuers commanded within %.3g s: no room to keep another's order",
                    kMaxIssuers, limits_.max_age_s);
    *slot = Issuer{};
    slot->used = true;
    slot->size = c.issuer.size();
    if (!c.issuer.empty()) std::memcpy(slot->name.data(), c.issuer.data(), c.issuer.size());
  }
  slot->last_sequence = c.sequence;
  slot->last_ns = now;
  out = cmd;
  return CommandRefusal::none;
}

}  // namespace mixpilot::net
