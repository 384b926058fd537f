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

const char* to_string(RestoreStatus status) {
  switch (status) {
    case RestoreStatus::ok: return "";
    case RestoreStatus::empty: return "the snapshot is empty: nothing was saved into it";
    case RestoreStatus::other_kind: return "the snapshot is of another kind of mode";
    case RestoreStatus::other_scenario:
      return "the snapshot is of another scenario, or of one with another length or shape";
    case RestoreStatus::pilot: return "the pilot source cannot continue from the saved one";
    case RestoreStatus::remote_vehicle:
      return "a remote vehicle flies the mode or flew the snapshot: its plant cannot go back";
    case RestoreStatus::assistance:
      return "the snapshot was flown with the other assistance (a probe and an assisted flight)";
    case RestoreStatus::no_pilot: return "the mode has no pilot to take the flight over";
  }
  return "unknown";
}

void Mode::save(ModeSnapshot& snapshot) const {
  ModeSnapshot& s = snapshot;
  if (s.state_ && s.kind_ != kind()) s.state_.reset();
  s.kind_ = kind();
  s.scenario_name_ = scenario_name();
  s.steps_total_ = steps_total();
  s.step_ = steps_done();
  s.next_forced_ = next_forced_;
  s.next_miss_ = next_miss_;
  s.next_command_ = next_command_;
  save_state(s.state_);
}

RestoreStatus Mode::restore(const ModeSnapshot& snapshot) {
  const ModeSnapshot& s = snapshot;
  if (const RestoreStatus r = fits(s); r != RestoreStatus::ok) return r;
  if (const RestoreStatus r = restore_state(*s.state_); r != RestoreStatus::ok) return r;
  next_forced_ = s.next_forced_;
  next_miss_ = s.next_miss_;
  next_command_ = s.next_command_;
  pending_count_ = 0;
  return RestoreStatus::ok;
}

RestoreStatus Mode::take_over(const ModeSnapshot& snapshot) {
  const ModeSnapshot& s = snapshot;
  if (const RestoreStatus r = fits(s); r != RestoreStatus::ok) return r;
  if (const RestoreStatus r = take_over_state(*s.state_); r != RestoreStatus::ok) return r;
  next_forced_ = s.next_forced_;
  next_miss_ = s.next_miss_;
  next_command_ = s.next_command_;
  pending_count_ = 0;
  return RestoreStatus::ok;
}

RestoreStatus Mode::fits(const ModeSnapshot& s) const {
  if (!s.state_) return RestoreStatus::empty;
  if (s.kind_ != kind()) return RestoreStatus::other_kind;
  if (s.scenario_name_ != scenario_name() || s.steps_total_ != steps_total())
    return RestoreStatus::other_scenario;
  return RestoreStatus::ok;
}

InstructorStatus Mode::instruct(const InstructorCommand& c) {
  if (invalid_reason(c)) return InstructorStatus::bad_value;
  if (finished()) return InstructorStatus::over;
  if (pending_count_ >= kMaxCommandsPerStep) return InstructorStatus::busy;
  InstructorStatus status = InstructorStatus::applied;
  switch (c.kind) {
    case InstructorCommandKind::bounds:
      status = set_authority_bounds(c.bounds) ? InstructorStatus::applied
                                              : InstructorStatus::no_authority;
      break;
    case InstructorCommandKind::gust: status = apply_gust(c.force, c.duration); break;
    case InstructorCommandKind::extra_delay: status = apply_extra_delay(c.delay); break;
    case InstructorCommandKind::input_loss: status = apply_input_loss(c.duration); break;
    case InstructorCommandKind::marker:
    case InstructorCommandKind::pause:
    case InstructorCommandKind::resume:
    case InstructorCommandKind::end: break;
  }
  if (status == InstructorStatus::applied) pending_[std::size_t(pending_count_++)] = c;
  return status;
}

void Mode::begin_commands(std::int64_t k) {
  std::size_t& n = next_command_;
  // Forward as the steps go; back after a snapshot of an earlier step was restored.
  while (n > 0 && scheduled_[n - 1].step >= k) --n;
  while (n < scheduled_.size() && scheduled_[n].step < k) ++n;
  for (; n < scheduled_.size() && scheduled_[n].step == k; ++n)
    (void)instruct(scheduled_[n].command);  // applied when recorded: the check finds any other
}

void Mode::end_commands(Telemetry& s) {
  s.num_commands = pending_count_;
  for (int i = 0; i < pending_count_; ++i)
    s.commands[std::size_t(i)] = pending_[std::size_t(i)];
  pending_count_ = 0;
  s.instructor = in_force(s.step);
  s.instructor.bounds = authority_bounds();
}

std::string mode_kind_names() {
  std::string names;
  for (ModeKind k : kModeKinds) names += std::string(names.empty() ? "" : ", ") + to_string(k);
  return names;
}

}  // namespace mixpilot
