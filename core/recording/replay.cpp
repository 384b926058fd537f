#include "core/recording/replay.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>
#include <cstdio>
#include <cstdlib>

#include "core/modes/make_mode.hpp"
#include "core/recording/branch_replay.hpp"
#include "core/modes/report.hpp"
#include "core/base/input_file.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot {

const std::string* embedded_scenario(const RecordingContents& rec, const std::string& path,
                                     std::string& error) {
  const auto it = rec.metadata.find("scenario");
  if (it != rec.metadata.end()) return &it->second;
  error = path + ": no embedded scenario in the 'mixpilot' metadata record";
  return nullptr;
}

std::string embedded_scenario_source(const RecordingContents& rec, const std::string& path) {
  const auto it = rec.metadata.find("scenario_path");
  // A path with control characters is no file anyone saved a scenario in; it would only carry
  // them into messages.
  if (it != rec.metadata.end() && !it->second.empty() && it->second.front() == '/' &&
      escape_controls(it->second) == it->second)
    return it->second;
  return path + " (embedded scenario)";
}

Metrics replay_metrics(const Mode& mode, const RecordingContents& rec) {
  std::vector<double> recorded_us(rec.solver.size());
  for (std::size_t k = 0; k < rec.solver.size(); ++k) recorded_us[k] = rec.solver[k].total_us;
  return with_lost_fields(mode.replayed_metrics(recorded_us), mode);
}

std::string in_embedded_scenario(const std::string& path, const std::string& error) {
  return path + ": its embedded scenario: " + error;
}

std::optional<Assistance> recorded_assistance(const RecordingContents& rec,
                                              const std::string& path, std::string& error) {
  const auto it = rec.metadata.find("assist");
  if (it == rec.metadata.end() || it->second == "on") return Assistance::on;
  if (it->second == "off") return Assistance::off;
  error = path + ": its 'assist' metadata is '" + printable(it->second) +
          "', expected on or off";
  return std::nullopt;
}

std::optional<AuthorityBounds> recorded_bounds(const RecordingContents& rec,
                                               const std::string& path, std::string& error) {
  AuthorityBounds b;
  const auto read = [&](const char* key, double& out) {
    const auto it = rec.metadata.find(key);
    if (it == rec.metadata.end()) return true;
    const std::string& text = it->second;
    double v = 0.0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (r.ec != std::errc{} || r.ptr != text.data() + text.size() || !std::isfinite(v)) {
      error = path + ": its '" + key + "' metadata is '" + printable(text) +
              "', expected a number from 0 to 1";
      return false;
    }
    out = v;
    return true;
  };
  if (!read("authority_floor", b.floor) || !read("authority_ceiling", b.ceiling))
    return std::nullopt;
  if (!b.valid()) {
    char text[160];
    std::snprintf(text, sizeof text,
                  ": its authority bounds (floor %.17g, ceiling %.17g) are not 0 <= floor <= "
                  "ceiling <= 1",
                  b.floor, b.ceiling);
    error = path + text;
    return std::nullopt;
  }
  return b;
}

namespace {

// The steps of the recorded (real-time) flight marked with `event`.
std::vector<std::int64_t> recorded_steps(const RecordingContents& rec, std::uint32_t event) {
  std::vector<std::int64_t> steps;
  for (const ModeChannelsMsg& c : rec.channels)
    if (c.events & event) steps.push_back(std::int64_t(c.step));
  return steps;
}

// The planned length of the recorded flight in steps (its metadata), or 0 where a recording
// older than the key does not say.
std::int64_t planned_steps(const RecordingContents& rec) {
  const auto it = rec.metadata.find("planned_steps");
  if (it == rec.metadata.end()) return 0;
  char* end = nullptr;
  const long long n = std::strtoll(it->second.c_str(), &end, 10);
  return end != it->second.c_str() && *end == '\0' && n > 0 && n <= (1ll << 40) ? n : 0;
}

}  // namespace

