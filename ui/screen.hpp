#pragma once
// The whole window, one frame at a time (SPEC §8, UI.md §1): a top bar with the status pill,
// the session buttons and the authority bar; the session panel, or a replay's Debrief panel; the
// arena (3D) or Pendubot (2D) view in the centre; plots on the right; the sticks at the bottom,
// or a replay's timeline. A
// function of the scene, the telemetry history and the UI's own state; what the user asked for
// comes back as requests (ui/requests.hpp). Keys by the UI's own names (ui/keys.hpp).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <imgui.h>

#include "input/mapping.hpp"
#include "input/mapping_wizard.hpp"
#include "core/modes/debrief.hpp"
#include "input/settings.hpp"
#include "ui/keys.hpp"
#include "ui/progress.hpp"
#include "ui/requests.hpp"
#include "ui/scene.hpp"

namespace mixpilot::ui {

struct ScoreCard;  // ui/score_card.hpp

enum class Camera { chase, orbit, top, side };
const char* to_string(Camera c);

// What the app shows about the flight besides its telemetry.
// waiting: the flight waits for its remote vehicle (--vehicle dds) and can be cancelled.
enum class RunState { ready, waiting, flying, paused, finished, replay, loading, lost };
const char* to_string(RunState s);

// An event of a replay's debrief (SPEC §10, core/modes/debrief.hpp) as the screen shows it:
// a row of the Debrief panel and a tick on the timeline (UI.md §6), which jump to it.
struct DebriefRow {
  double t = 0.0;    // [s] its start: where a jump puts the playhead
  double end = 0.0;  // [s] its end (t for a moment: a lost vehicle, a marker)
  DebriefKind kind = DebriefKind::takeover;
  std::string text;  // what happened, in words (describe())
  DebriefEvent event;  // as the builder made it (the score card weighs what it cost)
};

// The rows of a flight's debrief events (as the builder lists them: in the order they closed),
// by start time, in words for a ball of radius `ball_radius`.
std::vector<DebriefRow> debrief_rows(const std::vector<DebriefEvent>& events, double ball_radius);

// A replay's transport: a playhead over a recorded flight.
struct ReplayInfo {
  bool playing = false;
  double t = 0.0;             // [s] the playhead
  double duration = 0.0;      // [s] of the recording
  double loaded = 1.0;        // fraction of the flight ready to show (it is flown again first)
  double lambda_threshold = 0.5;  // λ_T: λ below it is a takeover (the debrief's)
  // The debrief: the Debrief panel lists these and the timeline marks them; [ and ] step
  // through them. By start time; once the whole flight is loaded (events_ready).
  std::vector<DebriefRow> events;
  bool events_ready = false;
  int selected = -1;  // the event selected (highlighted; what Export clip saves), −1: none
  // Fly from here (SPEC §10): offered (a pilot flies this mode), and while the moment is made
  // ready the part of the way flown (0 … 1; −1: not taking over).
  bool can_fly_from_here = false;
  double taking_over = -1.0;
};

// A lesson (SPEC §10) as the session panel shows it: the trainee's current step, how it is
// flown and judged, and the last flight's verdict. Texts made by the app.
struct LessonChoice {
  std::string description;
  std::vector<std::string> steps;  // the steps' titles
  int step = -1;                   // the trainee's step, 0-based (= steps.size(): all passed;
                                   // −1: the history is being read)
  std::string heading;             // "step 2 of 5: A slow climb"
  std::string rule;                // one line: "λ ≤ 0.50 · pass: skill ≥ 72, no collision, in B ≥ 90 %"
  std::string conditions;          // in words: "ceiling: λ at most 0.50 (the planner keeps ...)"
  std::string criteria;            // in words: "skill at least 72, no collision, ..."
  std::string attempts;            // "attempts: 1 failed, 2 left" ("" nothing to say)
  bool closed = false;             // the step's attempts are used up: nothing flies
  std::string verdict;             // the last flight's: "PASSED" / "NOT PASSED: ..." ("" none)
  bool verdict_passed = false;
  std::vector<std::string> verdict_lines;  // each criterion: "✓ skill 80.1 (at least 70)"
  std::string next;                // what R flies now: "Next: step 3 (R)", "Try again (R)"
  std::string error;               // the history could not be read ("" fine)
};

// The session panel's choices (SPEC §8): what the next flight flies.
struct SessionChoices {
  std::vector<std::string> scenarios;  // labels: shipped scenarios, then opened files
  int scenario = -1;                   // index into scenarios
  std::vector<std::string> pilots;     // pilot sources of the scenario (empty: the mode has none)
  int pilot = -1;
  bool record = false;                 // record the next flight
  std::string record_to;               // where (a file, or the folder of automatic names)
  std::string trainee;                 // the person flying
  // Mixed initiative: whether the planner assists the next flight (false: a probe, SPEC §10),
  // and whether it can be chosen (a new flight of a scenario with a pilot; a recording's
  // pilot flies as it was recorded).
  bool assist = true;
  bool assist_choosable = false;
  // Fly from here: the next flight goes on from a recording's moment ("from REC at t = 10.00 s";
  // "" for a flight from the start).
  std::string fly_from;
  // The ghost (SPEC §10): a recorded flight of the scenario flying along. The choices ("none",
  // "your best ...", the trainee's other recorded flights of it, --ghost's file; empty: this
  // flight can have none), the one chosen, and what became of it ("loading ...", why it was
  // refused; "" nothing to say).
  std::vector<std::string> ghosts;
  int ghost = -1;
  std::string ghost_note;
  bool ghost_note_is_error = false;
  // Lessons (SPEC §10): "none" then the lessons' names (empty: no lessons, or no history to
  // keep the progress in), the one chosen (0: none) and what the panel shows of it.
  std::vector<std::string> lessons;
  int lesson = 0;
  LessonChoice lesson_view;
};

// A joystick SDL sees.
struct InputDevice {
  std::int32_t instance = -1;  // SDL's instance id
  std::string name;
  bool mapped = false;         // SDL has a mapping (else the wizard can make one)
};

// The mapping wizard's state for its panel (SPEC §6).
struct WizardView {
  std::string device;
  std::string prompt, hint;
  std::size_t step = 0, steps = 0;
  bool optional = false, done = false;
  std::vector<std::string> bindings;
  std::string mapping;  // the SDL line once every stick is bound
  const input::RawJoystick* raw = nullptr;
};

// A person's device flying the session (SPEC §6): for the session panel, the input settings
// panel and the input-loss banner.
struct InputInfo {
  std::string pilot;                 // "gamepad" | "keyboard" ("" : the pilot is no device)
  std::string device;                // the gamepad in use ("" none)
  std::vector<InputDevice> devices;  // every joystick SDL sees
  std::int32_t active = -1;          // the instance in use
  bool connected = false;            // a gamepad is connected (the keyboard always is)
  bool waiting = false;              // Start was asked for: waiting for a gamepad
  input::StickAxes live;             // the sticks now, for the curves
  const input::InputSettings* settings = nullptr;
  std::string settings_path;         // where Save writes
  std::string note;                  // the settings file is broken: what was wrong
  std::string message;               // what the last mapping did ("" none)
  std::optional<WizardView> wizard;  // the mapping wizard, while it runs
};

struct RunInfo {
  RunState state = RunState::ready;
  double speed = 1.0;            // real-time factor (slow motion < 1)
  // So far: steps marked kEventDeadlineMiss, and steps that applied the previous solution's
  // input (count_step() adds one step's).
  std::int64_t deadline_misses = 0;
  std::int64_t fallbacks = 0;
  bool recording = false;
  bool can_restart = false;      // the app can start the flight again (Restart, R)
  std::string message;           // a line for the status area ("" none)
  bool message_is_error = false;
  Metrics metrics;               // the score fields at the end of a flight (empty: none yet)
  // The score card made of them (ui/score_card.hpp; nullptr: one of the metrics alone).
  const ScoreCard* card = nullptr;
  const SessionChoices* session = nullptr;  // the session panel (nullptr: none, e.g. headless)
  const ReplayInfo* replay = nullptr;       // a replay's transport (nullptr: a live flight)
  const InputInfo* input = nullptr;         // the input devices (nullptr: none, e.g. headless)
  const HistoryView* history = nullptr;     // trainees and progress (nullptr: no history)
  bool instructor_paused = false;  // the instructor paused the flight (SPEC §10)
  float text_scale = 1.0f;  // the user's text size: a factor on the display's scale
};


// Adds step `s` to the run's counts: the live flight, a replay's tape and a headless
// screenshot count the same events.
inline void count_step(const Telemetry& s, RunInfo& run) {
  run.fallbacks += (s.events & (kEventFallback | kEventOverrun)) != 0;
  run.deadline_misses += (s.events & kEventDeadlineMiss) != 0;
}

// A file browser's state (File → Open): the folder shown and what it holds.
struct OpenDialog {
  bool open = false;
  std::string folder;                // absolute
  std::vector<std::string> entries;  // sub-folders (ending in '/') then .toml and .mcap files
  std::string error;                 // why the folder could not be listed
  char path[1024] = "";              // the path being typed or picked
};

// The first launch (ui/first_launch.hpp): the welcome with its three ways in, then the tour.
enum class FirstLaunch { none, welcome, tour };

// Where the last frame drew what the tour points at (screen pixels; empty: not drawn).
struct TourMarks {
  ImVec2 bar_min{0, 0}, bar_max{0, 0};        // the authority bar
  ImVec2 ball_centre{0, 0};                   // the ball B around the reference point
  float ball_radius = 0.0f;
  ImVec2 sticks_min{0, 0}, sticks_max{0, 0};  // the sticks overlay
  ImVec2 start_min{0, 0}, start_max{0, 0};    // the Start button
};

// The UI's own state: kept by the app between frames, changed only by the UI.
struct UiState {
  Camera camera = Camera::chase;
  float orbit_yaw = 0.6f;     // [rad] orbit camera around the arena's centre
  float orbit_pitch = 0.5f;   // [rad]
  float orbit_distance = 0.0f;  // [m] 0: fit the arena
  bool plots_paused = false;
  double plots_paused_at = -1.0;  // [s] the plots' right edge while paused
  double plot_window = 10.0;  // [s]
  bool show_sticks = true;
  bool show_help = false;      // the shortcut sheet (F1, ?)
  bool show_debrief = true;    // a replay's Debrief panel (L)
  int debrief_shown_selected = -1;  // the selection the list last scrolled to
  bool show_progress = false;  // the Progress panel (H)
  bool score_card_closed = false;
  OpenDialog open_dialog;
  char trainee[64] = "";
  bool show_settings = false;        // the input settings panel (I)
  input::InputSettings draft;        // the settings being edited there
  bool draft_loaded = false;
  float session_choices_h = 0.0f;    // [px] the session panel's choices, as last drawn
  // The keyboard in the panels (ImGui's navigation) rather than on the flight (ui/shortcuts.hpp),
  // and the panel to give it to in this frame.
  bool keyboard_in_panels = false;
  bool focus_panels = false;
  // The first launch (ui/first_launch.hpp): what shows, the tour's step, the course's trainee.
  FirstLaunch first_launch = FirstLaunch::none;
  int tour_step = 0;
  char course_trainee[64] = "";
  TourMarks marks;
  // The chase camera's turn about the vertical from behind the vehicle [rad] and its rise [m],
  // chosen at READY so that no obstacle stands between it and the vehicle
  // (ui/chase_camera.hpp), kept in flight.
  double chase_turn = 0.0, chase_rise = 0.0;
};

// The index of the next (direction +1) or previous (−1) event starting after / before `t`,
// or −1.
int event_after(const std::vector<DebriefRow>& events, double t, int direction);

// What "Export clip" saves of a replay: the selected event from kClipHalfWidth before its start
// to kClipHalfWidth after its end, else the playhead ± kClipHalfWidth.
ExportClip clip_of(const ReplayInfo& replay);

// Builds one frame's ImGui windows over the whole display (between ImGui::NewFrame() and
// ImGui::Render()); appends what the user asked for to `requests`.
void draw_screen(const Scene& scene, const History& history, const RunInfo& run, UiState& ui,
                 Requests& requests);

// Where the arena or Pendubot view frames its scene (the chase camera keeps the vehicle at its
// centre) on a display of size `display` [pixels], as the last frame laid it out: the view pane
// between the top bar, the plots and a replay's transport, less the session panel at its left
// and the HUD above where they would cover the pane's centre.
void view_rect(ImVec2 display, const RunInfo& run, ImVec2& min, ImVec2& max);

// Freezes the plots at the newest time of `h` (or lets them roll again).
void set_plots_paused(UiState& ui, const History& h, bool paused);

}  // namespace mixpilot::ui
