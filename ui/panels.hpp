#pragma once
// The panels of the screen (ui/screen.hpp), each drawing into the current ImGui window's
// region [min, max) from the scene and the history.
#include <string>

#include <imgui.h>

#include "ui/scene.hpp"
#include "ui/screen.hpp"

namespace mixpilot::ui {

// 3D arena of the quadrotor modes over the pane [min, max), framed in [frame, max) (what the
// overlays leave of it; view_rect); the mouse orbits and zooms when over it. Its labels keep
// clear of [clear_min, clear_max) where they can (an overlay drawn over the view: the sticks).
// `camera_hint`: the camera and its keys at the bottom left (not where 1-4 mean something else).
void draw_arena(const Scene& scene, const History& history, UiState& ui, ImVec2 min, ImVec2 max,
                ImVec2 frame, ImVec2 clear_min = ImVec2(0, 0), ImVec2 clear_max = ImVec2(0, 0),
                bool camera_hint = true);
// Where draw_arena puts the world point `p` on screen, `newest` being the newest telemetry and
// [min, max) the frame (view_rect); false when it is behind the camera.
bool project_in_arena(const Scene& scene, const Telemetry& newest, const UiState& ui, ImVec2 min,
                      ImVec2 max, const Eigen::Vector3d& p, ImVec2& px);
// 2D side view of the Pendubot over the pane [min, max), framed in [frame, max).
void draw_pendubot(const Scene& scene, const History& history, ImVec2 min, ImVec2 max,
                   ImVec2 frame);
// The authority bar: planner 0 … 1 pilot, the fill up to λ in the authority colour; with
// `names`, the shares' names under it (a text line below max.y). A probe flight's bar says
// PROBE in its label and "assistance off" where the planner's share is named. The instructor's
// `bounds` (SPEC §10), when not [0, 1]: the share λ cannot reach is shaded, a tick in the
// caution colour marks each bound, and "ceiling 0.30" (or "floor 0.20 · ceiling 0.80") is said
// under its tick between the names, or in the label where there is no room there.
void draw_authority_bar(double lambda, ImVec2 min, ImVec2 max, bool names = true,
                        bool probe = false, const AuthorityBounds& bounds = {});
// Pilot command (filled dot) and MPC applied (diamond) on roll/pitch and thrust/yaw gimbals.
// The thrust stick is centred on the hover rotor speed `hover`.
void draw_sticks(const Telemetry& s, double hover, ImVec2 min, ImVec2 max);
// Rolling plots of the mode's channels (frozen while ui.plots_paused).
void draw_plots(const Scene& scene, const History& history, UiState& ui);
// The session panel: scenario, pilot, trainee, record, start / restart (run.session); at most
// `max_height` tall, the start or restart button always in sight under the choices (which
// scroll when they do not fit).
void draw_session_panel(const RunInfo& run, UiState& ui, Requests& out, float max_height);
// A replay's transport bar: timeline with event ticks, play / pause, events, speeds (run.replay).
void draw_transport(const RunInfo& run, Requests& out);
// The colour of a debrief event's kind, and its mark (shape and colour, `size` its half width)
// centred at `centre`: the timeline's ticks and the Debrief panel's rows share them.
ImU32 event_colour(DebriefKind kind);
void draw_event_mark(ImDrawList* dl, ImVec2 centre, float size, DebriefKind kind);
// A replay's Debrief panel (SPEC §10): its events (run.replay->events) with time and words, the
// selected one highlighted; a click selects one and moves the playhead to it. At most
// `max_height` tall: the list scrolls (to the selected event when the selection changes).
void draw_debrief_panel(const RunInfo& run, UiState& ui, float max_height, Requests& out);
// File → Open: a modal browser of scenarios and recordings while ui.open_dialog.open.
void draw_open_dialog(UiState& ui, Requests& out);
// Fills the dialog's entries from its folder.
void list_folder(OpenDialog& dialog);
// The input settings panel (ui.show_settings, run.input): stick mode, tilt and thrust, each
// axis's curve with the live stick on it, input loss, haptic cue; Apply / Save.
void draw_input_settings(const RunInfo& run, UiState& ui, Requests& out);
// The mapping wizard (while InputInfo::wizard is set): the prompt, the raw device, the line.
void draw_mapping_wizard(const RunInfo& run, Requests& out);
// The input-loss banner over the view while the pilot's device is lost or not yet back.
void draw_input_banner(const History& history, const RunInfo& run, ImVec2 min, ImVec2 max);
// The flight keys held now (bit k: input::Key k).
unsigned held_flight_keys();

// Layout: rows that wrap instead of running out of their window, so a pane holds at any
// display scale what it holds at 100 %.
// The width ImGui gives a button, a radio button or checkbox, of `label`.
float button_width(const char* label);
float radio_width(const char* label);
// Puts the next item (`width` wide) on the current row, `spacing` after the last (< 0: the
// style's), when it fits in the window's content region; else at the start of the next row.
void same_line_or_wrap(float width, float spacing = -1.0f);
// `text` shortened in its middle ("start…end") to fit `width` pixels of the current font.
std::string elide_middle(const std::string& text, float width);

}  // namespace mixpilot::ui
