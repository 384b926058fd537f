#include "core/modes/debrief.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/control/reason_words.hpp"

namespace mixpilot {

const char* to_string(DebriefKind kind) {
  switch (kind) {
    case DebriefKind::takeover: return "takeover";
    case DebriefKind::near_miss: return "near miss";
    case DebriefKind::collision: return "collision";
    case DebriefKind::fallback: return "fallback";
    case DebriefKind::input_lost: return "input lost";
    case DebriefKind::lost: return "vehicle lost";
    case DebriefKind::safe_hold: return "safe hold";
    case DebriefKind::marker: return "marker";
    case DebriefKind::instructor: return "instructor";
  }
  return "?";
}

LogLevel log_level(DebriefKind kind) {
  switch (kind) {
    case DebriefKind::takeover:
    case DebriefKind::near_miss:
    case DebriefKind::fallback:
    case DebriefKind::input_lost: return LogLevel::warn;
    case DebriefKind::collision:
    case DebriefKind::lost:
    case DebriefKind::safe_hold: return LogLevel::error;
    case DebriefKind::marker:
    case DebriefKind::instructor: return LogLevel::info;
  }
  return LogLevel::info;
}

namespace {

// The length of the first `n` bytes of `text` or fewer, cut before a UTF-8 continuation byte so
// no character is split.
std::size_t utf8_cut(const char* text, std::size_t length, std::size_t n) {
  if (length <= n) return length;
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  return n;
}

// The length of `text` without a UTF-8 character cut short at its end.
std::size_t without_partial(const char* text, std::size_t length) {
  std::size_t lead = length;
  while (lead > 0 && length - lead < 4 && (static_cast<unsigned char>(text[lead - 1]) & 0xC0) == 0x80)
    --lead;
  if (lead == 0) return length;
  const auto b = static_cast<unsigned char>(text[lead - 1]);
  const std::size_t need = b >= 0xF0 ? 4 : b >= 0xE0 ? 3 : b >= 0xC0 ? 2 : 1;
  return lead - 1 + need > length ? lead - 1 : length;
}

}  // namespace

void DebriefNote::assign(std::string_view text) {
  size_ = utf8_cut(text.data(), text.size(), kCapacity);
  if (size_ > 0) std::memcpy(text_.data(), text.data(), size_);  // data() may be null when empty
  text_[size_] = '\0';
}

DebriefSettings debrief_settings(const Mode& mode) {
  DebriefSettings s;
  s.dt = mode.dt();
  const ModeView v = mode.view();
  s.ball_radius = v.ball_radius;
  // SPEC §10: a near miss brings the vehicle's centre closer than twice its radius to a
  // surface, so its sphere within one radius: a clearance below r_v.
  s.near_miss_margin = v.vehicle_radius;
  return s;
}

void DebriefBuilder::setup(const DebriefSettings& s) {
  settings_ = s;
  // Steps of the hold: at or above the threshold for `hold_s` is steps j .. j + n − 1 with
  // n·Δt ≥ hold_s (the tolerance keeps 0.5 / 0.01 at 50 steps, not 51).
  hold_steps_ = std::max<std::int64_t>(1, std::int64_t(std::ceil(s.hold_s / s.dt - 1e-9)));
  events_.clear();
  events_.reserve(s.capacity);
  dropped_ = 0;
  last_step_ = -1;
  takeover_ = near_miss_ = collision_ = fallback_ = input_lost_ = safe_hold_ = Open{};
}

void DebriefBuilder::keep(const DebriefEvent& e) {
  if (events_.size() < events_.capacity()) events_.push_back(e);
  else ++dropped_;
}

void DebriefBuilder::start(Open& o, DebriefKind kind, const Telemetry& s) {
  o.open = true;
  o.touched = false;
  o.e = DebriefEvent{};
  o.e.kind = kind;
  o.e.start_step = s.step;
  o.e.start = s.t;
  o.e.extreme_t = s.t;
}

void DebriefBuilder::close(Open& o, std::int64_t closed, bool until_end) {
  o.open = false;
  DebriefEvent& e = o.e;
  e.end_step = o.last_on + 1;
  e.end = time_of(e.end_step);
  e.closed_step = closed;
  e.until_end = until_end;
  if (e.kind == DebriefKind::takeover || e.kind == DebriefKind::near_miss ||
      e.kind == DebriefKind::collision || e.kind == DebriefKind::input_lost)
    e.steps = e.end_step - e.start_step;
  if (e.kind == DebriefKind::near_miss && o.touched) return;  // a collision, said as one
  keep(e);
}

void DebriefBuilder::add(const Telemetry& s) {
  const std::int64_t k = s.step;
  last_step_ = k;
  const bool mi = s.mode == ModeKind::mixed_initiative;

  // A run closes once its condition has been off for `hold` steps: it last held at o.last_on,
  // and steps last_on + 1 .. k are clear of it (so an on step at most `hold` steps after the
  // last one continues the run).
  const auto run = [&](Open& o, DebriefKind kind, bool on, std::int64_t hold) {
    if (on) {
      if (!o.open) start(o, kind, s);
      o.last_on = k;
      return true;
    }
    if (o.open && k - o.last_on >= hold) close(o, k, false);
    return false;
  };

  // Takeover: λ below λ_T where something decided it (not the initial λ of the first step),
  // other than the instructor's ceiling: that share of the planner is the instructor's choice,
  // not something the pilot's flying caused.
  const bool decided = mi && s.solved && (s.reason.node >= 0 || s.reason.cap != LambdaCap::none) &&
                       s.reason.cap != LambdaCap::instructor_ceiling;
  if (run(takeover_, DebriefKind::takeover, decided && s.lambda < settings_.takeover_lambda,
          hold_steps_)) {
    DebriefEvent& e = takeover_.e;
    if (e.start_step == k || s.lambda < e.extreme) {
      e.extreme = s.lambda;
      e.extreme_t = s.t;
      e.reason = s.reason;
      e.input = s.pilot.input;
    }
  }

  // Contact, and the approaches without it.
  const bool contact = (s.events & kEventCollision) != 0 || s.clearance < 0.0;
  const bool measured = std::isfinite(s.clearance);
  if (run(collision_, DebriefKind::collision, contact, 1) && measured) {
    DebriefEvent& e = collision_.e;
    if (e.start_step == k || s.clearance < e.extreme) {
      e.extreme = s.clearance;
      e.extreme_t = s.t;
    }
  }
  const bool close_by = measured && s.clearance < settings_.near_miss_margin;
  if (run(near_miss_, DebriefKind::near_miss, close_by, hold_steps_)) {
    DebriefEvent& e = near_miss_.e;
    near_miss_.touched = near_miss_.touched || contact;
    if (e.start_step == k || s.clearance < e.extreme) {
      e.extreme = s.clearance;
      e.extreme_t = s.t;
    }
  }

  if (run(fallback_, DebriefKind::fallback, (s.events & (kEventFallback | kEventOverrun)) != 0,
          hold_steps_))
    ++fallback_.e.steps;
  if (run(safe_hold_, DebriefKind::safe_hold, (s.events & kEventSafeHold) != 0, hold_steps_))
    ++safe_hold_.e.steps;
  run(input_lost_, DebriefKind::input_lost, mi && s.pilot.input == InputState::lost, 1);

  // The instructor's commands of the step: markers with their text, the others in words.
  for (int i = 0; i < s.num_commands; ++i) {
    const InstructorCommand& c = s.commands[std::size_t(i)];
    DebriefEvent e;
    e.start_step = e.end_step = e.closed_step = k;
    e.start = e.end = e.extreme_t = s.t;
    e.steps = 1;
    if (c.kind == InstructorCommandKind::marker) {
      e.kind = DebriefKind::marker;
      e.note = c.text;
    } else {
      e.kind = DebriefKind::instructor;
      char words[DebriefNote::kCapacity + 1];
      e.note.assign(std::string_view(words, describe(c, words, sizeof words)));
    }
    keep(e);
  }

  if (s.events & kEventLost) {
    DebriefEvent e;
    e.kind = DebriefKind::lost;
    e.start_step = e.end_step = e.closed_step = k;
    e.start = e.end = e.extreme_t = s.t;
    e.steps = 1;
    keep(e);
  }
}

void DebriefBuilder::finish() {
  if (last_step_ < 0) return;
  const std::int64_t k = last_step_;
  for (Open* o : {&takeover_, &near_miss_, &collision_, &fallback_, &input_lost_, &safe_hold_}) {
    if (!o->open) continue;
    // Still on at the last step: it lasted to the end (the end is t_k + Δt). Off since, but not
    // for long enough to close: it ended where it was last on.
    const bool on = o->last_on == k;
    close(*o, k, on);
  }
}

void DebriefBuilder::mark(std::string_view text) {
  DebriefEvent e;
  e.kind = DebriefKind::marker;
  const std::int64_t k = std::max<std::int64_t>(last_step_, 0);
  e.start_step = e.end_step = e.closed_step = k;
  e.start = e.end = e.extreme_t = time_of(k);
  e.steps = 1;
  e.note.assign(text);
  keep(e);
}

std::vector<DebriefEvent> debrief_of(const std::vector<Telemetry>& steps, std::size_t count,
                                     const DebriefSettings& s) {
  DebriefBuilder b(s);
  for (std::size_t i = 0; i < std::min(count, steps.size()); ++i) b.add(steps[i]);
  b.finish();
  return b.events();
}

namespace {

// A duration in words: two decimals below a second (a fallback can last one step), else one.
void duration_words(double d, char* out, std::size_t size) {
  std::snprintf(out, size, d < 1.0 ? "%.2f s" : "%.1f s", d);
}

// Why λ was lowest in a takeover, said of the past where a cap bound it; the PH index's words
// (core/control/reason_words.hpp) otherwise.
void why_words(const DebriefEvent& e, double ball_radius, char* out, std::size_t size) {
  switch (e.reason.cap) {
    case LambdaCap::input_lost:
      std::snprintf(out, size, "%s",
                    e.input == InputState::lost       ? "the input was lost"
                    : e.input == InputState::recentre ? "the sticks were not centred yet"
                                                      : "control was returning to you");
      return;
    case LambdaCap::safe_hold: std::snprintf(out, size, "the safe controller flew"); return;
    case LambdaCap::probe: std::snprintf(out, size, "a probe flight"); return;
    case LambdaCap::instructor_ceiling:
      std::snprintf(out, size, "the instructor's ceiling held it");
      return;
    case LambdaCap::instructor_floor: std::snprintf(out, size, "the instructor's floor held it"); return;
    case LambdaCap::none: break;
  }
  if (e.reason.node < 0) {
    std::snprintf(out, size, "before the first prediction");
    return;
  }
  prediction_words(e.reason, ball_radius, out, size);
}

}  // namespace

std::size_t describe(const DebriefEvent& e, double ball_radius, char* out, std::size_t size) {
  if (size == 0) return 0;
  char d[32];
  duration_words(e.duration(), d, sizeof d);
  const char* last = e.until_end ? "the last " : "";
  int n = 0;
  switch (e.kind) {
    case DebriefKind::takeover: {
      char why[160];
      why_words(e, ball_radius, why, sizeof why);
      n = std::snprintf(out, size, "planner took over for %s%s (lowest λ %.2f): %s", last, d,
                        e.extreme, why);
      break;
    }
    case DebriefKind::near_miss:
      n = std::snprintf(out, size, "near miss for %s%s: %.3f m of clearance at the closest", last,
                        d, e.extreme);
      break;
    case DebriefKind::collision:
      if (std::isfinite(e.extreme) && e.extreme < 0.0)
        n = std::snprintf(out, size, "collision: in contact for %s%s, %.3f m deep", last, d,
                          -e.extreme);
      else
        n = std::snprintf(out, size, "collision: in contact for %s%s", last, d);
      break;
    case DebriefKind::fallback:
      n = std::snprintf(out, size, "%lld fallback%s in %s%s: the MPC applied its previous plan",
                        static_cast<long long>(e.steps), e.steps == 1 ? "" : "s", last, d);
      break;
    case DebriefKind::input_lost:
      n = std::snprintf(out, size, e.until_end ? "input lost for the last %s: the planner flew"
                                               : "input lost for %s: the planner flew until it "
                                                 "came back",
                        d);
      break;
    case DebriefKind::lost: n = std::snprintf(out, size, "vehicle lost: the flight ended"); break;
    case DebriefKind::safe_hold:
      n = std::snprintf(out, size,
                        "safe hold for %s%s: the MPC fell behind, the safe controller flew", last, d);
      break;
    case DebriefKind::marker: {
      const std::string_view note = e.note.view();
      n = std::snprintf(out, size, "marker: %.*s", int(note.size()), note.data());
      break;
    }
    case DebriefKind::instructor: {
      const std::string_view note = e.note.view();
      n = std::snprintf(out, size, "instructor: %.*s", int(note.size()), note.data());
      break;
    }
  }
  if (n < 0) {
    out[0] = '\0';
    return 0;
  }
  // snprintf cuts at a byte: a character it cut is left out whole.
  std::size_t length = std::strlen(out);
  if (std::size_t(n) >= size) length = without_partial(out, length);
  out[length] = '\0';
  return length;
}

std::string describe(const DebriefEvent& e, double ball_radius) {
  char buf[320];
  return std::string(buf, describe(e, ball_radius, buf, sizeof buf));
}

}  // namespace mixpilot
