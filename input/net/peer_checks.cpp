#include "input/net/peer_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/control/pilot.hpp"

namespace mixpilot::net {

namespace {

Rejection reject(RejectionNote& note, Rejection why, const char* format, double a = 0,
                 double b = 0, double c = 0) {
  note = RejectionNote{why, format, a, b, c};
  return why;
}

}  // namespace

const char* to_string(Rejection r) {
  switch (r) {
    case Rejection::none: return "taken";
    case Rejection::bad_value: return "bad value";
    case Rejection::bad_size: return "bad size";
    case Rejection::unknown_command: return "unknown command";
    case Rejection::stale: return "stale";
    case Rejection::other_publisher: return "another publisher";
  }
  return "?";
}

void describe(const RejectionNote& note, char* out, std::size_t size) {
  if (size == 0) return;
  char what[192];
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
  std::snprintf(what, sizeof what, note.format, note.a, note.b, note.c);
#pragma GCC diagnostic pop
  std::snprintf(out, size, "%s: %s", to_string(note.why), what);
}

// --- Joy -------------------------------------------------------------------------------------

Rejection JoyCheck::check(const JoyFields& m, std::int64_t now, std::int64_t& stamp,
                          RejectionNote& note) {
  if (m.num_axes < 4 || m.num_axes > std::uint32_t(JoyInput::kMaxAxes))
    return reject(note, Rejection::bad_size, "%.0f axes (4 to %.0f are read)", m.num_axes,
                  JoyInput::kMaxAxes);
  if (m.num_buttons > std::uint32_t(JoyInput::kMaxButtons))
    return reject(note, Rejection::bad_size, "%.0f buttons (at most %.0f are read)",
                  m.num_buttons, JoyInput::kMaxButtons);
  if (m.frame_id_length > kMaxFrameId)
    return reject(note, Rejection::bad_size, "a frame id of %.0f characters (at most %.0f)",
                  m.frame_id_length, kMaxFrameId);
  for (std::uint32_t i = 0; i < m.num_axes; ++i)
    if (!(std::abs(m.axes[i]) <= 1.0f))
      return reject(note, Rejection::bad_value, "axis %.0f is %.3g, not within [-1, 1]", i,
                    m.axes[i]);
  for (std::uint32_t i = 0; i < m.num_buttons; ++i)
    if (m.buttons[i] != 0 && m.buttons[i] != 1)
      return reject(note, Rejection::bad_value, "button %.0f is %.6g, not 0 or 1", i,
                    m.buttons[i]);
  if (m.nanosec >= 1'000'000'000u)
    return reject(note, Rejection::bad_value,
                  "a stamp of %.6g ns past its second (a second has 1e9)", m.nanosec);
  stamp = std::int64_t(m.sec) * 1'000'000'000 + std::int64_t(m.nanosec);
  const double age = 1e-9 * double(now - stamp);
  if (age > limits_.max_age_s)
    return reject(note, Rejection::stale, "stamped %.3g s ago (older than %.3g s is refused)",
                  age, limits_.max_age_s);
  if (-age > limits_.clock_tolerance_s)
    return reject(note, Rejection::stale,
                  "stamped %.3g s ahead of this machine's clock (more than %.3g s ahead is "
                  "refused: are both clocks synchronised?)",
                  -age, limits_.clock_tolerance_s);
  if (last_ns_ != kNone && stamp < last_ns_)
    return reject(note, Rejection::stale, "stamped %.3g s before the last sample taken",
                  1e-9 * double(last_ns_ - stamp));
  // A stamp ahead of this clock (within the tolerance) orders as if sent now: it cannot make
  // the honest samples after it look old.
  last_ns_ = std::min(stamp, now);
  return Rejection::none;
}

// --- Vehicle states --------------------------------------------------------------------------

bool SentCommands::sent_as(std::int64_t step, std::int64_t stamp_ns) const {
  const std::int64_t n = sent();
  if (step < 0 || step >= n || step < n - kRing) return false;
  return stamps_[std::size_t(step % kRing)].load(std::memory_order_relaxed) == stamp_ns;
}

void StateCheck::setup(const Limits& limits) {
  limits_ = limits;
  taken_ = false;
  last_step_ = -1;
  last_age_s_ = 0;
  offset_count_ = offset_next_ = 0;
}

Rejection StateCheck::check(const StateFields& m, std::int64_t received_ns,
                            const SentCommands& sent, RejectionNote& note) {
  if (m.nx != std::uint32_t(limits_.nx))
    return reject(note, Rejection::bad_size,
                  "%.0f state values, this scenario's model has %.0f (is the vehicle flying "
                  "another scenario?)",
                  m.nx, limits_.nx);
  if (m.status > 2)
    return reject(note, Rejection::bad_value,
                  "status %.0f (0 flying, 1 left its world, 2 ended)", m.status);
  for (std::uint32_t i = 0; i < m.nx; ++i)
    if (!(std::abs(m.x[i]) <= limits_.max_abs[i]))
      return reject(note, Rejection::bad_value,
                    "state value %.0f is %.3g, beyond %.3g: no vehicle has such a state", i,
                    m.x[i], limits_.max_abs[i]);
  if (!(m.command_age_s >= 0.0) || !std::isfinite(m.command_age_s))
    return reject(note, Rejection::bad_value, "a command age of %.3g s", m.command_age_s);
  if (m.command_step < 0) {
    // At rest before the first command: no command, no stamp, no age. Resting states need no
    // order among themselves.
    if (m.command_step != -1 || m.command_stamp_ns != 0 || m.command_age_s != 0.0)
      return reject(note, Rejection::unknown_command,
                    "echoes step %.6g stamped %.6g ns, age %.3g s (before the first command: "
                    "step -1, stamp 0, age 0)",
                    double(m.command_step), double(m.command_stamp_ns), m.command_age_s);
    if (taken_ && last_step_ >= 0)
      return reject(note, Rejection::stale,
                    "echoes no command, after a state that echoed step %.6g", double(last_step_));
    taken_ = true;
    return Rejection::none;
  }
  if (!sent.sent_as(m.command_step, m.command_stamp_ns))
    return reject(note, Rejection::unknown_command,
                  "echoes step %.6g stamped %.6g ns: not one of the newest commands sent "
                  "(%.6g sent)",
                  double(m.command_step), double(m.command_stamp_ns), double(sent.sent()));
  // The command has acted no longer than since it left.
  const double since_sent = 1e-9 * double(received_ns - m.command_stamp_ns);
  if (m.command_age_s > since_sent + limits_.clock_tolerance_s)
    return reject(note, Rejection::stale,
                  "claims step %.6g had acted %.3g s, but it left %.3g s before the state "
                  "arrived",
                  double(m.command_step), m.command_age_s, since_sent);
  // The vehicle's stamp against the median offset of its recent states.
  const double offset =
      double(m.stamp_ns) - double(m.command_stamp_ns) - 1e9 * m.command_age_s;
  offsets_[std::size_t(offset_next_)] = offset;
  offset_next_ = (offset_next_ + 1) % kOffsetWindow;
  offset_count_ = std::min(offset_count_ + 1, kOffsetWindow);
  if (offset_count_ >= 3) {
    std::array<double, kOffsetWindow> sorted;
    std::copy_n(offsets_.begin(), offset_count_, sorted.begin());
    const auto mid = sorted.begin() + offset_count_ / 2;
    std::nth_element(sorted.begin(), mid, sorted.begin() + offset_count_);
    const double off = 1e-9 * (offset - *mid);
    if (!(std::abs(off) <= limits_.max_delay_s))
      return reject(note, Rejection::stale,
                    "stamped %.3g s off the vehicle's clock as its other states show (more "
                    "than %.3g s)",
                    off, limits_.max_delay_s);
  }
  if (taken_ && (m.command_step < last_step_ ||
                 (m.command_step == last_step_ && m.command_age_s <= last_age_s_)))
    return reject(note, Rejection::stale,
                  "step %.6g at age %.3g s is not after the last state taken (step %.6g)",
                  double(m.command_step), m.command_age_s, double(last_step_));
  taken_ = true;
  last_step_ = m.command_step;
  last_age_s_ = m.command_age_s;
  return Rejection::none;
}

// --- Rotor commands --------------------------------------------------------------------------

void CommandCheck::setup(const Limits& limits) {
  limits_ = limits;
  taken_ = false;
  last_step_ = -1;
  last_due_ = -1.0;
}

std::int64_t CommandCheck::max_first_step() const {
  return std::int64_t(std::ceil(limits_.max_delay_s / limits_.dt));
}

Rejection CommandCheck::check(const CommandFields& m, std::int64_t now, RejectionNote& note) {
  if (m.nu != std::uint32_t(limits_.nu))
    return reject(note, Rejection::bad_size, "%.0f rotor values, this vehicle has %.0f", m.nu,
                  limits_.nu);
  const double range = limits_.u_max - limits_.u_min;
  for (std::uint32_t i = 0; i < m.nu; ++i) {
    const double u = m.u[i];
    if (!(u >= limits_.u_min - range && u <= limits_.u_max + range))
      return reject(note, Rejection::bad_value,
                    "rotor %.0f commanded %.3g, farther from its limit %.3g than the rotors' "
                    "whole range: not a rotor command",
                    i, u, u < limits_.u_min ? limits_.u_min : limits_.u_max);
  }
  if (m.step < 0)
    return reject(note, Rejection::stale, "step %.6g, before a flight's first (0)",
                  double(m.step));
  if (!taken_) {
    if (m.step > max_first_step())
      return reject(note, Rejection::stale,
                    "a first step %.6g: a controller starts its flight at step 0", double(m.step));
    taken_ = true;
    first_step_ = m.step;
    first_stamp_ = m.stamp_ns;
    first_arrival_ = now;
    last_step_ = m.step;
    last_due_ = double(m.step);
    return Rejection::none;
  }
  // Steps and stamps advance with this clock, from the first command taken.
  const double elapsed = 1e-9 * double(now - first_arrival_);
  const double due = double(first_step_) + elapsed / limits_.dt;  // the step due now
  const double ahead_s = (double(m.step) - due) * limits_.dt;
  if (ahead_s > limits_.max_delay_s)
    return reject(note, Rejection::stale,
                  "step %.6g is %.3g s ahead of the controller's pace (%.3g s after its first "
                  "command)",
                  double(m.step), ahead_s, elapsed);
  const double stamped = 1e-9 * (double(m.stamp_ns) - double(first_stamp_));
  if (stamped > elapsed + limits_.max_delay_s)
    return reject(note, Rejection::stale,
                  "stamped %.3g s after the first command, which arrived only %.3g s ago",
                  stamped, elapsed);
  const double nominal = double(m.step - first_step_) * limits_.dt;
  if (stamped < nominal - limits_.max_delay_s)
    return reject(note, Rejection::stale,
                  "stamped %.3g s after the first command, %.3g s of steps after it", stamped,
                  nominal);
  if (!(double(m.step) > last_due_))
    return reject(note, Rejection::stale, "step %.6g is not after the last one taken (%.6g)",
                  double(m.step), double(last_step_));
  last_step_ = m.step;
  // A step ahead of the pace orders as the step due now: it cannot make the honest steps after
  // it look old.
  last_due_ = std::min(double(m.step), std::max(due, last_due_));
  return Rejection::none;
}

}  // namespace mixpilot::net
