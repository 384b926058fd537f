#include "ui/shortcuts.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <imgui_internal.h>  // the panels' windows by name, keyboard navigation's focus

#include "ui/first_launch.hpp"

namespace mixpilot::ui {

namespace {

static_assert(int(input::Key::thrust_up) == 0 && int(input::Key::roll_right) == 7,
              "the keyboard pilot's rows follow kFlightKeys");

constexpr Shortcut kTable[] = {
    {Key::space, Mod::none, Action::start_pause, kAlways, "Space",
     "start / pause / resume the flight; play / pause a replay"},
    {Key::r, Mod::none, Action::restart, kLive, "R", "restart the flight (fly it again)"},
    {Key::r, Mod::ctrl, Action::record, kLive, "Ctrl+R", "record the next flight or not"},
    {Key::o, Mod::ctrl, Action::open_file, kAlways, "Ctrl+O",
     "open a scenario (.toml) or a recording (.mcap)"},
    {Key::digit1, Mod::none, Action::camera_chase, kAlways, "1  2  3  4",
     "camera: chase, orbit, top, side (mouse: drag orbits, the wheel zooms)"},
    {Key::digit2, Mod::none, Action::camera_orbit, kAlways, nullptr, nullptr},
    {Key::digit3, Mod::none, Action::camera_top, kAlways, nullptr, nullptr},
    {Key::digit4, Mod::none, Action::camera_side, kAlways, nullptr, nullptr},
    {Key::d, Mod::none, Action::sticks, kAlways | kNotKeyboardPilot, "D",
     "show / hide the sticks (while the keyboard flies, D is yaw)"},
    {Key::p, Mod::none, Action::plots, kAlways, "P", "pause / resume the plots"},
    {Key::h, Mod::none, Action::progress, kAlways, "H",
     "progress: this trainee's flights of this scenario, best run, trend"},
    {Key::i, Mod::none, Action::input_settings, kAlways, "I",
     "input settings: stick mode, curves, input loss, haptic cue; map a gamepad"},
    {Key::w, Mod::none, Action::fly, kLive | kKeyboardPilot, "W / S",
     "keyboard pilot: thrust up / down (hold; the sticks ramp)"},
    {Key::s, Mod::none, Action::fly, kLive | kKeyboardPilot, nullptr, nullptr},
    {Key::a, Mod::none, Action::fly, kLive | kKeyboardPilot, "A / D", "keyboard pilot: yaw left / right"},
    {Key::d, Mod::none, Action::fly, kLive | kKeyboardPilot, nullptr, nullptr},
    {Key::up, Mod::none, Action::fly, kLive | kKeyboardPilot, "Up / Down",
     "keyboard pilot: pitch forward / back"},
    {Key::down, Mod::none, Action::fly, kLive | kKeyboardPilot, nullptr, nullptr},
    {Key::left, Mod::none, Action::fly, kLive | kKeyboardPilot, "Left / Right",
     "keyboard pilot: roll left / right"},
    {Key::right, Mod::none, Action::fly, kLive | kKeyboardPilot, nullptr, nullptr},
    {Key::left, Mod::any, Action::step_back, kReplay, "Left / Right",
     "replay: step 100 ms (Shift 10 ms, Alt 500 ms)"},
    {Key::right, Mod::any, Action::step_forward, kReplay, nullptr, nullptr},
    {Key::home, Mod::none, Action::to_start, kReplay, "Home / End", "replay: start / end"},
    {Key::end, Mod::none, Action::to_end, kReplay, nullptr, nullptr},
    {Key::up, Mod::none, Action::faster, kReplay, "Up / Down", "replay: faster / slower (0.25x to 8x)"},
    {Key::down, Mod::none, Action::slower, kReplay, nullptr, nullptr},
    {Key::left_bracket, Mod::none, Action::previous_event, kReplay, "[  ]",
     "replay: previous / next event of the debrief (selects it, the playhead at its start)"},
    {Key::right_bracket, Mod::none, Action::next_event, kReplay, nullptr, nullptr},
    {kDebriefKey, Mod::none, Action::debrief, kReplay, kDebriefKeyName,
     "replay: show / hide the Debrief panel, the list of what happened"},
    {kExportClipKey, Mod::none, Action::export_clip, kReplay, kExportClipKeyName,
     "replay: export a clip beside the recording: the selected event ± 5 s, else the playhead "
     "± 5 s"},
    {kFlyFromHereKey, Mod::none, Action::fly_from_here, kReplay, "T",
     "replay: fly from here - a new flight from the playhead's moment, with the pilot you pick "
     "(READY there; Space starts), scored from there on"},
    {Key::tab, Mod::none, Action::panels, kAlways, "Tab",
     "the keyboard into the panels: the arrows move between controls, Space presses, Enter "
     "types into a field, Ctrl+Tab goes to the next panel; Esc brings it back to the flight"},
    {Key::escape, Mod::none, Action::leave, kAlways | kWelcome, "Esc",
     "back from the panels; close this sheet, the progress or the score card; leave the replay; "
     "stop waiting for the vehicle; the welcome: not now"},
    {Key::equal, Mod::ctrl, Action::text_larger, kAlways, "Ctrl+=  Ctrl+-  Ctrl+0",
     "text larger / smaller / as the display's (kept for the next start)"},
    {Key::keypad_add, Mod::ctrl, Action::text_larger, kAlways, nullptr, nullptr},
    {Key::minus, Mod::ctrl, Action::text_smaller, kAlways, nullptr, nullptr},
    {Key::keypad_subtract, Mod::ctrl, Action::text_smaller, kAlways, nullptr, nullptr},
    {Key::digit0, Mod::ctrl, Action::text_reset, kAlways, nullptr, nullptr},
    {Key::keypad_0, Mod::ctrl, Action::text_reset, kAlways, nullptr, nullptr},
    {Key::f1, Mod::none, Action::help, kAlways | kWelcome, "F1  ?", "this sheet"},
    {Key::digit1, Mod::none, Action::welcome_watch, kWelcome, "1  2  3",
     "the welcome: watch the novice fly / fly yourself / the beginner course"},
    {Key::digit2, Mod::none, Action::welcome_fly, kWelcome, nullptr, nullptr},
    {Key::digit3, Mod::none, Action::welcome_course, kWelcome, nullptr, nullptr},
};

// Whether a row that acts `when` acts now: one of its flights (live, replay, welcome) and all
// of its conditions.
bool holds(unsigned when, unsigned now) {
  constexpr unsigned kFlights = kLive | kReplay | kWelcome;
  const unsigned conditions = when & ~kFlights;
  return (when & now & kFlights) != 0 && (now & conditions) == conditions;
}

bool mod_held(Mod m) {
  const ImGuiIO& io = ImGui::GetIO();
  switch (m) {
    case Mod::none: return !io.KeyCtrl;
    case Mod::ctrl: return io.KeyCtrl;
    case Mod::any: return true;
  }
  return false;
}

// The replay speeds, slowest first (↑ / ↓ move along them).
constexpr double kReplaySpeeds[] = {0.25, 0.5, 1.0, 2.0, 4.0, 8.0};

void replay_keys(const RunInfo& run, UiState& ui, Requests& out, unsigned now) {
  const ReplayInfo& r = *run.replay;
  const ImGuiIO& io = ImGui::GetIO();
  const double step = io.KeyShift ? 0.01 : io.KeyAlt ? 0.5 : 0.1;
  if (pressed(Action::step_back, now)) out.push_back(Seek{std::max(0.0, r.t - step)});
  if (pressed(Action::step_forward, now))
    out.push_back(Seek{std::min(r.loaded * r.duration, r.t + step)});
  if (pressed(Action::to_start, now)) out.push_back(Seek{0.0});
  if (pressed(Action::to_end, now)) out.push_back(Seek{r.loaded * r.duration});
  const auto at = std::find(std::begin(kReplaySpeeds), std::end(kReplaySpeeds), run.speed);
  const bool known = at != std::end(kReplaySpeeds);
  const double faster = known && at + 1 != std::end(kReplaySpeeds) ? *(at + 1) : 8.0;
  const double slower = known && at != std::begin(kReplaySpeeds) ? *(at - 1) : 0.25;
  if (pressed(Action::faster, now)) out.push_back(SetPlaySpeed{faster});
  if (pressed(Action::slower, now)) out.push_back(SetPlaySpeed{slower});
  if (pressed(Action::previous_event, now)) out.push_back(JumpToEvent{-1});
  if (pressed(Action::next_event, now)) out.push_back(JumpToEvent{+1});
  if (pressed(Action::export_clip, now)) out.push_back(clip_of(r));
  if (pressed(Action::fly_from_here, now) && r.can_fly_from_here && r.taking_over < 0.0)
    out.push_back(FlyFromHere{});
  if (pressed(Action::debrief, now)) ui.show_debrief = !ui.show_debrief;
  if (pressed(Action::leave, now) && !ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId))
    out.push_back(LeaveReplay{});
}

bool help_typed() {
  const ImGuiIO& io = ImGui::GetIO();
  for (int i = 0; i < io.InputQueueCharacters.Size; ++i)
    if (io.InputQueueCharacters[i] == '?') return true;
  return false;
}

}  // namespace

