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
// Okabe–Ito's hues, their lightness chosen so that what must be told apart is told apart by
// lightness alone (kMustTellApart below): in greyscale and for red–green colour blindness.
inline constexpr ImU32 kPilot = rgb(0x8F, 0xD0, 0xF5);    // light sky blue
inline constexpr ImU32 kPlanner = rgb(0xE6, 0x9F, 0x00);  // orange: text and lines
// The planner's share of the authority bar: the orange dark enough to stand apart from the
// pilot's light blue by lightness (the orange itself is as light as the blue).
inline constexpr ImU32 kPlannerFill = rgb(0x94, 0x54, 0x00);
inline constexpr ImU32 kMpc = rgb(0x00, 0x9E, 0x73);      // bluish green: what was applied
inline constexpr ImU32 kCaution = rgb(0xFF, 0xF0, 0x4A);  // yellow
inline constexpr ImU32 kCritical = rgb(0xC2, 0x5D, 0x00); // vermilion
inline constexpr ImU32 kNote = rgb(0xB8, 0xBE, 0xC6);     // grey: what only informs
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
// The windows' background (apply_style's WindowBg, opaque): the score card, the panels.
inline constexpr ImU32 kWindow = rgb(0x1A, 0x1C, 0x21);
inline constexpr ImU32 kText = rgb(0xE8, 0xE8, 0xE8);
// The authority bar's outline (its extent, whatever λ is) and the dark casing that keeps its
// needle apart from the light pilot share.
inline constexpr ImU32 kBarOutline = rgb(0xA8, 0xAE, 0xB6);
inline constexpr ImU32 kNeedleCasing = rgb(0x10, 0x12, 0x15);

// Two colours that must be told apart, where the screen puts one against the other, and why.
struct Apart {
  ImU32 a, b;
  const char* where;
};
// Every pair the screen tells apart by colour: the λ bar's shares and its needle and outline
// (UI.md acceptance 2: who has authority at a glance, in greyscale too), and the debrief
// events' severities against each other and the panes they are drawn on. The kinds of events
// are told apart by their marks' shapes (draw_event_mark) and named in words; colour says
// only how serious an event was. tests/test_ui.cpp (ScoreCard.PaletteReads...) requires a
// luminance contrast of at least kLeastContrast for each pair in normal vision, greyscale,
// protanopia and deuteranopia.
inline constexpr double kLeastContrast = 3.0;  // WCAG 2.1 SC 1.4.11, graphical objects
inline constexpr Apart kMustTellApart[] = {
    {kPilot, kPlannerFill, "the authority bar: the pilot's share against the planner's"},
    {kText, kPlannerFill, "the authority bar: the needle on the planner's share"},
    {kNeedleCasing, kPilot, "the authority bar: the needle's casing on the pilot's share"},
    {kBarOutline, kWindow, "the authority bar: its outline on the HUD"},
    {kCaution, kCritical, "debrief events: a warning (near miss, takeover) against an error "
                          "(collision, vehicle lost)"},
    {kCaution, kPane, "debrief events: a warning's mark on the timeline"},
    {kCritical, kPane, "debrief events: an error's mark on the timeline"},
    {kNote, kPane, "debrief events: a marker's mark on the timeline"},
    {kCaution, kWindow, "debrief events: a warning's mark in the Debrief panel, the score card"},
    {kCritical, kWindow, "debrief events: an error's mark in the Debrief panel, the score card"},
    {kNote, kWindow, "debrief events: a marker's mark in the Debrief panel"},
};
}  // namespace colour

// The colour of authority λ ∈ [0, 1] (the trail): the authority bar's planner share (0) … its
// pilot share (1), lighter as λ rises, so λ reads in greyscale too.
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

// The large bold font load_fonts() adds for a number that comes first (the score card's score),
// kLargeFactor times the text's size, ASCII only; nullptr when DejaVu Sans Bold is not found
// (then the text's font drawn at that size).
inline constexpr float kLargeFactor = 2.4f;
ImFont* large_font();

}  // namespace mixpilot::ui
