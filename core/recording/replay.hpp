#pragma once
// Flying a recording again: the same mode from its embedded scenario, checked step by step
// against what was recorded. Every front end replays through here, by way of the flight
// assembly (app/flight_rig.hpp): `mixpilot score`, `mixpilot fly --pilot REC.mcap`, `replay`
// and the window's replay.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/control/mi_settings.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/recording.hpp"

namespace mixpilot {

// The scenario text a recording embeds; nullptr with "<path>: no embedded scenario ..." when
// it has none.
const std::string* embedded_scenario(const RecordingContents& rec, const std::string& path,
                                     std::string& error);

// Where a recording's embedded scenario came from: its original file (absolute, as recorded),
// so that paths inside it (reference trajectories) resolve as they did; else a label.
std::string embedded_scenario_source(const RecordingContents& rec, const std::string& path);

// The metrics of a replay of `rec`: the mode's own, except that mixed initiative's timing fields
// (RTI median and p99, deadline misses) describe the recorded flight's first steps_done() steps,
// not this replay, so `fly --pilot REC` and `score REC` agree to the bit on any machine
// (Mode::replayed_metrics).
[[nodiscard]] Metrics replay_metrics(const Mode& mode, const RecordingContents& rec);

// An error found in the scenario embedded in the recording at `path`, said as such: its
// file:line:col name the file it was recorded from, which may have changed since.
[[nodiscard]] std::string in_embedded_scenario(const std::string& path, const std::string& error);

// Whether the recorded flight was assisted or a probe (its `assist` metadata; on when absent);
// nullopt with "<path>: ..." for a value other than on or off.
std::optional<Assistance> recorded_assistance(const RecordingContents& rec,
                                              const std::string& path, std::string& error);
// The authority bounds the recorded flight started with (its authority_floor /
// authority_ceiling metadata; [0, 1] when absent); nullopt with "<path>: ..." for a value that
// is not a number or bounds that are not 0 <= floor <= ceiling <= 1.
std::optional<AuthorityBounds> recorded_bounds(const RecordingContents& rec,
                                               const std::string& path, std::string& error);

// A fresh flight of `scenario_text` for the recording: mixed initiative replays the recorded
// pilot commands and is as long as they are, assisted or as a probe as it was recorded; other
// modes fly on their own for as many steps as were recorded. `duration` overrides the length.
// A branch (SPEC §10, fly from here: the recording names a parent) replays its parent up to its
// take-over first (core/recording/branch_replay.hpp); `depth` counts the branches whose parent
// this recording is (a parent's replay is asked for with depth + 1).
std::unique_ptr<Mode> replay_mode(const RecordingContents& rec, const std::string& path,
                                  const std::string& scenario_text, const std::string& source,
                                  std::optional<double> duration, std::string& error,
                                  int depth = 0);

// replay_mode()'s flight of the steps `rec` holds, flown by its own recorded commands (a
// branch's from its take-over on, without its parent), assisted or not by `assist`.
std::unique_ptr<Mode> replay_own_steps(const RecordingContents& rec, const std::string& path,
                                       const std::string& scenario_text, const std::string& source,
                                       std::optional<double> duration, Assistance assist,
                                       std::string& error);

// The first step a recording holds: a branch's take-over step (its parent_step metadata), 0 for
// any other recording.
std::int64_t first_recorded_step(const RecordingContents& rec);

// Compares each replayed step with the recorded one: the state, the applied input and, in
// mixed initiative, λ and what decided it (where the recording has /controller/lambda_reason;
// the last pilot command shows only in the last applied input), the instructor's commands of
// the step (/instructor/command), and at the end that every
// recorded step was replayed. A branch's steps before its first recorded one are its parent's:
// its replay checks those against the parent.
class ReplayCheck final : public TelemetrySink {
 public:
  explicit ReplayCheck(const RecordingContents& rec)
      : rec_(&rec), first_step_(first_recorded_step(rec)) {}
  void on_sample(const Telemetry& s) override;
  // True when every recorded step was replayed bit for bit (call after the run).
  bool matches(std::int64_t steps_replayed) const;
  // What differed first, for messages ("" when nothing did).
  std::string first_difference(std::int64_t steps_replayed) const;
  // What differed first among the steps replayed so far, however many those are ("" when
  // nothing did): a parent replayed up to a branch's take-over.
  std::string difference_so_far() const;

 private:
  bool same_commands(const Telemetry& s);

  const RecordingContents* rec_;
  std::size_t next_command_ = 0;  // into rec_->commands
  std::int64_t first_step_ = 0;  // of the recording
  std::int64_t first_ = -1;      // first differing step
  const char* what_ = "";
};

// "interrupted at t = 3.0 s of 30.0 s" when `rec` was stopped before its planned end ("" if
// not), from its replay `replayed`.
std::string recording_ended_early(const RecordingContents& rec, const Mode& replayed);

}  // namespace mixpilot
