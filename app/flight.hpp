#pragma once
// One flight as the command line asks for it (`mixpilot fly`, `replay`, `demo`): the options,
// the scenario and recording they name, and the mode made from them. Shared by the headless
// path (app/fly.cpp) and the window (app/window.cpp).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/screenshot.hpp"
#include "app/video.hpp"
#include "input/device_pilot.hpp"
#include "input/gamepad.hpp"
#include "input/keyboard.hpp"
#include "input/net/joy_peer.hpp"
#include "input/net/remote_vehicle.hpp"
#include "input/settings.hpp"
#include "input/virtual_gamepad.hpp"
#include "core/control/mi_settings.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/session.hpp"
#include "core/modes/report.hpp"
#include "core/recording/recording.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "core/scenario/scenario.hpp"

namespace mixpilot::cli {

// Fly from here (SPEC §10): the moment of a recorded flight a new, live flight takes over from
// (app/take_over.hpp makes it off the UI thread). The new flight flies the recording's embedded
// scenario, as long and as assisted as it was, from the recorded flight's state at step k.
struct FlyFrom {
  std::string parent;         // the recording, absolute
  std::string parent_sha256;  // its content hash (a replay of the branch checks it)
  std::int64_t step = 0;      // k: the new flight's first step
  double t = 0.0;             // [s] t_k = k Δt
  std::shared_ptr<const ModeSnapshot> snapshot;  // the recorded flight before step k
  std::string scenario_text, scenario_source, scenario_file;  // the recording's
  double duration = 0.0;      // [s] the recorded flight's planned length
  Assistance assist = Assistance::on;
};

// A lesson step's flight (SPEC §10, core/scenario/lesson.hpp): what its recording and its
// history row say of it.
struct LessonTag {
  std::string lesson, lesson_hash;
  int step = -1;  // 0-based; −1: not a lesson's flight
  int steps = 0;
  std::string title;
  bool active() const { return step >= 0; }
};

struct FlyOptions {
  std::string scenario_path;
  // The scenario's text when it is not the file's own: a variant of it with some keys set to
  // other values (core/scenario/scenario_keys.hpp: a sweep's run, a figure's flight), which a
  // recording embeds as flown; scenario_path then names it in messages and anchors its
  // relative paths.
  std::string scenario_text;
  std::string pilot;
  bool headless = false;
  std::optional<double> duration;
  std::string record;
  std::string report;
  bool allow_mismatch = false;
  bool force = false;
  std::vector<ScreenshotRequest> screenshots;
  VideoOptions video;              // replay --video: a video file of the replay
  int width = 1280, height = 720;  // of the screenshots, the video and the window
  float scale = 0.0f;              // --scale: the UI's display scale (0: the window's; headless 1)
  bool realtime = false;           // headless, paced by the wall clock
  bool exit_at_end = false;        // window: start at once, close when the run is over
  bool replay = false;             // `mixpilot replay`: a recording of any mode flown again
  std::string gamepad_script;      // --gamepad-script: a virtual gamepad plays it
  std::string input_settings;      // --input-settings (default: the user's input.toml)
  std::optional<input::InputSettings> input_values;  // the app's settings, instead of a file
  // --assist on|off (mixed initiative): off flies a probe (SPEC §10). Unset: on for a new
  // flight, as recorded for a replay (which refuses another value).
  std::optional<Assistance> assist;
  // --floor / --ceiling, or a lesson step's ceiling (mixed initiative, SPEC §10): the bounds on
  // λ from the first step.
  AuthorityBounds bounds = {};
  // --commands: a script of instructor's commands at flight times (core/modes/command_script.hpp).
  std::string commands;
  std::uint32_t domain = 0;        // --domain: the DDS domain of network peers
  bool publish = false;            // --publish: telemetry out over DDS, the station announced
  // The instructor's network (SPEC §10, docs/instructor-security.md), with --publish:
  std::string station;             // --station: this station's name ("" → host-pid)
  bool instructor = false;         // --instructor: obey an instructor's commands
  std::string dds_security;        // --dds-security FOLDER: this identity's DDS Security files
  bool allow_unauthenticated_commands = false;  // --allow-unauthenticated-commands (loopback)
  std::string vehicle;             // --vehicle: "" (simulated) or "dds" (mixpilot vehicle)
  double vehicle_wait_s = 30.0;    // --vehicle-wait: how long to wait for the vehicle
  std::string trainee;             // --trainee: who flies ("" → the login name; SPEC §10)
  std::string history;             // --history: "" the default SQLite file, "off", a location
  // --ghost: a recorded flight of the scenario flying along (SPEC §10, app/ghost.hpp): a
  // recording's path, "best" (the trainee's best recorded flight of it in the history) or
  // "off"; "" the front end's default (the window: best; headless: off).
  std::string ghost;
  const char* command = "fly";     // for messages
  // Fly from here: the new flight goes on from this moment of a recording (the window's).
  std::shared_ptr<const FlyFrom> from;
  // A lesson step's flight: recorded in its metadata.
  LessonTag lesson;
  // The window: the lesson its picker starts on (a file; `mixpilot lesson` without --headless).
  std::string lesson_file;
  // The window may offer the first launch's welcome (ui/first_launch.hpp): `fly` in the window
  // without a scenario named (app/fly.cpp says when); it shows while the history has no flight
  // and the user never dismissed it.
  bool first_launch = false;
};

// A person's device flying the session (--pilot gamepad | keyboard, SPEC §6), kept alive for
// the flight: the stick source the pilot reads and, with --gamepad-script, the virtual pad
// that plays the script from the start of the flight.
struct Devices {
  input::InputSettings settings;
  std::unique_ptr<input::VirtualGamepad> virtual_pad;
  std::vector<input::ScriptRow> script;
  std::shared_ptr<input::Gamepad> gamepad;  // one per process: the app's, across flights
  std::unique_ptr<input::KeyboardSource> keyboard;
  std::unique_ptr<net::JoyPeer> peer;  // --pilot dds[:TOPIC]
  input::DevicePilot* pilot = nullptr;  // owned by the mode