std::unique_ptr<Mode> replay_own_steps(const RecordingContents& rec, const std::string& path,
                                     const std::string& text, const std::string& source,
                                     std::optional<double> duration, Assistance assist,
                                     std::string& error) {
  const auto kind = scenario_mode(text, source, error);
  if (!kind) return nullptr;
  const bool mi = *kind == "mixed_initiative";
  // As many steps as were recorded (an interrupted run, or one flown with --duration), in a
  // flight of the planned length: the metrics are those the flight had. A branch's recorded
  // steps come after its parent's, from its first step on.
  const std::int64_t first = first_recorded_step(rec);
  const auto recorded = first + std::int64_t(mi ? rec.pilot.size() : rec.states.size());
  const double dt = rec.control_period_ns > 0 ? 1e-9 * double(rec.control_period_ns) : 0.0;
  ModeRequest request;
  request.duration = duration;
  if (!duration && dt > 0.0)
    request.duration = double(std::max(planned_steps(rec), recorded)) * dt;
  if (mi) {
    const std::optional<AuthorityBounds> bounds = recorded_bounds(rec, path, error);
    if (!bounds) return nullptr;
    request.bounds = *bounds;
    request.assist = assist;
    request.pilot_source = std::make_unique<ReplayPilot>(rec.pilot, "replay:" + path, first);
  }
  // The instructor's commands (SPEC §10), applied again at the steps they took effect at.
  std::optional<std::vector<StepCommand>> commands = recorded_commands(rec, path, error);
  if (!commands) return nullptr;
  auto mode = make_mode(text, source, std::move(request), error);
  if (mode) mode->replay_commands(std::move(*commands));
  if (mode && !duration) mode->stop_after(recorded);
  // What depended on the wall clock is replayed as recorded: the overruns' fallbacks and the
  // deadline misses.
  if (mode)
    mode->replay_timing(recorded_steps(rec, kEventOverrun), recorded_steps(rec, kEventDeadlineMiss));
  return mode;
}

std::unique_ptr<Mode> replay_mode(const RecordingContents& rec, const std::string& path,
                                  const std::string& text, const std::string& source,
                                  std::optional<double> duration, std::string& error, int depth) {
  if (const auto v = rec.metadata.find("vehicle"); v != rec.metadata.end() && !v->second.empty()) {
    error = path + " was flown with a remote vehicle (--vehicle " + printable(v->second) +
            "): its plant ran in another process, so the flight cannot be flown again here";
    return nullptr;
  }
  const std::optional<Assistance> assist = recorded_assistance(rec, path, error);
  if (!assist) return nullptr;
  std::optional<ParentLink> parent;
  if (!parent_link(rec, path, parent, error)) return nullptr;
  if (parent) return branch_replay_mode(rec, path, *parent, text, source, duration, depth, error);
  auto mode = replay_own_steps(rec, path, text, source, duration, *assist, error);
  const auto embedded = rec.metadata.find("scenario");
  if (!mode && embedded != rec.metadata.end() && embedded->second == text)
    error = in_embedded_scenario(path, error);
  return mode;
}

std::int64_t first_recorded_step(const RecordingContents& rec) {
  std::optional<ParentLink> parent;
  std::string ignored;  // a malformed link: replay_mode() refuses the recording
  return parent_link(rec, "", parent, ignored) && parent ? parent->step : 0;
}

namespace {

bool same(const std::vector<double>& recorded, const Eigen::VectorXd& v) {
  return recorded.size() == std::size_t(v.size()) &&
         std::equal(v.data(), v.data() + v.size(), recorded.begin());
}

bool same(const LambdaReasonMsg& recorded, const Telemetry& s) {
  const LambdaReason& r = s.reason;
  return recorded.lambda == s.lambda && recorded.ph_index == r.ph_index &&
         recorded.d_res == r.d_res && recorded.node == r.node && recorded.ahead == r.ahead &&
         recorded.direction[0] == r.direction(0) && recorded.direction[1] == r.direction(1) &&
         recorded.direction[2] == r.direction(2) && recorded.cap == std::uint8_t(r.cap);
}

}  // namespace

