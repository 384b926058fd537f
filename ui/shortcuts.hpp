#pragma once
// Every key of the window in one table (UI.md §10): the key handling acts on its rows and the
// shortcut sheet (F1) lists them, so no key works without being listed. A row is a key (with
// Ctrl or not), the action it asks for, when it does so, and the words the sheet shows.
//
// The keyboard is in one of two places. Normally it drives the flight and the window (this
// table). Tab moves it into the panels (ImGui's keyboard navigation: the arrows move between
// controls, Space presses, Enter types into a field, Ctrl+Tab goes to the next panel); Esc
// brings it back. The welcome and its tour take it into their panels while they show.
#include <span>

#include "ui/keys.hpp"
#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::ui {

enum class Action {
  // The live flight and the window.
  start_pause, restart, record, open_file, camera_chase, camera_orbit, camera_top, camera_side,
  sticks, plots, progress, input_settings, help, text_larger, text_smaller, text_reset,
  panels, leave,
  // A replay.
  step_back, step_forward, to_start, to_end, faster, slower, previous_event, next_event,
  export_clip, fly_from_here, debrief,
  // The keyboard pilot's keys (held, not pressed: kFlightKeys).
  fly,
  // The welcome's three ways in.
  welcome_watch, welcome_fly, welcome_course,
};

// When a row acts: a bit each.
enum When : unsigned {
  kLive = 1u << 0,           // a live flight on screen (not a replay)
  kReplay = 1u << 1,         // a replay
  kKeyboardPilot = 1u << 2,  // the keyboard flies the live flight
  kNotKeyboardPilot = 1u << 3,
  kWelcome = 1u << 4,        // the welcome shows (its keys only)
  kAlways = kLive | kReplay,
};

enum class Mod { none, ctrl, any };  // any: Shift and Alt too (they change the step)

struct Shortcut {
  Key key;
  Mod mod;
  Action action;
  unsigned when;     // When bits: all of them must hold (kAlways: any flight)
  // The sheet's line: the keys and what they do. nullptr: the line above covers this row too
  // (its keys name this one: "1  2  3  4").
  const char* keys;
  const char* what;
};

// The keys ImGui's navigation reads while the keyboard is in the panels (the Tab row says them):
// moving, pressing, typing, scrolling, leaving.
inline constexpr Key kPanelKeys[] = {Key::tab,     Key::left,      Key::right,     Key::up,
                                     Key::down,    Key::space,     Key::enter,     Key::keypad_enter,
                                     Key::escape,  Key::page_up,   Key::page_down, Key::home,
                                     Key::end,     Key::backspace, Key::del};

// The table, in the sheet's order.
std::span<const Shortcut> shortcuts();

// The name of a key as the sheet writes it ("Space", "F1", "[", "Left").
const char* key_name(Key k);

// The When bits that hold now.
unsigned key_context(const RunInfo& run, const UiState& ui);

// Whether a row of `a` that holds in `now` went down in this frame with its modifier.
bool pressed(Action a, unsigned now);

// Acts on the keys of this frame (after the panels were drawn): the window's shortcuts, or,
// while the keyboard is in the panels, Esc to leave them.
void handle_keys(UiState& ui, Requests& out, const RunInfo& run, const History& h);

// Moves the keyboard into the panels: the frontmost open panel takes it (the welcome, a dialog,
// the input settings, the progress, this sheet, the score card, the session or Debrief panel,
// else the top bar or a replay's transport).
void enter_panels(UiState& ui);
// Once a frame, after every panel was drawn: keyboard navigation on while the keyboard is in
// the panels (off otherwise, so the arrows fly), and a line that says so.
void update_keyboard_focus(UiState& ui, const RunInfo& run);
// Once a frame, before any panel is drawn: the keyboard's focus given to the panel
// enter_panels() asked for (the welcome or the tour while they show), once it was drawn.
void focus_panels(UiState& ui);

// The text scale steps of Ctrl+= / Ctrl+- and the sheet's buttons.
inline constexpr float kTextScales[] = {0.8f, 0.9f, 1.0f, 1.1f, 1.25f, 1.5f, 1.75f, 2.0f};
// The next larger (direction +1) or smaller (−1) step from `scale`.
float next_text_scale(float scale, int direction);

// The shortcut sheet's window.
inline constexpr const char* kHelpWindow = "Keyboard and mouse (F1)";
// The shortcut sheet (F1 or ?): the table's lines for this window, how the keyboard reaches the
// panels, the text size, and the welcome again.
void draw_help_sheet(const RunInfo& run, UiState& ui, Requests& out, ImVec2 display);

}  // namespace mixpilot::ui
