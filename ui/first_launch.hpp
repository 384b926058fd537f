#pragma once
// The first launch (SPEC §8; UI.md's newcomer's checks): a welcome that offers three ways in —
// watch the emulated novice fly mi_helix with the planner's help, fly yourself (the gamepad
// found, by its name, else the keyboard, with its keys), or start the beginner course under a
// trainee's name — then a short tour of callouts pointing at the real widgets (the authority
// bar and what λ means, the ball B, the sticks, Start), stepped through or skipped. The app
// decides when it shows (app/trainer.hpp); F1 shows it again. Keyboard-only: it takes the
// keyboard (ui/shortcuts.hpp), 1 2 3 pick a way, the arrows and Space press, Esc is "not now".
#include <span>

#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::ui {

inline constexpr const char* kWelcomeWindow = "Welcome to mixpilot";
inline constexpr const char* kTourWindow = "##tour";

// A step of the tour: what it points at, its heading and its words.
enum class TourTarget { authority_bar, ball, sticks, start };
struct TourStep {
  TourTarget target;
  const char* title;
  const char* text;
};
std::span<const TourStep> tour_steps();

// The gamepad the welcome offers ("" none): the one in use, else the first SDL can use.
std::string found_gamepad(const RunInfo& run);

// Shows the welcome (and gives it the keyboard).
void show_welcome(UiState& ui);

// While ui.first_launch is welcome / tour: the centred welcome, or the tour's callout for step
// ui.tour_step next to what it points at (ui.marks, the last frame's), outlined.
void draw_first_launch(const RunInfo& run, UiState& ui, Requests& out, ImVec2 display);

}  // namespace mixpilot::ui
