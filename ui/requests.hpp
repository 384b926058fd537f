#pragma once
// What the user asked for in a frame (a button, a key), one small type per thing asked, grouped
// by the lifecycle that acts on it: the live flight with the session's choices for the next one,
// a replay, the input settings, the mapping wizard, and the app itself for what crosses them
// (opening a file, leaving a replay). Panels push them; the app hands each group to its
// controller. A panel asks for the transport of what it shows: a replay's buttons and keys push
// replay requests, the live flight's push live ones.
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "input/settings.hpp"

namespace mixpilot::ui {

// The live flight, and the session panel's choices for the next one.
struct StartFlight {};
struct TogglePause {};        // pause / resume the flight
struct SetFlightSpeed {
  double speed;               // real-time factor: 0.25–1 (slow motion)
};
struct RestartFlight {};
struct CancelVehicleWait {};  // stop waiting for the remote vehicle (Esc)
struct HeldFlightKeys {       // the keyboard pilot's keys, every frame it flies
  unsigned keys;              // bit k: input::Key k is held
};
struct PickScenario {
  int index;                  // into SessionChoices::scenarios
};
struct PickPilot {
  int index;                  // into SessionChoices::pilots
};
struct SetRecord {
  bool on;                    // record the next flight
};
struct SetTrainee {
  std::string name;
};
struct SetAssist {
  bool on;                    // false: the next flight is a probe (SPEC §10)
};
struct FlyFromStart {};       // a flight flown on from a recording's moment: from t = 0 instead
struct PickGhost {
  int index;                  // into SessionChoices::ghosts
};
struct PickLesson {
  int index;                  // into SessionChoices::lessons (0: none)
};
struct ChooseLesson {         // a lesson by its name ("beginner"): what a first launch offers
  std::string name;
};
struct FlyWith {              // a shipped scenario by its name and a pilot by theirs, flown next
  std::string scenario;       // "mi_helix" ("" the one chosen)
  std::string pilot;          // "novice", "gamepad", "keyboard"
};
using LiveRequest = std::variant<StartFlight, TogglePause, SetFlightSpeed, RestartFlight,
                                 CancelVehicleWait, HeldFlightKeys, PickScenario, PickPilot,
                                 SetRecord, SetTrainee, SetAssist, FlyFromStart, PickGhost,
                                 PickLesson, ChooseLesson, FlyWith>;

// A replay's transport.
struct TogglePlay {};
struct SetPlaySpeed {
  double speed;               // 0.25–8
};
struct Seek {
  double t;                   // [s] the playhead
};
struct JumpToEvent {
  int direction;              // −1 previous, +1 next
};
struct SetLambdaThreshold {
  double lambda;              // λ_T of the debrief's takeovers
};
struct SelectEvent {
  int index;                  // into ReplayInfo::events: selected, the playhead at its start
};
using ReplayRequest =
    std::variant<TogglePlay, SetPlaySpeed, Seek, JumpToEvent, SetLambdaThreshold, SelectEvent>;

// The input settings panel.
struct ApplySettings {
  input::InputSettings settings;  // from the next flight on
  bool save = false;              // and written to InputInfo::settings_path
};
struct UseGamepad {
  std::int32_t instance;          // SDL's instance id (-1: the first connected)
};
using InputRequest = std::variant<ApplySettings, UseGamepad>;

// The mapping wizard.
struct MapGamepad {
  std::int32_t instance;          // start mapping this SDL joystick
};
struct WizardSkip {};
struct WizardBack {};
struct WizardSave {};             // save the mapping and end the wizard
struct WizardCancel {};
using WizardRequest = std::variant<MapGamepad, WizardSkip, WizardBack, WizardSave, WizardCancel>;

// Across the lifecycles.
struct OpenFile {
  std::string path;               // a scenario (.toml) or a recording (.mcap)
};
struct LeaveReplay {};            // back to the live flight (Esc)
struct ReplayRecording {          // a flight of the Progress panel: its recording, replayed
  std::string path;
};
struct ExportClip {               // a time window of the replay shown, saved as a video file
  double from, to;                // [s] beside its recording (the export outlives the replay)
};

// What "Export clip" saves around a replay's time `t` [s]: `half_width` seconds either side,
// within the recording's [0, duration].
inline constexpr double kClipHalfWidth = 5.0;  // [s]
inline ExportClip clip_around(double t, double duration, double half_width = kClipHalfWidth) {
  const double from = t - half_width < 0.0 ? 0.0 : t - half_width;
  const double to = t + half_width > duration ? duration : t + half_width;
  return ExportClip{from, to};
}

// Fly from here (SPEC §10): the replay's moment at the playhead becomes a live flight, READY
// there, which the trainee's pilot flies on.
struct FlyFromHere {};

// The first launch (ui/first_launch.hpp): one of its three ways in, and the welcome done with
// (its tour ended or skipped, or "not now"): it does not come back.
enum class WayIn { watch, fly, course };
struct FirstLaunchChoice {
  WayIn way;
  std::string trainee;            // the course's trainee ("" the login name)
};
struct FirstLaunchDone {};
// The text size, a factor on the display's scale (1: as the display's), kept for next time.
struct SetTextScale {
  float scale;
};
using AppRequest = std::variant<OpenFile, LeaveReplay, ReplayRecording, ExportClip, FlyFromHere,
                                FirstLaunchChoice, FirstLaunchDone, SetTextScale>;

// Any request converts to a Request: `requests.push_back(ui::Seek{t})`.
using Request = std::variant<LiveRequest, ReplayRequest, InputRequest, WizardRequest, AppRequest>;
// One frame's requests in the order asked. The app keeps one and clears it every frame: its
// capacity stays, so frames allocate nothing for requests that carry no text.
using Requests = std::vector<Request>;

// Visits a request with one lambda per type: `std::visit(overloaded{...}, r)`.
template <class... F>
struct overloaded : F... {
  using F::operator()...;
};
// Spelled out: clang 14 (the sanitizer build) does not deduce an aggregate's arguments.
template <class... F>
overloaded(F...) -> overloaded<F...>;

}  // namespace mixpilot::ui
