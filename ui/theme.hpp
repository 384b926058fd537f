#pragma once
// One colour scheme everywhere (Okabe–Ito, UI.md §9): the pilot and the planner keep their
// colours in the authority bar, the trail, the plots and the sticks.
#include <string>

#include <imgui.h>

namespace mixpilot::ui {

namespace colour {
inline constexpr ImU32 rgb(unsigned r, unsigned g, unsigned b, unsigned a = 255) {
  return (ImU32(a) << 24) | (ImU32(b) << 16) | (ImU32(g) << 8) | ImU32(r);
}
inline constexpr ImU32 kPilot = rgb(0x56, 0xB4, 0xE9);    // sky blue
inline constexpr ImU32 kPlanner = rgb(0xE6, 0x9F, 0x00);  // orange
inline constexpr ImU32 kMpc = rgb(0x00, 0x9E, 0x73);      // bluish green: what was applied
inline constexpr ImU32 kCaution = rgb(0xF0, 0xE4, 0x42);  // yellow
inline constexpr ImU32 kCritical = rgb(0xD5, 0x5E, 0x00); // vermilion
inline constexpr ImU32 kReference = rgb(0xEE, 0xEE, 0xEE, 200);
inline constexpr ImU32 kGrid = rgb(0x60, 0x66, 0x70, 160);
inline constexpr ImU32 kWall = rgb(0x90, 0x98, 0xA8, 200);
inline constexpr ImU32 kObstacle = rgb(0xCC, 0x79, 0xA7);  // reddish purple
// A ghost (ui/ghost.hpp): lavender, a hue no other thing on the arena has, lighter than the
// obstacles' purple; drawn translucent, with a dashed trail and filled rotors (the vehicle's
// are rings), so it reads apart from the vehicle in greyscale too.
inline constexpr ImU32 kGhost = rgb(0xB4, 0xA0, 0xFF);
inline constexpr ImU32 kBackground = rgb(0x16, 0x19, 0x1E);  // the arena and plot areas
// The panes (top bar, plots, transport): the frame is cleared to it and the panes draw no
// background of their own, which spares a software rasterizer a screenful of blending.
inline constexpr ImU32 kPane = rgb(0x19, 0x1C, 0x21);
inline constexpr ImU32 kText = rgb(0xE8, 0xE8, 0xE8);
}  // namespace colour

// The colour of authority λ ∈ [0, 1]: planner (0) … pilot (1), through grey.
ImU32 authority_colour(double lambda);

// Dark style, sizes scaled by `scale` (the display's content scale: 1 at 96 dpi, 1.5 at 144).
void apply_style(float scale);

// The scale apply_style was given. Sizes the UI draws itself (line widths, radii, gaps) are
// written for 100 % and pass through scaled(), so they grow with the fonts; layout is in units
// of the font size and the style's metrics.
float ui_scale();
inline float scaled(float pixels_at_100) { return pixels_at_100 * ui_scale(); }

// Loads DejaVu Sans (and Sans Mono) found through fontconfig at round(15·scale) px, with the
// Greek glyphs (λ, φ, θ, Ω); ImGui's built-in font (13·scale px) when none is found. Returns
// the file used, or "" for the built-in.
std::string load_fonts(float scale);

// The monospace font for numbers (the default font when none was loaded).
ImFont* mono_font();

// Adds DejaVu Sans at `factor` times the text's size for headings (a printed figure's title),
// after load_fonts() and before the first frame; nullptr when it cannot (then there is none).
ImFont* add_heading_font(float scale, float factor);
// The heading font added, or nullptr.
ImFont* heading_font();

}  // namespace mixpilot::ui
