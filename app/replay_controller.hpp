#pragma once
// A recording's replay in the app (SPEC §8 "Replay"): the tape flown again on its loader thread,
// the playhead, the speed and the debrief's events (SPEC §10: the Debrief panel's list and the
// timeline's ticks, rebuilt from the replayed telemetry), the one selected; its transport's and
// the panel's requests move them. Open from File → Open or `mixpilot replay`; closed by leaving
// it (Esc) or opening another file.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/flight_rig.hpp"
#include "app/ghost.hpp"
#include "app/replay_tape.hpp"
#include "app/status_line.hpp"
#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

class ReplayController {
 public:
  // `command` names the command in messages; `allow_mismatch`: a replay that differs from its
  // recording is no failure (--allow-mismatch).
  // `ghost`: a recording that flies along every replay of its scenario (replay --ghost; ""
  // none).
  ReplayController(const char* command, bool allow_mismatch, StatusLine& status,
                   std::string ghost = "");
  ~ReplayController();
  ReplayController(const ReplayController&) = delete;
  ReplayController& operator=(const ReplayController&) = delete;

  // The recording at `path` made ready to replay; nullopt with the reason. Nothing changes
  // until open() (the caller may close what the replay replaces in between).
  [[nodiscard]] std::unique_ptr<FlightRig> prepare(const std::string& path,
                                                 std::string& error) const;
  // Shows the prepared replay of `path`, loading on its thread, the playhead at 0.
  void open(std::unique_ptr<FlightRig> rig, const std::string& path);
  void close();
  bool is_open() const { return tape_ != nullptr; }

  void play() { info_.playing = true; }
  void seek(double t) { info_.t = std::max(0.0, t); }  // [s] the playhead
  void load();  // flies the whole replay now (headless), with a progress bar, and reads its ghost
  // Why the ghost was refused ("" when it flies along, or there is none).
  const std::string& ghost_error() const { return ghost_error_; }

  // The transport's requests (ignored while no replay is open).
  void handle(const ui::ReplayRequest& r);
  // Once a frame: `wall_dt` [s] advances a playing replay; the snapshot's transport in `run`.
  void update(double wall_dt, ui::RunInfo& run);

  // While open. What the screen draws: the scene, and the tape up to the playhead.
  const ui::Scene& scene() const { return tape_->scene(); }
  ui::History shown() const;
  // Played to its end, every step loaded.
  bool over() const;
  // Fly from here: the step under the playhead, when a pilot flies this mode and the step is
  // loaded (−1 otherwise); pauses the replay there.
  std::int64_t fly_from_here();
  // While the moment is made ready: the part of the way flown (−1: done, or not taking over).
  void set_taking_over(double progress) { info_.taking_over = progress; }
  double shown_time() const;  // [s] of the step on screen (−1: none loaded yet)
  const ReplayTape* tape() const { return tape_.get(); }

  // Stops the loader and prints the summary; `status` with kExitReplayMismatch where the
  // replay differs from the recording.
  [[nodiscard]] int finish(int status);

 private:
  const char* command_;
  bool allow_mismatch_;
  StatusLine& status_;
  std::unique_ptr<ReplayTape> tape_;
  // Outlives the tape: the screen keeps showing it until another flight is shown.
  ui::ReplayInfo info_;
  bool events_final_ = false;  // the debrief's events are those of the whole tape
  double speed_ = 1.0;
  // The ghost (app/ghost.hpp): its recording, read off the UI thread for each replay opened.
  void poll_ghost();
  std::string ghost_path_, ghost_error_;
  std::unique_ptr<GhostLoader> ghost_loader_;
  std::vector<std::unique_ptr<GhostLoader>> ghost_retired_;  // of replays closed: joined once done
};

}  // namespace mixpilot::cli
