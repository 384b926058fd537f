#include "core/recording/session_recording.hpp"

#include <chrono>
#include <cmath>

#include "core/base/input_file.hpp"

namespace mixpilot {

RecordingSink::~RecordingSink() {
  if (open_) {
    // Never closed: the run ended some other way (an exception), so not at its scheduled end.
    std::string ignored;
    (void)close(ignored, /*interrupted=*/true);
  }
}

bool RecordingSink::open(const std::string& path, const Mode& mode, const SessionInfo& info,
                         std::string& error, const Settings& settings, bool overwrite) {
  if (open_) {
    error = path + ": the recorder is already open";
    return false;
  }
  settings_ = settings;
  mode_ = mode.kind();
  pilot_name_ = info.pilot;
  const auto period_ns = std::uint64_t(std::llround(mode.dt() * 1e9));
  SessionInfo planned = info;
  planned.planned_steps = mode.steps_total();
  planned.bounds = mode.authority_bounds();
  if (!recorder_.open(path, period_ns, planned, error, overwrite)) return false;
  debrief_.setup(debrief_settings(mode));
  logged_ = 0;
  log_ = LogMsg{};
  log_.name = kDebriefLogger;
  // Slots sized like the mode's telemetry: copying a step into one then allocates nothing.
  slots_.assign(std::size_t(std::max(settings.slots, 2)), mode.telemetry());
  head_ = 0;
  tail_ = 0;
  closing_ = false;
  dropped_ = 0;
  open_ = true;
  writer_ = std::thread([this] { writer_loop(); });
  return true;
}

void RecordingSink::on_sample(const Telemetry& sample) {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  const std::uint64_t n = slots_.size();
  while (head - tail_.load(std::memory_order_acquire) >= n) {
    if (settings_.when_full == FullRing::drop) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
  slots_[head % n] = sample;
  head_.store(head + 1, std::memory_order_release);
  wake_.notify_one();
}

void RecordingSink::writer_loop() {
  const std::uint64_t n = slots_.size();
  for (;;) {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (head_.load(std::memory_order_acquire) == tail) {
      if (closing_.load(std::memory_order_acquire) && head_.load(std::memory_order_acquire) == tail)
        return;
      // notify_one() from the stepping thread takes no lock, so a wake-up can slip between the
      // check and the wait: the timeout bounds that case.
      std::unique_lock<std::mutex> lock(wake_mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(2));
      continue;
    }
    write(slots_[tail % n]);
    tail_.store(tail + 1, std::memory_order_release);
  }
}

void RecordingSink::write(const Telemetry& s) {
  const auto step = std::uint64_t(s.step);
  const RosTime stamp = ros_time_from_ns(recorder_.log_time_ns(step));
  const bool mi = mode_ == ModeKind::mixed_initiative;
  if (s.has_joy) {
    joy_.stamp = stamp;
    joy_.axes.assign(s.joy.axes.begin(), s.joy.axes.begin() + s.joy.num_axes);
    joy_.buttons.assign(s.joy.buttons.begin(), s.joy.buttons.begin() + s.joy.num_buttons);
    recorder_.record_joy(step, joy_);
  }
  if (mi) {
    pilot_.stamp = stamp;
    pilot_.step = step;
    pilot_.roll = s.pilot.roll;
    pilot_.pitch = s.pilot.pitch;
    for (int i = 0; i < 4; ++i) pilot_.rotor_speed[std::size_t(i)] = s.pilot.rotor_speed(i);
    pilot_.source = pilot_name_;
    pilot_.authority = s.pilot.authority;
    pilot_.input_state = static_cast<std::uint8_t>(s.pilot.input);
    recorder_.record_pilot(pilot_);
  }

  state_.stamp = stamp;
  state_.step = step;
  state_.x.assign(s.x.data(), s.x.data() + s.x.size());
  recorder_.record_state(state_);
  if (mi) {
    recorder_.record_lambda(step, s.lambda);
    reason_.stamp = stamp;
    reason_.step = step;
    reason_.lambda = s.lambda;
    reason_.ph_index = s.reason.ph_index;
    reason_.d_res = s.reason.d_res;
    reason_.node = s.reason.node;
    reason_.ahead = s.reason.ahead;
    for (int i = 0; i < 3; ++i) reason_.direction[std::size_t(i)] = s.reason.direction(i);
    reason_.cap = static_cast<std::uint8_t>(s.reason.cap);
    recorder_.record_reason(reason_);
  }

  applied_.stamp = stamp;
  applied_.step = step;
  applied_.u.assign(s.u.data(), s.u.data() + s.u.size());
  applied_.roll = s.applied.roll;
  applied_.pitch = s.applied.pitch;
  for (int i = 0; i < 4; ++i) applied_.rotor_speed[std::size_t(i)] = s.applied.rotor_speed(i);
  recorder_.record_applied(applied_);

  solver_.stamp = stamp;
  solver_.step = step;
  solver_.status = std::uint8_t(s.stats.status);
  solver_.qp_iterations = std::uint32_t(s.stats.qp_iterations);
  solver_.integration_us = s.stats.integration_us;
  solver_.linearization_us = s.stats.linearization_us;
  solver_.qp_us = s.stats.qp_us;
  solver_.total_us = s.stats.total_us;
  solver_.fallback = s.stats.status == RtiStatus::fallback;
  recorder_.record_solver(solver_);

  if (s.predicted.cols() > 0) {
    prediction_.stamp = stamp;
    prediction_.step = step;
    prediction_.position.assign(s.predicted.data(), s.predicted.data() + s.predicted.size());
    prediction_.reference.assign(s.predicted_reference.data(),
                                 s.predicted_reference.data() + s.predicted_reference.size());
    recorder_.record_prediction(prediction_);
  }

  channels_.stamp = stamp;
  channels_.step = step;
  channels_.events = s.events;
  const auto nc = std::size_t(s.num_channels);
  channels_.names.resize(nc);
  channels_.units.resize(nc);
  channels_.values.resize(nc);
  for (std::size_t i = 0; i < nc; ++i) {
    channels_.names[i] = s.channels[i].name;
    channels_.units[i] = s.channels[i].unit;
    channels_.values[i] = s.channels[i].value;
  }
  recorder_.record_channels(channels_);

  for (int i = 0; i < s.num_commands; ++i) {
    const InstructorCommand& c = s.commands[std::size_t(i)];
    command_.stamp = stamp;
    command_.step = step;
    command_.kind = static_cast<std::uint8_t>(c.kind);
    command_.floor = c.bounds.floor;
    command_.ceiling = c.bounds.ceiling;
    for (int j = 0; j < 3; ++j) command_.force[std::size_t(j)] = c.force(j);
    command_.duration = c.duration;
    command_.delay = c.delay;
    command_.text.assign(c.text.view());
    recorder_.record_command(command_);
  }

  debrief_.add(s);
  write_events();
}

InstructorCommandMsg to_message(const InstructorCommand& c, std::uint64_t step) {
  InstructorCommandMsg m;
  m.stamp = RosTime{};
  m.step = step;
  m.kind = static_cast<std::uint8_t>(c.kind);
  m.floor = c.bounds.floor;
  m.ceiling = c.bounds.ceiling;
  for (int j = 0; j < 3; ++j) m.force[std::size_t(j)] = c.force(j);
  m.duration = c.duration;
  m.delay = c.delay;
  m.text.assign(c.text.view());
  return m;
}

std::optional<InstructorCommand> from_message(const InstructorCommandMsg& m, std::string& why) {
  const std::optional<InstructorCommandKind> kind = instructor_command_kind(m.kind);
  if (!kind) {
    why = "its kind is " + std::to_string(m.kind) + ", expected 0 to " +
          std::to_string(kInstructorCommandKindCount - 1);
    return std::nullopt;
  }
  if (m.text.size() > DebriefNote::kCapacity) {
    why = "its text is " + std::to_string(m.text.size()) + " bytes long, expected at most " +
          std::to_string(DebriefNote::kCapacity);
    return std::nullopt;
  }
  if (escape_controls(m.text) != m.text) {
    why = "its text holds control characters";
    return std::nullopt;
  }
  InstructorCommand c;
  c.kind = *kind;
  c.bounds = AuthorityBounds{m.floor, m.ceiling};
  c.force = Eigen::Vector3d(m.force[0], m.force[1], m.force[2]);
  c.duration = m.duration;
  c.delay = m.delay;
  c.text.assign(m.text);
  if (const char* bad = invalid_reason(c)) {
    why = std::string("a ") + to_string(c.kind) + " whose values are out of range: " + bad;
    return std::nullopt;
  }
  return c;
}

std::optional<std::vector<StepCommand>> recorded_commands(const RecordingContents& rec,
                                                          const std::string& path,
                                                          std::string& error) {
  std::vector<StepCommand> out;
  out.reserve(rec.commands.size());
  for (std::size_t i = 0; i < rec.commands.size(); ++i) {
    const InstructorCommandMsg& m = rec.commands[i];
    const std::string which = path + ": its /instructor/command message " + std::to_string(i + 1) +
                              " (step " + std::to_string(m.step) + ") ";
    std::string why;
    const std::optional<InstructorCommand> c = from_message(m, why);
    if (!c) {
      error = which + "is refused: " + why;
      return std::nullopt;
    }
    if (m.step > (std::uint64_t(1) << 40) || (!out.empty() && std::int64_t(m.step) < out.back().step)) {
      error = which + "is refused: its step is out of order";
      return std::nullopt;
    }
    std::size_t same_step = 0;
    for (auto it = out.rbegin(); it != out.rend() && it->step == std::int64_t(m.step); ++it)
      ++same_step;
    if (same_step >= std::size_t(kMaxCommandsPerStep)) {
      error = which + "is refused: a step takes at most " + std::to_string(kMaxCommandsPerStep) +
              " commands";
      return std::nullopt;
    }
    out.push_back({std::int64_t(m.step), *c});
  }
  return out;
}

void RecordingSink::write_events() {
  const std::vector<DebriefEvent>& events = debrief_.events();
  const double r = debrief_.settings().ball_radius;
  for (; logged_ < events.size(); ++logged_) {
    const DebriefEvent& e = events[logged_];
    log_.stamp = ros_time_from_ns(recorder_.log_time_ns(std::uint64_t(e.start_step)));
    log_.level = static_cast<std::uint8_t>(log_level(e.kind));
    char words[320];
    log_.msg.assign(words, describe(e, r, words, sizeof words));
    log_.function = to_string(e.kind);
    recorder_.record_log(std::uint64_t(e.closed_step), log_);
  }
}

bool RecordingSink::close(std::string& error, bool interrupted) {
  if (!open_) {
    error = "the recorder is not open";
    return false;
  }
  closing_.store(true, std::memory_order_release);
  wake_.notify_one();
  writer_.join();
  open_ = false;
  // The events still open end with the flight (after the last step recorded).
  debrief_.finish();
  write_events();
  return recorder_.close(error, interrupted, std::uint64_t(dropped_.load()));
}

bool ReplayPilot::command(std::int64_t step, double, const Eigen::VectorXd&, PilotCommand& out) {
  const std::int64_t i = step - first_;
  if (i < 0 || i >= std::int64_t(commands_.size())) return false;
  const PilotCommandMsg& m = commands_[std::size_t(i)];
  if (m.step != std::uint64_t(step)) return false;  // a gap: the recording is not contiguous
  out.roll = m.roll;
  out.pitch = m.pitch;
  for (int i = 0; i < 4; ++i) out.rotor_speed(i) = m.rotor_speed[std::size_t(i)];
  out.authority = m.authority;
  out.input = m.input_state <= 3 ? static_cast<InputState>(m.input_state) : InputState::lost;
  return true;
}

}  // namespace mixpilot