void ReplayCheck::on_sample(const Telemetry& s) {
  if (first_ >= 0 || s.step < first_step_) return;
  const auto k = std::size_t(s.step - first_step_);
  const char* what = nullptr;
  if (k >= rec_->states.size() || !same(rec_->states[k].x, s.x)) {
    what = "state";
  } else if (k >= rec_->applied.size() || !same(rec_->applied[k].u, s.u)) {
    what = "applied input";
  } else if (s.mode == ModeKind::mixed_initiative &&
             (k >= rec_->lambda.size() || rec_->lambda[k].lambda != s.lambda)) {
    what = "lambda";
  } else if (s.mode == ModeKind::mixed_initiative && !rec_->reasons.empty() &&
             (k >= rec_->reasons.size() || !same(rec_->reasons[k], s))) {
    // Recordings older than the topic have none: their λ alone is checked.
    what = "lambda reason";
  } else if (!same_commands(s)) {
    what = "instructor's commands";
  }
  if (what) {
    first_ = s.step;
    what_ = what;
  }
}

// The recorded /instructor/command messages of step s.step, in order, against the step's.
bool ReplayCheck::same_commands(const Telemetry& s) {
  const std::vector<InstructorCommandMsg>& recorded = rec_->commands;
  std::size_t& n = next_command_;
  while (n > 0 && std::int64_t(recorded[n - 1].step) >= s.step) --n;
  while (n < recorded.size() && std::int64_t(recorded[n].step) < s.step) ++n;
  int i = 0;
  for (; n < recorded.size() && std::int64_t(recorded[n].step) == s.step; ++n, ++i) {
    if (i >= s.num_commands) return false;
    const InstructorCommand& c = s.commands[std::size_t(i)];
    const InstructorCommandMsg& m = recorded[n];
    if (m.kind != std::uint8_t(c.kind) || m.floor != c.bounds.floor ||
        m.ceiling != c.bounds.ceiling || m.force[0] != c.force(0) || m.force[1] != c.force(1) ||
        m.force[2] != c.force(2) || m.duration != c.duration || m.delay != c.delay ||
        std::string_view(m.text) != c.text.view())
      return false;
  }
  return i == s.num_commands;
}

bool ReplayCheck::matches(std::int64_t steps) const {
  return first_difference(steps).empty();
}

std::string ReplayCheck::difference_so_far() const {
  if (first_ < 0) return "";
  return std::string("the ") + what_ + " of step " + std::to_string(first_) +
         " differs from the recorded one";
}

std::string ReplayCheck::first_difference(std::int64_t steps) const {
  if (first_ >= 0) return difference_so_far();
  // A branch's steps are counted from its first (the take-over's), as are its parent's.
  const std::int64_t own = steps - first_step_;
  const std::string from =
      first_step_ > 0 ? " from the take-over at step " + std::to_string(first_step_) : "";
  if (own != std::int64_t(rec_->states.size()))
    return std::to_string(std::max<std::int64_t>(own, 0)) + " steps replayed" + from + ", " +
           std::to_string(rec_->states.size()) + " recorded";
  if (!rec_->pilot.empty() && own != std::int64_t(rec_->pilot.size()))
    return std::to_string(own) + " steps replayed" + from + ", " +
           std::to_string(rec_->pilot.size()) + " pilot commands recorded";
  return "";
}

std::string recording_ended_early(const RecordingContents& rec, const Mode& replayed) {
  if (!rec.end || !rec.end->interrupted) return "";
  char buf[96];
  std::snprintf(buf, sizeof buf, "interrupted at t = %.1f s of %.1f s",
                double(replayed.steps_done()) * replayed.dt(),
                double(replayed.steps_total()) * replayed.dt());
  return buf;
}

}  // namespace mixpilot