  // The flight starts now: the script's t = 0.
  void started();
  // The haptic cue for the λ of the last step (the control thread calls it; never blocks).
  void cue(double lambda) const;
};

// The flight of FlyOptions, set up: the scenario from --scenario or the recording given as
// --pilot, and the mode it names.
struct Flight {
  std::string scenario_text;
  std::string scenario_source;  // for messages and relative paths
  std::string scenario_file;    // the scenario's file, absolute (recorded as scenario_path)
  std::optional<RecordingContents> recording;  // --pilot REC.mcap
  std::unique_ptr<Mode> mode;
  std::string pilot;  // mixed initiative: the pilot source's name
  std::shared_ptr<Devices> devices;  // --pilot gamepad | keyboard
  std::unique_ptr<net::RemoteVehicle> vehicle;  // --vehicle dds
  std::shared_ptr<const FlyFrom> from;  // a branch: flown on from this moment of its parent
  LessonTag lesson;                      // a lesson step's flight
};

// The haptic cue from the control thread: each step's λ to the gamepad (an atomic store).
class HapticSink final : public TelemetrySink {
 public:
  explicit HapticSink(const Devices& d) : devices_(&d) {}
  void on_sample(const Telemetry& s) override { devices_->cue(s.lambda); }

 private:
  const Devices* devices_;
};

// True for the pilots that are a person's device.
bool is_device_pilot(const std::string& pilot);

// The input settings at `path` (or the user's default file). A broken file gives the defaults
// and, in `note`, what was wrong, so the app still starts and says why.
input::InputSettings load_input_settings(const std::string& path, std::string& note);

// Reads the scenario (and the recording of a replay) and makes the mode; nullopt with the
// reason and the exit status (kExitError, or kExitReplayMismatch for a --scenario other than
// the recording's).
// `gamepad`: the app's running gamepad, used instead of starting one (SDL's joystick state
// has one owner per process).
// `wait`: block waits for a --vehicle dds vehicle here (up to --vehicle-wait); later returns
// with the link listening, for a caller that must not block (the window): it polls
// Flight::vehicle->heard() and calls attach_vehicle() once it is.
enum class VehicleWait { block, later };
std::optional<Flight> prepare_flight(const FlyOptions& o, std::string& error, int& status,
                                     std::shared_ptr<input::Gamepad> gamepad = nullptr,
                                     VehicleWait wait = VehicleWait::block);
// The heard vehicle flies the flight's mode; false with the reason.
[[nodiscard]] bool attach_vehicle(Flight& f, std::string& error);
// Why no vehicle flies after --vehicle-wait: none heard, or what was rejected.
std::string vehicle_not_heard(const FlyOptions& o, const Flight& f);

// What a recording of the flight says about it (its metadata). `trainee` is the person flying,
// when the app knows.
SessionInfo session_info(const Flight& f, const std::string& trainee = "");
Labels report_labels(const Flight& f, bool was_interrupted);

// Output paths, checked before the flight: distinct, writable, and never over a special file,
// nor over an existing file without --force. False with the reason.
[[nodiscard]] bool check_outputs(const FlyOptions& o, std::string& error);

// The summary's real-time line: deadline misses, worst start lateness, p99 and longest step,
// and the control thread's scheduling.
void print_realtime(const RealtimeStats& st, double dt);
// The remote vehicle's line: states taken, rejected by reason, commands sent.
void print_vehicle(const net::RemoteVehicle& vehicle);
// The network pilot's line: samples taken, rejected by reason, publishers, latency.
void print_peer(const net::JoyPeer& peer);
// The input settings a command flies with: --input-settings FILE (`path`), which must exist and
// be valid (nullopt with `error`), else the user's file, whose errors give the defaults and a
// note on stderr ("mixpilot <command>: ...").
std::optional<input::InputSettings> command_input_settings(const char* command,
                                                           const std::string& path,
                                                           std::string& error);

// A mixed-initiative recording and its embedded scenario (gamepad-script, joy-publish);
// nullopt with the reason.
struct PilotRecording {
  RecordingContents recording;
  Scenario scenario;
};
std::optional<PilotRecording> read_pilot_recording(const std::string& path, std::string& error);

// The stick positions (SDL's axes: left x, left y down, right x, right y down) that give a
// recorded pilot command through `settings` (the inverse of the shaping; clamped at full
// deflection): how gamepad-script and joy-publish fly a recording through a device path.
std::array<double, 4> sdl_axes_for(const PilotCommandMsg& m, const input::InputSettings& settings);
// --domain's value: 0-232 (DDS's domain id range); a usage error otherwise.
std::uint32_t parse_domain(const char* command, const std::string& text);

// The shortest text of `t` ("%g").
std::string seconds_text(double t);

}  // namespace mixpilot::cli
