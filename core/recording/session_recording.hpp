#pragma once
// Sessions to and from recordings (core/recording/recording.hpp): a telemetry sink that records
// every control step of any mode, and a pilot source that replays a recording's pilot commands
// into a fresh mixed-initiative session. With the same scenario and build, a replay reproduces
// the original telemetry exactly.
//
// The writer thread also builds the flight's debrief (core/modes/debrief.hpp) from the steps it
// writes, and records each event on /rosout as it closes; close() records those still open.
//
// The sink never writes on the stepping thread: on_sample() copies the step's telemetry into a
// ring of slots sized at open(), and a writer thread beside the session encodes and writes it.
// A full ring either waits for the writer (lossless, for as-fast-as-possible runs: nothing is
// lost) or drops the step and counts it (real time: the control step never waits on the disk).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/control/pilot.hpp"
#include "core/modes/debrief.hpp"
#include "core/modes/session.hpp"
#include "core/recording/recording.hpp"

namespace mixpilot {

class RecordingSink final : public TelemetrySink {
 public:
  enum class FullRing { wait, drop };

  struct Settings {
    FullRing when_full = FullRing::wait;
    int slots = 256;  // steps the writer may lag behind
  };

  RecordingSink() = default;
  ~RecordingSink() override;
  RecordingSink(const RecordingSink&) = delete;
  RecordingSink& operator=(const RecordingSink&) = delete;

  // Opens `path` for a session of `mode`, whose current telemetry gives the slot sizes, and
  // starts the writer thread. The file is written as a temporary beside `path` until close()
  // (core/base/output_file.hpp); an existing file at `path` is replaced only with
  // `overwrite`, and never one that is not a regular file.
  bool open(const std::string& path, const Mode& mode, const SessionInfo& info,
            std::string& error, const Settings& settings, bool overwrite = false);
  bool open(const std::string& path, const Mode& mode, const SessionInfo& info,
            std::string& error) {
    return open(path, mode, info, error, Settings{});
  }
  // Hands the step to the writer. Allocates nothing; waits only when the ring is full and
  // the settings say so.
  void on_sample(const Telemetry& sample) override;
  // Writes what is queued, stops the writer and completes the file, ending it with the
  // "mixpilot_end" record (RecordingEnd: `interrupted` for a flight stopped before its end, the
  // steps recorded and dropped); false with a message if anything failed on the way.
  bool close(std::string& error, bool interrupted = false);
  // The temporary being written (where a failed or crashed run's data is).
  const std::string& temp_path() const { return recorder_.writer().tmp_path(); }

  std::int64_t dropped() const { return dropped_.load(); }  // steps lost to a full ring
  // The debrief's events recorded so far (read it after close(): the writer thread builds it).
  const std::vector<DebriefEvent>& events() const { return debrief_.events(); }

 private:
  void writer_loop();
  void write(const Telemetry& s);
  void write_events();  // the debrief's events closed since the last call, on /rosout

  SessionRecorder recorder_;
  Settings settings_;
  ModeKind mode_ = ModeKind::mixed_initiative;
  std::string pilot_name_;
  std::vector<Telemetry> slots_;
  std::atomic<std::uint64_t> head_{0};  // steps handed over (written by on_sample)
  std::atomic<std::uint64_t> tail_{0};  // steps written (written by the writer)
  std::atomic<bool> closing_{false};
  std::atomic<std::int64_t> dropped_{0};
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  std::thread writer_;
  bool open_ = false;

  // Message buffers of the writer thread.
  PilotCommandMsg pilot_;
  VehicleStateMsg state_;
  AppliedCommandMsg applied_;
  SolverStatsMsg solver_;
  PredictionMsg prediction_;
  JoyMsg joy_;
  ModeChannelsMsg channels_;
  LambdaReasonMsg reason_;
  InstructorCommandMsg command_;
  // The debrief, built on the writer thread.
  DebriefBuilder debrief_;
  std::size_t logged_ = 0;  // events recorded
  LogMsg log_;
};

// An instructor's command as recorded at `step`, and back: nullopt with what is wrong when the
// message holds an unknown kind, a value that is not finite or out of range
// (invalid_reason()), or a marker text longer than DebriefNote::kCapacity bytes or with
// control characters.
InstructorCommandMsg to_message(const InstructorCommand& c, std::uint64_t step);
std::optional<InstructorCommand> from_message(const InstructorCommandMsg& m, std::string& why);
// The recording's commands at their steps, for Mode::replay_commands(); nullopt with
// "<path>: its /instructor/command message N (step K) ..." when one is bad or they are not in
// the order of their steps.
std::optional<std::vector<StepCommand>> recorded_commands(const RecordingContents& rec,
                                                          const std::string& path,
                                                          std::string& error);

class ReplayPilot final : public PilotSource {
 public:
  // `commands` of the steps first_step, first_step + 1, ... (a branch's recording starts at its
  // take-over step, SPEC §10; any other at 0).
  ReplayPilot(std::vector<PilotCommandMsg> commands, std::string name, std::int64_t first_step = 0)
      : commands_(std::move(commands)), name_(std::move(name)), first_(first_step) {}
  std::string name() const override { return name_; }
  // The recorded command of this step; false outside the recorded steps.
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override;
  // Keeps nothing (save() leaves the state null): its position in the recording is the step.
  // Restored with a snapshot of any flight of the recorded scenario, it flies the recorded
  // commands from the snapshot's step on.
  [[nodiscard]] bool restore(const PilotState*) override { return true; }
  // The recorded commands hold any input loss as it was flown.
  [[nodiscard]] bool lose_input(std::int64_t) override { return true; }

 private:
  std::vector<PilotCommandMsg> commands_;
  std::string name_;
  std::int64_t first_ = 0;
};

}  // namespace mixpilot