std::span<const Shortcut> shortcuts() { return kTable; }

const char* key_name(Key k) {
  static const char* const kLetters[] = {"A", "B", "C", "D", "E", "F", "G", "H", "I", "J", "K",
                                         "L", "M", "N", "O", "P", "Q", "R", "S", "T", "U", "V",
                                         "W", "X", "Y", "Z"};
  static const char* const kDigits[] = {"0", "1", "2", "3", "4", "5", "6", "7", "8", "9"};
  static const char* const kF[] = {"F1", "F2", "F3", "F4", "F5", "F6", "F7", "F8", "F9", "F10",
                                   "F11", "F12"};
  const int i = int(k);
  if (i >= int(Key::a) && i <= int(Key::z)) return kLetters[i - int(Key::a)];
  if (i >= int(Key::digit0) && i <= int(Key::digit9)) return kDigits[i - int(Key::digit0)];
  if (i >= int(Key::f1) && i <= int(Key::f12)) return kF[i - int(Key::f1)];
  switch (k) {
    case Key::space: return "Space";
    case Key::enter: return "Enter";
    case Key::keypad_enter: return "Enter";
    case Key::escape: return "Esc";
    case Key::tab: return "Tab";
    case Key::backspace: return "Backspace";
    case Key::insert: return "Insert";
    case Key::del: return "Delete";
    case Key::left: return "Left";
    case Key::right: return "Right";
    case Key::up: return "Up";
    case Key::down: return "Down";
    case Key::page_up: return "Page Up";
    case Key::page_down: return "Page Down";
    case Key::home: return "Home";
    case Key::end: return "End";
    case Key::left_bracket: return "[";
    case Key::right_bracket: return "]";
    case Key::minus: return "-";
    case Key::equal: return "=";
    case Key::keypad_subtract: return "-";
    case Key::keypad_add: return "=";  // the sheet names the main keyboard's
    case Key::keypad_0: return "0";
    default: return "?";
  }
}

