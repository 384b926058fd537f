#pragma once
// The live flight (SPEC §8): the mode on the real-time runner's thread with its sinks and its
// recording, the wait for a remote vehicle or for a gamepad, and the session panel's choices
// for the next flight (scenario, pilot, record, trainee). Start, pause, slow motion, restart
// and the keyboard pilot's keys act on it.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/ghost.hpp"
#include "app/input_controller.hpp"
#include "app/lesson.hpp"
#include "app/status_line.hpp"
#include "core/modes/debrief.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

// One flight in the app: its assembly (app/flight_rig.hpp: the mode, session, sinks, vehicle
// link and the runner that paces it) and what the screen keeps of it.
struct LiveFlight {
  std::unique_ptr<FlightRig> rig;
  ui::Scene scene;
  ui::History history;
  Telemetry sample;  // the ring's values are copied into it (sized once)
  ui::RunInfo counts;  // fallbacks and deadline misses so far (ui::count_step)
  bool waiting = false;  // Start asked for, waiting for the gamepad
  // --vehicle dds: listening for the vehicle while the window draws on (FlightRig::
  // poll_vehicle each frame); no_vehicle: none came (or the wait was cancelled, or it cannot
  // fly this mode), so this flight cannot start. Restart waits again.
  bool awaiting_vehicle = false, no_vehicle = false;
  FlightRig::Closed closing;  // what closing the flight did (its recording, the publisher)
  Metrics metrics;   // once the run is over
  // The flight's debrief (SPEC §10), built from the telemetry as the screen takes it (the same
  // builder as the recorder's), and its rows once the run is over: the score card's events.
  DebriefBuilder debrief;
  std::vector<ui::DebriefRow> events;
  bool events_ready = false;
  // What a ghost of this flight must be a flight of (app/ghost.hpp); nullopt: it has none.
  std::optional<GhostTarget> ghost_target;

  const Flight& flight() const { return rig->flight(); }
  const Mode& mode() const { return rig->mode(); }
  RealtimeRunner& runner() const { return *rig->runner(); }
  bool started() const { return rig->started(); }
  bool closed() const { return rig->closed(); }
};

class LiveController {
 public:
  // `o`: the command line's flight (scenario, pilot, --record, --report, ...); the input
  // settings and the gamepad are `input`'s.
  // `history`: where flights are remembered and what the window shows of the history
  // (nullptr: --history off); it outlives the controller.
  LiveController(FlyOptions o, InputController& input, StatusLine& status,
                 HistoryWriter* history);
  ~LiveController();
  LiveController(const LiveController&) = delete;
  LiveController& operator=(const LiveController&) = delete;

  // The first flight of the options, ready to start; false with the reason and the status.
  [[nodiscard]] bool open(std::string& error, int& status);
  // A scenario file (File → Open) joins the choices and is flown next; its errors are said.
  void open_scenario(const std::string& path);
  // After a replay: a closed flight (or none) gives way to a new one of the same choices;
  // nothing flies when the app was opened on a recording alone (no scenario to fly).
  void reopen();
  // The input settings changed: a device flight that is not flying is made again with them.
  void settings_changed();
  // Stops the flight and completes its recording (a replay takes the screen).
  void close();
  // Fly from here (SPEC §10): the next flight goes on from `from`, a moment of a recording,
  // READY there (its screen shows `so_far`, the recording's steps up to that moment); the pilot
  // is the one chosen for live flights, else the gamepad when `pad_connected`, else the
  // keyboard, and the session panel picks another. Restart flies it from that moment again;
  // another scenario, or Fly from the start, from t = 0. False, said on the status line and
  // changing nothing, when no flight can be made of it.
  bool fly_from(std::shared_ptr<const FlyFrom> from, const ui::History& so_far,
                bool pad_connected);

  // Start: the flight flies (or waits for its vehicle or its gamepad).
  void start();
  // The live flight's and the session panel's requests (ignored while no flight is open).
  void handle(const ui::LiveRequest& r);
  // Once a frame: the newest telemetry; a flight waiting for its gamepad starts once
  // `pad_connected`; the snapshot's flight state and session choices in `run`.
  void update(bool pad_connected, ui::RunInfo& run);

  LiveFlight* flight() const { return live_.get(); }  // nullptr: none
  // The run is over and every step has been drawn (true when there is no flight).
  bool over() const;
  double shown_time() const;  // [s] of the telemetry on screen (−1: none yet)

