#pragma once
// The live flight (SPEC §8): the mode on the real-time runner's thread with its sinks and its
// recording, the wait for a remote vehicle or for a gamepad, and the session panel's choices
// for the next flight (scenario, pilot, record, trainee). Start, pause, slow motion, restart
// and the keyboard pilot's keys act on it.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/flight.hpp"
#include "app/input_controller.hpp"
#include "app/status_line.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "input/net/telemetry_publisher.hpp"
#include "ui/requests.hpp"
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

class LiveController {
 public:
  // `o`: the command line's flight (scenario, pilot, --record, --report, ...); the input
  // settings and the gamepad are `input`'s.
  LiveController(FlyOptions o, InputController& input, StatusLine& status);
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

 private:
  // The flight's assembly (live_controller.cpp's first section).
  std::unique_ptr<LiveFlight> make_live(std::string& error, int& status);
  void update_vehicle_wait(LiveFlight& f);
  void close_live(LiveFlight& f);

  [[nodiscard]] bool replace_live(std::string& error);  // a new, unstarted flight of the choices
  void fly_scenario(std::size_t index);  // the next flight flies scenario_paths_[index]
  void refresh_choices();
  std::string next_record_path() const;

  FlyOptions options_;
  InputController& input_;
  StatusLine& status_line_;
  std::unique_ptr<LiveFlight> live_;
  ui::SessionChoices choices_;
  std::vector<std::string> scenario_paths_;  // parallel to choices_.scenarios
  std::string first_record_;                 // --record: the first recorded flight's path
  std::vector<std::string> recorded_;        // recordings written, for the summary
  int status_ = 0;
};

}  // namespace mixpilot::cli
