#pragma once
// The application (SPEC §8), whatever draws it. It holds one controller per lifecycle — the
// live flight with the session's choices, a recording's replay, the input settings with the
// gamepad, the mapping wizard — and the UI's own state. One frame, build_frame() between
// ImGui::NewFrame() and ImGui::Render(): the controllers bring the frame's snapshot up to date
// (ui::RunInfo), the screen draws it, and each request the user made goes to the controller it
// concerns. The window (app/window.cpp), the headless renderer and the tests drive the same
// object.
#include <memory>
#include <string>
#include <vector>

#include "app/clip_export.hpp"
#include "app/flight.hpp"
#include "app/history_writer.hpp"
#include "app/input_controller.hpp"
#include "app/live_controller.hpp"
#include "app/replay_controller.hpp"
#include "app/replay_tape.hpp"
#include "app/status_line.hpp"
#include "app/take_over.hpp"
#include "app/window_settings.hpp"
#include "app/wizard_controller.hpp"
#include "ui/requests.hpp"
#include "ui/score_card.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

class Trainer {
 public:
  // `o`: the command line's flight (scenario, pilot, --record, --report, ...).
  explicit Trainer(FlyOptions o);
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;

  // The first live flight from the options, ready to start; false with the reason and status.
  [[nodiscard]] bool open_live(std::string& error, int& status);
  // A recording to replay (File → Open, `mixpilot replay`); false with the reason.
  [[nodiscard]] bool open_replay(const std::string& path, std::string& error);

  // One frame: takes the newest telemetry, draws the screen, acts on the user's requests.
  // `wall_dt` [s] advances a playing replay.
  void build_frame(double wall_dt);

  // What a request of the screen does (build_frame passes each frame's through here).
  void act(const ui::Request& r);
  void start();            // Start: the live flight flies / the replay plays
  void seek(double t) { replay_.seek(t); }  // a replay's playhead [s]
  void load_replay() { replay_.load(); }    // flies the whole replay now (headless)
  bool replaying() const { return replay_.is_open(); }
  // The first launch's welcome is still to be decided: it waits for the history to be read.
  bool welcome_undecided() const { return welcome_pending_; }
  // The live flight's run is over and every step has been drawn; a replay played to its end.
  bool over() const;
  double shown_time() const;  // [s] of the telemetry on screen (−1: none yet)
  ui::UiState& ui_state() { return ui_; }
  const ui::RunInfo& run_info() const { return run_; }
  const LiveFlight* live() const { return live_.flight(); }
  const ReplayTape* replay() const { return replay_.tape(); }
  // replay --ghost: why its recording was refused ("" none, or it flies along).
  const std::string& replay_ghost_error() const { return replay_.ghost_error(); }
  HistoryWriter* history() { return history_.get(); }
  ClipExporter& clips() { return clips_; }
  // Fly from here (SPEC §10): the moment being made ready off the UI thread (nullptr: none).
  const TakeOver* taking_over() const { return take_over_.get(); }
  // The user's text size, a factor on the display's scale (window.toml; the window rebuilds
  // its fonts when it changes).
  float text_scale() const { return window_settings_.text_scale; }

  // Stops the flight (closing its recording) and the replay; prints the summary, writes the
  // report; returns the exit status (kExitReplayMismatch for a replay that differs).
  [[nodiscard]] int finish();

 private:
  void open_file(const std::string& path);  // File → Open: a scenario or a recording
  void poll_history();                       // the writer's outcomes and newest snapshot
  void leave_replay();
  void fly_from_here();    // the replay's playhead: a moment made ready for a live flight
  void poll_take_over();   // ... and once it is, the live flight READY there
  // The first launch: the welcome shows once the history says it has no flight (at once
  // without a history), unless it was dismissed; its choices, and it done with (saved).
  void update_welcome();
  void first_launch(const ui::FirstLaunchChoice& c);
  void save_window_settings(const char* what);
  // The score card of the flight on screen (ui/score_card.hpp), made again when what it is
  // made of changes (the history's snapshot, the debrief, the flight).
  void update_card();

  // Declared before the controllers, which say things into it and outlive none of it.
  ui::RunInfo run_;  // the frame's snapshot
  StatusLine status_{run_};
  // "Export clip": outlives the replay it was asked from (the file is written on its own).
  ClipExporter clips_{status_};
  InputController input_;
  WizardController wizard_;
  // Before live_: a flight closing hands its row to it (nullptr: --history off).
  std::unique_ptr<HistoryWriter> history_;
  std::vector<HistoryWriter::Outcome> outcomes_;   // polled each frame, capacity kept
  std::shared_ptr<const ui::HistoryView> history_view_;  // the frame's (run_.history)
  LiveController live_;
  ReplayController replay_;
  std::unique_ptr<TakeOver> take_over_;  // after replay_: it outlives no replay
  ui::UiState ui_;
  // window.toml: the text size and whether the welcome was done with.
  WindowSettings window_settings_;
  bool welcome_pending_ = false;  // the welcome may show, once the history is read
  ui::ScoreCard card_;
  // What card_ was made of: the flight or replay, its metrics, its debrief, the history.
  struct CardKey {
    const void* flight = nullptr;
    std::size_t metrics = 0;
    const void* events = nullptr;
    std::size_t event_count = 0;
    bool events_ready = false;
    const void* history = nullptr;
    std::string verdict;  // a lesson step's, once the session panel has it
    bool operator==(const CardKey&) const = default;
  };
  CardKey card_for_;
  ui::Requests requests_;  // this frame's; cleared each frame, its capacity kept
};

}  // namespace mixpilot::cli
