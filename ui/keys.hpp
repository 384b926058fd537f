#pragma once
// The keys the UI knows, by name. ImGui 1.86 reads a key as an index into io.KeysDown, in
// whatever numbering the platform backend writes there; here the numbering is the UI's own:
// a backend (the window maps GLFW's key codes, app/window.cpp) writes io.KeysDown[int(Key)],
// and use_key_names() points ImGui's own keys (Tab, the arrows, Enter, Ctrl+C...) at the same
// names, so no platform's key codes reach ui/. The headless renderer and the tests press keys
// by these names.
#include <iterator>

#include <imgui.h>

#include "input/keyboard.hpp"

namespace mixpilot::ui {

enum class Key : int {
  // Letters and digits in order: a backend may count from Key::a and Key::digit0.
  a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, q, r, s, t, u, v, w, x, y, z,
  digit0, digit1, digit2, digit3, digit4, digit5, digit6, digit7, digit8, digit9,
  f1, f2, f3, f4, f5, f6, f7, f8, f9, f10, f11, f12,
  space, enter, keypad_enter, escape, tab, backspace, insert, del,
  left, right, up, down, page_up, page_down, home, end,
  left_bracket, right_bracket, minus, equal, keypad_subtract, keypad_add, keypad_0,
  left_shift, right_shift, left_ctrl, right_ctrl, left_alt, right_alt, left_super, right_super,
  count
};
static_assert(int(Key::count) <= int(sizeof(ImGuiIO::KeysDown) / sizeof(bool)));

// Points io.KeyMap (ImGui's own keys) at the UI's key names; once, after the platform backend
// has set up (it fills io.KeyMap with its own codes).
void use_key_names(ImGuiIO& io);

// Whether `k` went down in this frame (with ImGui's key repeat) / is held.
inline bool key_pressed(Key k) { return ImGui::IsKeyPressed(int(k)); }
inline bool key_down(Key k) { return ImGui::IsKeyDown(int(k)); }
// Holds or releases `k` for the next frames, as a backend does.
inline void set_key(ImGuiIO& io, Key k, bool down) { io.KeysDown[int(k)] = down; }

// A replay's "Export clip": the playhead ± ui::kClipHalfWidth saved as a video (the button's
// label and the help sheet name it too).
inline constexpr Key kExportClipKey = Key::e;
inline constexpr const char* kExportClipKeyName = "E";
// A replay's "fly from here" (SPEC §10): T takes the controls at the playhead ("take over"; no
// other shortcut uses it, nor do the keyboard pilot's keys).
inline constexpr Key kFlyFromHereKey = Key::t;

// A replay's Debrief panel, the list of what happened (SPEC §10), shown or hidden ("list"; no
// other shortcut uses it, nor do the keyboard pilot's keys).
inline constexpr Key kDebriefKey = Key::l;
inline constexpr const char* kDebriefKeyName = "L";

// The keys that fly the keyboard pilot (input/keyboard.hpp), indexed by input::Key: W S A D
// and the arrows.
inline constexpr Key kFlightKeys[] = {Key::w, Key::s, Key::a, Key::d,
                                      Key::up, Key::down, Key::left, Key::right};
static_assert(std::size(kFlightKeys) == std::size_t(input::Key::count));

}  // namespace mixpilot::ui
