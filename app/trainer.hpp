#pragma once
// The application (SPEC §8), whatever draws it: the live flight on the real-time runner's
// thread, or a recording's replay, the session panel's choices, and what the user's requests do
// to them. One frame: build_frame() between ImGui::NewFrame() and ImGui::Render(). The window
// (app/window.cpp) and the headless tests drive the same object.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/flight.hpp"
#include "core/recording/replay.hpp"
#include "app/replay_tape.hpp"
#include "core/recording/session_recording.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "input/mapping_wizard.hpp"
#include "input/net/telemetry_publisher.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

// One flight in the app: the mode, its session and sinks, and the runner that paces it.
struct LiveFlight {
  Flight flight;
  std::unique_ptr<Session> session;
  RecordingSink recorder;
  std::string record_path;  // "" when not recording
  std::optional<ReplayCheck> check;  // flying a recording's pilot commands
  std::optional<HapticSink> haptic;  // a gamepad pilot: λ to the rumble
  std::optional<net::TelemetryPublisher> publisher;  // --publish: the telemetry over DDS
  std::unique_ptr<RealtimeRunner> runner;
  ui::Scene scene;
  ui::History history;
  Telemetry sample;  // the ring's values are copied into it (sized once)
  ui::RunInfo counts;  // fallbacks and deadline misses so far (ui::count_step)
  bool started = false, closed = false;
  bool waiting = false;  // Start asked for, waiting for the gamepad
  // --vehicle dds: listening for the vehicle until vehicle_deadline while the window draws on;
  // no_vehicle: none came (or the wait was cancelled), so this flight cannot start.
  bool awaiting_vehicle = false, no_vehicle = false;
  std::chrono::steady_clock::time_point vehicle_deadline;
  Metrics metrics;   // once the run is over
};

class Trainer {
 public:
  // `o`: the command line's flight (scenario, pilot, --record, --report, ...).
  explicit Trainer(FlyOptions o);
  ~Trainer();
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
  void act(const ui::UiRequest& req);
  void start();            // Start: the live flight flies / the replay plays
  void seek(double t);     // a replay's playhead [s]
  void load_replay();      // flies the whole replay now (headless), with a progress bar
  bool replaying() const { return replay_ != nullptr; }
  // The live flight's run is over and every step has been drawn; a replay played to its end.
  bool over() const;
  double shown_time() const;  // [s] of the telemetry on screen (−1: none yet)
  ui::UiState& ui_state() { return ui_; }
  const ui::RunInfo& run_info() const { return run_; }
  const LiveFlight* live() const { return live_.get(); }
  const ReplayTape* replay() const { return replay_.get(); }

  // Stops the flight (closing its recording) and the replay; prints the summary, writes the
  // report; returns the exit status (kExitReplayMismatch for a replay that differs).
  int finish();

 private:
  std::unique_ptr<LiveFlight> make_live(std::string& error, int& status);
  bool replace_live(std::string& error);  // a new, unstarted flight of the choices
  void close_live(LiveFlight& f);
  void refresh_choices();
  void update_live();
  void update_vehicle_wait(LiveFlight& f);
  void update_replay(double wall_dt);
  void say(std::string message, bool error = false);
  void update_input();
  std::shared_ptr<input::Gamepad> gamepad(std::string& error);
  std::string next_record_path() const;

  FlyOptions options_;
  std::unique_ptr<LiveFlight> live_;
  std::unique_ptr<ReplayTape> replay_;
  ui::ReplayInfo replay_info_;
  bool replay_events_final_ = false;
  double replay_speed_ = 1.0;
  ui::SessionChoices choices_;
  std::vector<std::string> scenario_paths_;  // parallel to choices_.scenarios
  std::string first_record_;                 // --record: the first recorded flight's path
  std::vector<std::string> recorded_;        // recordings written, for the summary
  ui::UiState ui_;
  ui::RunInfo run_;
  int status_ = 0;
  std::shared_ptr<input::Gamepad> gamepad_;  // started when a flight first needs it
  bool gamepad_failed_ = false;              // SDL could not start its gamepad support
  input::InputSettings input_settings_;      // what the next device flight uses
  std::string input_settings_path_;
  ui::InputInfo input_;
  std::optional<input::MappingWizard> wizard_;  // mapping a joystick SDL does not know
  std::string wizard_device_;
  input::RawJoystick wizard_raw_;  // the newest raw reading (the wizard panel shows it)
  void act_on_input(const ui::UiRequest& req);
};

}  // namespace mixpilot::cli