unsigned key_context(const RunInfo& run, const UiState& ui) {
  if (ui.first_launch == FirstLaunch::welcome) return kWelcome;
  if (run.replay) return kReplay | kNotKeyboardPilot;
  return kLive | (run.input && run.input->pilot == "keyboard" ? kKeyboardPilot : kNotKeyboardPilot);
}

bool pressed(Action a, unsigned now) {
  for (const Shortcut& s : kTable)
    if (s.action == a && holds(s.when, now) && mod_held(s.mod) && key_pressed(s.key)) return true;
  return false;
}

float next_text_scale(float scale, int direction) {
  if (direction > 0) {
    for (const float s : kTextScales)
      if (s > scale + 1e-3f) return s;
    return kTextScales[std::size(kTextScales) - 1];
  }
  for (auto it = std::rbegin(kTextScales); it != std::rend(kTextScales); ++it)
    if (*it < scale - 1e-3f) return *it;
  return kTextScales[0];
}

void handle_keys(UiState& ui, Requests& out, const RunInfo& run, const History& h) {
  const ImGuiIO& io = ImGui::GetIO();
  const unsigned now = key_context(run, ui);
  if (ui.first_launch != FirstLaunch::none) return;  // the welcome and the tour take their keys
  if (ui.open_dialog.open) return;                    // the file browser has its own
  if (ui.keyboard_in_panels) {
    // ImGui closes an open list or popup with Esc first; then Esc leaves the panels.
    if (pressed(Action::help, now)) ui.show_help = !ui.show_help;
    if (pressed(Action::leave, now) && !ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId) &&
        ImGui::GetActiveID() == 0)
      ui.keyboard_in_panels = false;
    return;
  }
  if (io.WantCaptureKeyboard) return;
  if (pressed(Action::help, now) || help_typed()) ui.show_help = !ui.show_help;
  if (pressed(Action::open_file, now)) ui.open_dialog.open = true;
  if (pressed(Action::record, now) && run.session) out.push_back(SetRecord{!run.session->record});
  if (pressed(Action::text_larger, now)) out.push_back(SetTextScale{next_text_scale(run.text_scale, +1)});
  if (pressed(Action::text_smaller, now)) out.push_back(SetTextScale{next_text_scale(run.text_scale, -1)});
  if (pressed(Action::text_reset, now)) out.push_back(SetTextScale{1.0f});
  if (io.KeyCtrl) return;  // the rest are plain keys
  if (pressed(Action::panels, now)) {
    enter_panels(ui);
    return;
  }
  const bool leave = pressed(Action::leave, now);
  if (leave && ui.show_help) ui.show_help = false;
  else if (leave && ui.show_progress) ui.show_progress = false;
  else if (run.replay) replay_keys(run, ui, out, now);
  else if (leave && run.state == RunState::waiting) out.push_back(CancelVehicleWait{});
  else if (leave && !run.metrics.empty() && !ui.score_card_closed) ui.score_card_closed = true;
  // Space is the transport's: a replay plays or pauses, a live flight starts, pauses or resumes.
  if (pressed(Action::start_pause, now) && run.state != RunState::waiting) {
    if (run.replay) out.push_back(TogglePlay{});
    else if (run.state == RunState::ready) out.push_back(StartFlight{});
    else out.push_back(TogglePause{});
  }
  if (pressed(Action::restart, now) && run.can_restart) out.push_back(RestartFlight{});
  if (pressed(Action::camera_chase, now)) ui.camera = Camera::chase;
  if (pressed(Action::camera_orbit, now)) ui.camera = Camera::orbit;
  if (pressed(Action::camera_top, now)) ui.camera = Camera::top;
  if (pressed(Action::camera_side, now)) ui.camera = Camera::side;
  if (pressed(Action::sticks, now)) ui.show_sticks = !ui.show_sticks;
  if (pressed(Action::input_settings, now) && run.input) {
    ui.show_settings = !ui.show_settings;
    ui.draft_loaded = false;
  }
  if (pressed(Action::plots, now)) set_plots_paused(ui, h, !ui.plots_paused);
  if (pressed(Action::progress, now)) ui.show_progress = !ui.show_progress;
}