  // Stops the flight (closing its recording); prints the summary, writes the report; returns
  // the exit status (kExitReplayMismatch for a recording's pilot that flew otherwise).
  [[nodiscard]] int finish();
  // kExitError once a recording could not be completed, else kExitOk.
  int status() const { return status_; }
  // What the history's writer did with a flight handed over: said on the status line (a
  // failure once, however many flights it costs).
  void history_outcome(const HistoryWriter::Outcome& o);

 private:
  // The flight's assembly (live_controller.cpp's first section).
  std::unique_ptr<LiveFlight> make_live(std::string& error, int& status);
  void update_vehicle_wait(LiveFlight& f);
  void close_live(LiveFlight& f);

  [[nodiscard]] bool replace_live(std::string& error);  // a new, unstarted flight of the choices
  void fly_scenario(std::size_t index);  // the next flight flies scenario_paths_[index]
  void refresh_choices();
  std::string next_record_path() const;
  // A history failure, said on the status line once (the same failure again is not repeated).
  void history_problem(const std::string& why);
  // The history's snapshot follows the session: the trainee and the scenario flown next.
  void show_progress();
  // The ghost (SPEC §10) of the flight not yet started, once a frame: the session panel's ghost
  // choices from the history's snapshot `h` (nullptr: none), the recording the choice names
  // loaded off the UI thread, then shown with the flight; a loaded or refused recording is said
  // on the status line.
  void update_ghost(LiveFlight& f, const ui::HistoryView* h);
  void ghost_options(const LiveFlight& f, const ui::HistoryView* h);
  // Lessons (SPEC §10): the lesson chosen (nullptr: none); its progress from the history's
  // snapshot `h`; a flight READY for the trainee's step; the panel's view of it.
  const Lesson* lesson() const {
    return lesson_ >= 0 ? &lessons_[std::size_t(lesson_)] : nullptr;
  }
  void load_lessons();
  void pick_lesson(int index);
  void update_lesson(const ui::HistoryView* h);
  void show_lesson();
  [[nodiscard]] bool fly_lesson_step(std::string& error);  // a new, unstarted flight of the step
  void lesson_view(const ui::HistoryView* h);

  FlyOptions options_;
  HistoryWriter* history_;  // outlives live_: its rig hands its row over at close
  std::string history_said_;
  std::string shown_trainee_, shown_scenario_;  // what the snapshot was asked for
  InputController& input_;
  StatusLine& status_line_;
  std::unique_ptr<LiveFlight> live_;
  ui::SessionChoices choices_;
  std::vector<std::string> scenario_paths_;  // parallel to choices_.scenarios
  std::string first_record_;                 // --record: the first recorded flight's path
  std::vector<std::string> recorded_;        // recordings written, for the summary
  int status_ = 0;
  // Fly from here: the moment the next flight goes on from (null: from the start), and the
  // recorded steps shown before it (the newest ones up to that moment).
  std::shared_ptr<const FlyFrom> from_;
  std::vector<Telemetry> from_shown_;
  // The ghost: what the session panel chose, the options it offers (parallel to
  // choices_.ghosts, made again when the history's snapshot or the flight changes), the
  // recording loaded for it, the loader reading one, and loaders whose result is no longer
  // wanted (kept until they finish: the UI never waits for a join).
  GhostChoice ghost_choice_;
  std::vector<GhostChoice> ghost_options_;
  const ui::HistoryView* ghost_options_of_ = nullptr;
  std::uint64_t flights_made_ = 0, ghost_options_for_ = 0;  // make_live()'s count
  std::shared_ptr<const ui::Ghost> ghost_;
  std::unique_ptr<GhostLoader> ghost_loader_;
  std::vector<std::unique_ptr<GhostLoader>> ghost_retired_;
  std::string ghost_refused_;  // the recording refused for the choice (not read again for it)
  // Lessons: the shipped ones (and --lesson's file), parallel to choices_.lessons after "none";
  // the one chosen (−1: none); the trainee's step in it and the failed attempts there (−1:
  // not read yet), from the history's snapshot and moved on by each verdict; the snapshot
  // they were last taken from; the last flight's verdict and the step it judged.
  std::vector<Lesson> lessons_;
  int lesson_ = -1;
  int lesson_step_ = -1, lesson_failed_ = 0;
  int lesson_attempts_known_ = 0;  // attempts the snapshot must hold to be taken
  int lesson_made_for_ = -2;       // the step a READY flight was last made for
  const ui::HistoryView* lesson_seen_ = nullptr;
  std::string lesson_for_;  // "trainee\nlesson hash" the progress is of
  std::optional<LessonVerdict> verdict_;
  int verdict_step_ = -1;
  std::optional<ui::LessonAttemptView> last_attempt_;  // the history's newest, before any here
};

}  // namespace mixpilot::cli