void enter_panels(UiState& ui) {
  ui.keyboard_in_panels = true;
  ui.focus_panels = true;
}

void update_keyboard_focus(UiState& ui, const RunInfo& /*run*/) {
  ImGuiIO& io = ImGui::GetIO();
  if (ui.keyboard_in_panels) io.ConfigFlags |= ImGuiConfigFlags_NavEnableKeyboard;
  else io.ConfigFlags &= ~ImGuiConfigFlags_NavEnableKeyboard;
  if (ui.keyboard_in_panels) {
    // Said where it cannot be missed, at the view's bottom right (above a replay's transport).
    const char* text = "keyboard in the panels · Esc: back to the flight";
    const ImVec2 ts = ImGui::CalcTextSize(text);
    const float pad = ImGui::GetStyle().FramePadding.x;
    const ImGuiWindow* view = ImGui::FindWindowByName("##view");
    const ImVec2 corner = view && view->WasActive
                              ? ImVec2(view->Pos.x + view->Size.x, view->Pos.y + view->Size.y)
                              : io.DisplaySize;
    const ImVec2 at(corner.x - ts.x - 3.0f * pad, corner.y - ts.y - 3.0f * pad);
    ImDrawList* dl = ImGui::GetForegroundDrawList();
    dl->AddRectFilled(ImVec2(at.x - pad, at.y - pad), ImVec2(at.x + ts.x + pad, at.y + ts.y + pad),
                      IM_COL32(0x10, 0x10, 0x14, 220), pad);
    dl->AddText(at, IM_COL32(0xF0, 0xE4, 0x42, 255), text);
  }
}

void focus_panels(UiState& ui) {
  // Before any item of the frame: ImGui's navigation picks the panel's first control (or its
  // default) while the items are submitted, from the windows of the last frame.
  if (!ui.focus_panels) return;
  // The welcome or the tour while they show (once drawn); else the frontmost open panel.
  const char* const first_launch[] = {ui.first_launch == FirstLaunch::welcome ? kWelcomeWindow
                                                                              : kTourWindow};
  const char* const panels[] = {"Map a gamepad", "Input settings (I)", "Progress (H)", kHelpWindow,
                                "Score card",    "Session",            "Debrief",      "##transport",
                                "##top"};
  const std::span<const char* const> order =
      ui.first_launch != FirstLaunch::none ? std::span<const char* const>(first_launch)
                                           : std::span<const char* const>(panels);
  for (const char* name : order) {
    ImGuiWindow* w = ImGui::FindWindowByName(name);
    if (!w || !w->WasActive || w->Hidden) continue;
    ImGui::FocusWindow(w);
    ImGui::NavInitWindow(w, true);
    ImGuiContext& g = *GImGui;
    g.NavDisableHighlight = false;
    g.NavDisableMouseHover = true;
    ui.focus_panels = false;
    return;
  }
  // The welcome or the tour not drawn yet: next frame. No panel at all: nothing to focus.
  if (ui.first_launch == FirstLaunch::none) ui.focus_panels = false;
}

}  // namespace mixpilot::ui
