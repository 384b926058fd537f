#include "ui/screen.hpp"

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <vector>

#include <imgui_internal.h>  // the panes' sizes of the last frame (FindWindowByName)

#include "ui/chase_camera.hpp"
#include "ui/first_launch.hpp"
#include "ui/ghost.hpp"
#include "ui/panels.hpp"
#include "ui/instructor_hud.hpp"
#include "ui/reason.hpp"
#include "ui/shortcuts.hpp"
#include "ui/score_card.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

const char* to_string(Camera c) {
  switch (c) {
    case Camera::chase: return "chase";
    case Camera::orbit: return "orbit";
    case Camera::top: return "top";
    case Camera::side: return "side";
  }
  return "?";
}

const char* to_string(RunState s) {
  switch (s) {
    case RunState::ready: return "READY";
    case RunState::waiting: return "WAITING";
    case RunState::flying: return "FLYING";
    case RunState::paused: return "PAUSED";
    case RunState::finished: return "FINISHED";
    case RunState::replay: return "REPLAY";
    case RunState::loading: return "LOADING";
    case RunState::lost: return "LOST";
  }
  return "?";
}

namespace {

// Fixed panes stay behind (ImGui puts each such window at the back when it is created) and
// show the frame's clear colour, colour::kPane; overlays come after them and never take the
// focus.
constexpr ImGuiWindowFlags kPane = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                   ImGuiWindowFlags_NoSavedSettings |
                                   ImGuiWindowFlags_NoBringToFrontOnFocus | ImGuiWindowFlags_NoBackground;
constexpr ImGuiWindowFlags kOverlay = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                      ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoInputs |
                                      ImGuiWindowFlags_NoFocusOnAppearing |
                                      ImGuiWindowFlags_NoBackground;

ImU32 state_colour(RunState s) {
  switch (s) {
    case RunState::flying: return colour::kMpc;
    case RunState::paused: return colour::kCaution;
    case RunState::waiting: return colour::kCaution;
    case RunState::lost: return colour::kCritical;
    case RunState::replay: return colour::kPilot;
    default: return colour::rgb(0x80, 0x88, 0x90);
  }
}

// What the item just drawn does, on hover (every control has one).
void tip(const char* text) {
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", text);
}

// The status pill: as tall as a button, so the first row lines up.
void pill(const char* text, ImU32 c) {
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const ImVec2 ts = ImGui::CalcTextSize(text);
  const ImVec2 pad(ImGui::GetFontSize() * 0.66f, ImGui::GetStyle().FramePadding.y);
  const ImVec2 size(ts.x + 2 * pad.x, ImGui::GetFrameHeight());
  ImGui::GetWindowDrawList()->AddRectFilled(p, ImVec2(p.x + size.x, p.y + size.y), c, 0.5f * size.y);
  ImGui::GetWindowDrawList()->AddText(ImVec2(p.x + pad.x, p.y + pad.y), colour::rgb(0x10, 0x10, 0x10),
                                      text);
  ImGui::Dummy(size);
}

// A pane whose height is its content's: `width` wide at `pos`, its top left corner, or its
// bottom left with pivot (0, 1). ImGui fits its height to what it held in the last frame.
void begin_pane(const char* name, ImVec2 pos, float width, ImVec2 pivot = ImVec2(0, 0)) {
  ImGui::SetNextWindowPos(pos, ImGuiCond_Always, pivot);
  ImGui::SetNextWindowSizeConstraints(ImVec2(width, 0.0f), ImVec2(width, FLT_MAX));
  ImGui::Begin(name, nullptr, kPane | ImGuiWindowFlags_AlwaysAutoResize);
}

// The top bar: the pill, the title, Open and Help; then the flight's controls and time, the
// recording mark and the app's message, wrapping onto further rows where the width runs out.
// Returns its height.
float top_bar(const Scene& sc, const History& h, const RunInfo& run, UiState& ui, Requests& out,
              float width) {
  begin_pane("##top", ImVec2(0, 0), width);
  pill(to_string(run.state), state_colour(run.state));
  ImGui::SameLine();
  // A replay has its controls and its time in the transport bar: here only the way back.
  if (run.replay) {
    if (ImGui::Button("Back to live (Esc)")) out.push_back(LeaveReplay{});
    tip("Leave the replay: back to the live flight and its session panel");
    ImGui::SameLine();
  }
  // File and help at the right end; the title gives way to them (elided, full text on hover).
  const ImGuiStyle& st = ImGui::GetStyle();
  const float right_w = button_width("Open... (Ctrl+O)") + button_width("Help (F1)") +
                        st.ItemSpacing.x;
  const float right_x = ImGui::GetWindowContentRegionMax().x - right_w;
  const std::string title =
      sc.title + "   ·   " + to_string(sc.mode) + "   ·   " + sc.input_source;
  const float title_w = right_x - st.ItemSpacing.x - ImGui::GetCursorPosX();
  ImGui::AlignTextToFramePadding();
  ImGui::TextUnformatted(elide_middle(title, std::max(0.0f, title_w)).c_str());
  if (ImGui::IsItemHovered() && ImGui::CalcTextSize(title.c_str()).x > title_w)
    ImGui::SetTooltip("%s", title.c_str());
  ImGui::SameLine(std::max(ImGui::GetCursorPosX(), right_x));
  if (ImGui::Button("Open... (Ctrl+O)")) ui.open_dialog.open = true;
  tip("Open a scenario (.toml) to fly or a recording (.mcap) to replay");
  ImGui::SameLine();
  if (ImGui::Button("Help (F1)")) ui.show_help = !ui.show_help;
  tip("Every key, the text size, and the welcome again");

  // The second row: what the flight does now, the buttons first.
  if (!run.replay) {
    bool first = true;
    const auto button = [&](const char* label) {
      if (!first) same_line_or_wrap(button_width(label));
      first = false;
      return ImGui::Button(label);
    };
    if (run.state == RunState::ready) {
      if (button("Start (Space)")) out.push_back(StartFlight{});
      tip("Start the flight: the clock runs and the pilot flies");
      ui.marks.start_min = ImGui::GetItemRectMin();
      ui.marks.start_max = ImGui::GetItemRectMax();
    } else if (run.state == RunState::waiting) {
      if (button("Cancel (Esc)")) out.push_back(CancelVehicleWait{});
      tip("Stop waiting for the remote vehicle");
    } else if (run.state == RunState::flying || run.state == RunState::paused) {
      if (button(run.state == RunState::paused ? "Resume (Space)" : "Pause (Space)"))
        out.push_back(TogglePause{});
      tip(run.state == RunState::paused ? "Go on flying" : "Freeze the flight (the clock stops)");
    }
    if (run.can_restart && run.state != RunState::ready) {
      if (button("Restart (R)")) out.push_back(RestartFlight{});
      tip("Fly the same flight again from its start");
    }
    for (double sp : {0.25, 0.5, 1.0}) {
      char label[16];
      std::snprintf(label, sizeof label, "%gx", sp);
      if (!first) same_line_or_wrap(radio_width(label));
      first = false;
      if (ImGui::RadioButton(label, run.speed == sp)) out.push_back(SetFlightSpeed{sp});
      tip(sp < 1.0 ? "Slow motion: the flight runs at this share of real time"
                   : "Real time");
    }
    const Telemetry* s = h.empty() ? nullptr : &h.newest();
    ImGui::PushFont(mono_font());
    char time[64];
    std::snprintf(time, sizeof time, "t %6.2f / %.0f s", s ? s->t : 0.0, sc.duration);
    same_line_or_wrap(ImGui::CalcTextSize(time).x + ImGui::CalcTextSize(" ").x);
    ImGui::AlignTextToFramePadding();
    ImGui::Text(" %s", time);
    ImGui::PopFont();
  }
  if (run.recording) {
    same_line_or_wrap(ImGui::CalcTextSize("● REC").x);
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "● REC");
  }
  if (!run.message.empty()) {
    // After the controls when a useful part of it fits there, else on a row of its own; what
    // does not fit is elided and shown whole on hover.
    const float full = ImGui::CalcTextSize(run.message.c_str()).x;
    same_line_or_wrap(std::min(full, 16 * ImGui::GetFontSize()), 2 * st.ItemSpacing.x);
    const float w = ImGui::GetWindowContentRegionMax().x - ImGui::GetCursorPosX();
    const std::string shown = elide_middle(run.message, w);
    if (run.message_is_error)
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "%s", shown.c_str());
    else
      ImGui::TextUnformatted(shown.c_str());
    if (shown != run.message && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", run.message.c_str());
  }
  const float height = ImGui::GetWindowHeight();
  ImGui::End();
  return height;
}

// The HUD's longest item: it needs at least this width.
constexpr const char* kWidestHudItem = "in B 100.0 % of the last 60 s";

// The HUD: the authority bar, then deviation, time in B, RTI time, fallbacks, deadline
// misses and a remote vehicle's round trip, each item wrapping within `width`. Compact (for a
// short view): a thinner bar without the shares' names under it, and fewer lines.
// Returns the screen y of its bottom edge.
float hud(const Scene& sc, const History& h, const RunInfo& run, ImVec2 pos, float width,
          bool compact, TourMarks& marks) {
  ImGui::SetNextWindowPos(pos);
  ImGui::SetNextWindowSize(ImVec2(width, 0.0f));
  // A translucent backing keeps its text readable over the scene.
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::Begin("##hud", nullptr,
               (kOverlay & ~ImGuiWindowFlags_NoBackground) | ImGuiWindowFlags_AlwaysAutoResize);
  const Telemetry* s = h.empty() ? nullptr : &h.newest();
  const float w = ImGui::GetContentRegionAvail().x;
  if (sc.shared_authority) {
    // Before the first step (READY) the telemetry holds what the first step will use: the
    // initial λ within the instructor's bounds (core/modes/mi_mode.cpp).
    const ImVec2 bar_min = ImGui::GetCursorScreenPos();
    const float bar_h = (compact ? 1.4f : 2.0f) * ImGui::GetFontSize();
    draw_authority_bar(s ? s->lambda : 1.0, bar_min, ImVec2(bar_min.x + w, bar_min.y + bar_h),
                       !compact, sc.probe, s ? s->instructor.bounds : AuthorityBounds{});
    marks.bar_min = bar_min;
    marks.bar_max = ImVec2(bar_min.x + w, bar_min.y + bar_h);
    ImGui::Dummy(ImVec2(w, bar_h + (compact ? scaled(5) : scaled(4) + ImGui::GetTextLineHeight())));
    // Why λ fell, while it matters and a moment after (ui/reason.hpp); the safe hold has its
    // own line below.
    const std::optional<std::size_t> why = shown_reason(h);
    if (why && !(s->events & kEventSafeHold)) {
      const Telemetry& r = h[*why];
      ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + w);
      ImGui::PushStyleColor(ImGuiCol_Text,
                            r.reason.cap == LambdaCap::probe ? colour::kPilot : colour::kPlanner);
      ImGui::TextUnformatted(reason_text(r, sc.ball_radius).c_str());
      ImGui::PopStyleColor();
      ImGui::PopTextWrapPos();
    }
  }
  // The instructor (ui/instructor_hud.hpp): each command as it takes effect, for a few seconds, and
  // what is in force, on lines of their own.
  if (s) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + w);
    if (run.instructor_paused) {
      ImGui::PushStyleColor(ImGuiCol_Text, colour::kCaution);
      ImGui::TextUnformatted("paused by the instructor");
      ImGui::PopStyleColor();
    }
    // The newest two (one on a short view): the debrief keeps them all.
    for (const std::string& banner : instructor_banners(h, compact ? 1 : 2)) {
      ImGui::PushStyleColor(ImGuiCol_Text, colour::kCaution);
      ImGui::TextUnformatted(banner.c_str());
      ImGui::PopStyleColor();
    }
    // What is in force, item by item, wrapping between items.
    bool first_item = true;
    for (const std::string& part : instructor_in_force(*s)) {
      if (!first_item) same_line_or_wrap(ImGui::CalcTextSize(part.c_str()).x);
      first_item = false;
      ImGui::TextUnformatted(part.c_str());
    }
    ImGui::PopTextWrapPos();
  }
  // The ghost (ui/ghost.hpp): a dashed swatch in its colour, as its trail is drawn, and how far
  // ahead or behind along the reference the flight is; what it is, on hover.
  if (sc.ghost && s) {
    const std::string line = ghost_hud_text(sc, *s);
    const ImVec2 at = ImGui::GetCursorScreenPos();
    const float dash = 0.5f * ImGui::GetFontSize(), y = at.y + 0.5f * ImGui::GetTextLineHeight();
    for (int i = 0; i < 3; ++i)
      ImGui::GetWindowDrawList()->AddLine(ImVec2(at.x + float(i) * 1.5f * dash, y),
                                          ImVec2(at.x + (float(i) * 1.5f + 1.0f) * dash, y),
                                          colour::kGhost, scaled(2.5f));
    ImGui::Dummy(ImVec2(4.5f * dash, 0.0f));
    ImGui::SameLine();
    ImGui::PushTextWrapPos(ImGui::GetWindowContentRegionMax().x);
    ImGui::PushStyleColor(ImGuiCol_Text, colour::kGhost);
    ImGui::TextUnformatted(line.c_str());
    ImGui::PopStyleColor();
    ImGui::PopTextWrapPos();
  }
  ImGui::PushFont(mono_font());
  const float gap = ImGui::CalcTextSize("   ").x;
  bool first = true;
  // An item wider than the HUD (a large text scale) wraps at its words inside it.
  const auto item = [&](const char* text, ImU32 colour) {
    if (!first) same_line_or_wrap(ImGui::CalcTextSize(text).x, gap);
    first = false;
    ImGui::PushTextWrapPos(0.0f);
    ImGui::PushStyleColor(ImGuiCol_Text, colour);
    ImGui::TextUnformatted(text);
    ImGui::PopStyleColor();
    ImGui::PopTextWrapPos();
  };
  char text[96];
  if (sc.shared_authority) {
    // Over the last minute at most (a replay's history is the whole flight up to the playhead).
    std::int64_t in_ball = 0;
    const std::size_t from = h.empty() ? 0 : h.first_at_or_after(h.newest().t - 60.0 + 0.5 * sc.dt);
    for (std::size_t i = from; i < h.size(); ++i)
      in_ball += channel_value(h[i], "deviation") <= sc.ball_radius ? 1 : 0;
    const std::size_t n = h.size() - from;
    std::snprintf(text, sizeof text, "deviation %.3f m (r %.2f)",
                  s ? channel_value(*s, "deviation") : 0.0, sc.ball_radius);
    item(text, colour::kText);
    const double share = n ? 100.0 * double(in_ball) / double(n) : 100.0;
    if (compact)
      std::snprintf(text, sizeof text, "in B %5.1f %%", share);
    else
      std::snprintf(text, sizeof text, "in B %5.1f %% of the last %.0f s", share,
                    n ? h.newest().t - h[from].t + sc.dt : 0.0);
    item(text, colour::kText);
  }
  first = !compact;  // the solver on a line of its own, where there is room
  std::snprintf(text, sizeof text, "RTI %5.0f us", s ? s->stats.total_us : 0.0);
  item(text, colour::kText);
  std::snprintf(text, sizeof text, "fallbacks %lld", static_cast<long long>(run.fallbacks));
  item(text, colour::kText);
  // Deadline misses in the caution colour once there are any (UI.md §8).
  std::snprintf(text, sizeof text, "deadline misses %lld", static_cast<long long>(run.deadline_misses));
  item(text, run.deadline_misses > 0 ? colour::kCaution : colour::kText);
  // The MPC's plan ran out (SPEC §4's failure policy exhausted): the safe controller flies.
  if (s && (s->events & kEventSafeHold)) {
    first = true;
    item("SAFE HOLD: this machine cannot keep up;", colour::kCritical);
    item("the safe controller flies", colour::kCritical);
  }
  // A remote vehicle (SPEC §9): the round-trip time the predictor uses, and the newest sample.
  if (const double rtt = s ? channel_value(*s, "RTT estimate", -1.0) : -1.0; rtt >= 0.0) {
    first = true;
    item("remote vehicle:", colour::kText);
    std::snprintf(text, sizeof text, "RTT %5.1f ms estimated,", 1e3 * rtt);
    item(text, colour::kText);
    std::snprintf(text, sizeof text, "last sample %5.1f ms", 1e3 * channel_value(*s, "RTT sample", 0.0));
    item(text, colour::kText);
  }
  ImGui::PopFont();
  const float bottom = ImGui::GetWindowPos().y + ImGui::GetWindowHeight();
  ImGui::End();
  return bottom;
}

}  // namespace

namespace {

// The height ImGui gave the pane `name` in the last frame (its content's), else `fallback`.
float pane_height(const char* name, float fallback) {
  const ImGuiWindow* w = ImGui::FindWindowByName(name);
  return w && w->Size.y > 0.0f ? w->Size.y : fallback;
}

// Before a pane was ever laid out: `rows` rows of buttons.
float rows_height(int rows) {
  const ImGuiStyle& st = ImGui::GetStyle();
  return 2.0f * st.WindowPadding.y + float(rows) * ImGui::GetFrameHeightWithSpacing() - st.ItemSpacing.y;
}

// The plots' width: a third of a wide display, never narrower than its legends need.
float plots_width(float display_w) {
  const float em = ImGui::GetFontSize();
  return std::min(std::clamp(0.3f * display_w, 18.5f * em, 30.5f * em), 0.45f * display_w);
}

// The view pane: between the top bar and the transport, left of the plots.
void view_pane(ImVec2 display, float top, float bottom, ImVec2& min, ImVec2& max) {
  min = ImVec2(0, top);
  max = ImVec2(display.x - plots_width(display.x), std::max(top, display.y - bottom));
}

// The session panel shows while no flight is under way.
bool session_panel_shown(const RunInfo& run) {
  return run.session && !run.replay && run.state != RunState::flying &&
         run.state != RunState::paused;
}

// The HUD's least width: its longest item's.
float hud_least_width() {
  return mono_font()->CalcTextSizeA(ImGui::GetFontSize(), FLT_MAX, 0.0f, kWidestHudItem).x +
         2 * ImGui::GetStyle().WindowPadding.x;
}

// The session panel's width in a view `view_w` wide: narrower (down to what its buttons need)
// where the view is narrow, to leave the scene some room and the HUD its place beside it (READY
// shows the authority bar the flight starts with).
float session_panel_width(float view_w) {
  const float em = ImGui::GetFontSize(), m = ImGui::GetStyle().WindowPadding.x;
  return std::min(
      std::clamp(std::min(view_w - 10.0f * em, view_w - 3.0f * m - hud_least_width()), 14.0f * em,
                 20.0f * em),
      view_w - 2.0f * m);
}

// A replay's Debrief panel (its window's name: the layout reads its last frame by it).
constexpr const char* kDebriefWindow = "Debrief";

// The vehicle's half size on screen as a part of the frame's height (the chase camera's
// distance and field of view), with a margin.
constexpr float kVehicleInFrame = 0.13f;

// Where the view frames its scene (the chase camera keeps the vehicle at its centre): the pane,
// less the panel at its left (the session panel, a replay's Debrief panel) and the HUD above
// where they would cover that centre (a small window, a large scale), so the vehicle stays in
// sight. `panel_right`: the left panel's right edge (the pane's left without one);
// `hud_bottom`: the HUD's bottom edge (the pane's top without one).
ImVec2 frame_min(ImVec2 min, ImVec2 max, float panel_right, float hud_bottom) {
  const float m = ImGui::GetStyle().WindowPadding.x, em = ImGui::GetFontSize();
  ImVec2 f = min;
  if (panel_right > min.x && panel_right + 3.0f * em > 0.5f * (min.x + max.x))
    f.x = std::min(panel_right + m, max.x - 1.0f);
  if (hud_bottom + m > 0.5f * (min.y + max.y) - kVehicleInFrame * (max.y - min.y))
    f.y = std::min(hud_bottom + m, max.y - 1.0f);
  return f;
}

}  // namespace

void view_rect(ImVec2 display, const RunInfo& run, ImVec2& min, ImVec2& max) {
  const float top = pane_height("##top", rows_height(2));
  const float bottom = run.replay ? pane_height("##transport", rows_height(3)) : 0.0f;
  view_pane(display, top, bottom, min, max);
  const ImGuiWindow* hud = ImGui::FindWindowByName("##hud");
  const float hud_bottom = hud && hud->Active ? hud->Pos.y + hud->Size.y : min.y;
  float panel_right = min.x;
  if (session_panel_shown(run)) {
    panel_right = min.x + ImGui::GetStyle().WindowPadding.x + session_panel_width(max.x - min.x);
  } else if (const ImGuiWindow* d = ImGui::FindWindowByName(kDebriefWindow);
             run.replay && d && d->Active) {
    panel_right = d->Pos.x + d->Size.x;
  }
  min = frame_min(min, max, panel_right, hud_bottom);
}

void draw_screen(const Scene& sc, const History& h, const RunInfo& run, UiState& ui,
                 Requests& out) {
  const ImVec2 d = ImGui::GetIO().DisplaySize;
  const ImGuiStyle& st = ImGui::GetStyle();
  const float em = ImGui::GetFontSize();
  focus_panels(ui);
  ui.marks = TourMarks{};  // drawn again below
  // READY: the chase camera turns, where it must, so that no obstacle hides the vehicle.
  if (run.state == RunState::ready && !h.empty()) {
    const ChasePose pose = clear_chase_pose(sc, h.newest());
    ui.chase_turn = pose.turn;
    ui.chase_rise = pose.rise;
  }
  // The panes take their heights from their content (top bar, transport), the view the rest.
  const float top = top_bar(sc, h, run, ui, out, d.x);
  float bottom = 0.0f;
  if (run.replay) {
    begin_pane("##transport", ImVec2(0, d.y), d.x, ImVec2(0, 1));
    draw_transport(run, out);
    bottom = ImGui::GetWindowHeight();
    ImGui::End();
  }
  ImVec2 vmin, vmax;
  view_pane(d, top, bottom, vmin, vmax);
  const float view_w = vmax.x - vmin.x;

  // The overlays on the view first (the view pane stays behind them: ImGui keeps it at the
  // back), so the scene can be framed in what they leave. They keep a margin from the view's
  // edges and from each other.
  const float m = st.WindowPadding.x;
  const bool panel = session_panel_shown(run);
  ImVec2 panel_max(vmin.x, vmin.y);  // its bottom right corner
  if (panel) {
    const float panel_w = session_panel_width(view_w);
    const float panel_h = std::max(0.0f, vmax.y - top - 2 * m);
    ImGui::SetNextWindowPos(ImVec2(vmin.x + m, top + m));
    ImGui::SetNextWindowSizeConstraints(ImVec2(panel_w, 0), ImVec2(panel_w, panel_h));
    ImGui::Begin("Session", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                     ImGuiWindowFlags_AlwaysAutoResize);
    draw_session_panel(run, ui, out, panel_h);
    panel_max = ImVec2(ImGui::GetWindowPos().x + ImGui::GetWindowWidth(),
                       ImGui::GetWindowPos().y + ImGui::GetWindowHeight());
    ImGui::End();
  }

  const float hud_least = hud_least_width();
  // A replay's Debrief panel (L) at the view's left like the session panel, the HUD beside it
  // where both fit; else under the HUD (which the authority bar keeps first), where there is
  // room for a few rows of it.
  const bool debrief = run.replay && ui.show_debrief;
  const float debrief_w = std::min(20.0f * em, view_w - 3 * m - hud_least);
  const bool debrief_beside = debrief && debrief_w >= 13.0f * em;
  bool left = panel;  // a panel at the view's left, its bottom right corner panel_max
  const auto debrief_panel = [&](ImVec2 pos, float w, float max_h) {
    ImGui::SetNextWindowPos(pos);
    ImGui::SetNextWindowSizeConstraints(ImVec2(w, 0), ImVec2(w, max_h));
    ImGui::Begin(kDebriefWindow, nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                     ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoFocusOnAppearing);
    draw_debrief_panel(run, ui, max_h, out);
    panel_max = ImVec2(ImGui::GetWindowPos().x + ImGui::GetWindowWidth(),
                       ImGui::GetWindowPos().y + ImGui::GetWindowHeight());
    ImGui::End();
    left = true;
  };
  if (debrief_beside) debrief_panel(ImVec2(vmin.x + m, top + m), debrief_w, vmax.y - top - 2 * m);

  // The HUD at the top centre of the view, beside the left panel; where the view is too
  // narrow for both (a small window, a large scale) it waits for the flight to start.
  float hud_bottom = top;
  {
    const float lo = left ? panel_max.x + m : vmin.x + m, room = vmax.x - m - lo;
    const float w = std::min(std::clamp(0.6f * view_w, 28.0f * em, 43.0f * em), room);
    if (w >= hud_least) {
      const float x = std::max(lo, std::min(vmin.x + 0.5f * (view_w - w), vmax.x - m - w));
      hud_bottom = hud(sc, h, run, ImVec2(x, top + m), w, vmax.y - vmin.y < 24.0f * em, ui.marks);
    }
  }
  if (debrief && !debrief_beside) {
    const float y = hud_bottom + m, max_h = vmax.y - m - y;
    if (max_h >= 6.0f * ImGui::GetFrameHeightWithSpacing())
      debrief_panel(ImVec2(vmin.x + m, y), std::min(20.0f * em, view_w - 2 * m), max_h);
  }
  const ImVec2 frame = frame_min(vmin, vmax, left ? panel_max.x : vmin.x, hud_bottom);
  const ImVec2 centre(0.5f * (frame.x + vmax.x), 0.5f * (frame.y + vmax.y));

  // The sticks at the bottom of the frame over the camera line, below the vehicle or, where
  // the view is short, beside it; shrunk down to a readable size. Placed before the view is
  // drawn, so the arena's labels keep clear of them.
  bool sticks = false;
  ImVec2 sticks_min(0, 0), sticks_size(0, 0);
  if (sc.shared_authority && ui.show_sticks && !h.empty()) {
    const float floor = vmax.y - ImGui::GetTextLineHeightWithSpacing() - m;
    const float vehicle = kVehicleInFrame * (vmax.y - frame.y);
    const float aspect = 300.0f / 170.0f, least = scaled(80);
    const auto fit = [&](float above, float width) {
      return std::min({scaled(170), floor - above, width / aspect});
    };
    // Below the vehicle, centred.
    float ht = fit(std::max(hud_bottom, centre.y + vehicle) + m, vmax.x - frame.x - 2 * m);
    float x = std::clamp(centre.x - 0.5f * ht * aspect, frame.x + m, vmax.x - m - ht * aspect);
    if (ht < least) {  // at the bottom right, clear of the vehicle
      const float beside = centre.x + vehicle + m;
      ht = fit(std::max(hud_bottom, frame.y) + m, vmax.x - m - beside);
      x = vmax.x - m - ht * aspect;
    }
    // Beside a panel at the view's left rather than under it, where they fit there.
    if (left && x < panel_max.x + m && floor - ht < panel_max.y + m &&
        panel_max.x + m + ht * aspect <= vmax.x - m)
      x = panel_max.x + m;
    const bool clear_of_panel = !left || x >= panel_max.x + m || floor - ht >= panel_max.y + m;
    sticks = ht >= least && clear_of_panel;
    sticks_min = ImVec2(x, floor - ht);
    sticks_size = ImVec2(ht * aspect, ht);
  }

  ImGui::SetNextWindowPos(vmin);
  ImGui::SetNextWindowSize(ImVec2(view_w, vmax.y - vmin.y));
  ImGui::Begin("##view", nullptr, kPane | ImGuiWindowFlags_NoScrollbar);
  if (sc.view == ViewKind::arm_2d) draw_pendubot(sc, h, vmin, vmax, frame);
  else if (sticks)
    draw_arena(sc, h, ui, vmin, vmax, frame, sticks_min,
               ImVec2(sticks_min.x + sticks_size.x, sticks_min.y + sticks_size.y));
  else draw_arena(sc, h, ui, vmin, vmax, frame);
  ImGui::End();

  if (sticks) {
    ImGui::SetNextWindowPos(sticks_min);
    ImGui::SetNextWindowSize(sticks_size);
    ImGui::Begin("##sticks", nullptr, kOverlay);
    ui.marks.sticks_min = sticks_min;
    ui.marks.sticks_max = ImVec2(sticks_min.x + sticks_size.x, sticks_min.y + sticks_size.y);
    const ImVec2 p = ImGui::GetCursorScreenPos();
    draw_sticks(h.newest(), sc.hover_rotor_speed, p,
                ImVec2(p.x + sticks_size.x - 2 * st.WindowPadding.x,
                       p.y + sticks_size.y - 2 * st.WindowPadding.y));
    ImGui::End();
  }

  // The plots scroll when the pane is too short for them all.
  ImGui::SetNextWindowPos(ImVec2(vmax.x, top));
  ImGui::SetNextWindowSize(ImVec2(d.x - vmax.x, vmax.y - top));
  ImGui::Begin("##plots", nullptr, kPane & ~ImGuiWindowFlags_NoScrollbar);
  draw_plots(sc, h, ui);
  ImGui::End();

  if (run.metrics.empty()) {
    ui.score_card_closed = false;
  } else if (!ui.score_card_closed) {
    bool open = true;
    if (run.card) {
      draw_score_card(*run.card, run.replay != nullptr, open, d, out);
    } else {  // the score fields alone (a caller that made no card)
      FlightOutcome o;
      o.metrics = run.metrics;
      draw_score_card(score_card_of(o), false, open, d, out);
    }
    if (!open) ui.score_card_closed = true;
  }
  if (ui.show_help) draw_help_sheet(run, ui, out, d);
  if (ui.show_progress) {
    static const HistoryView kOff = [] {
      HistoryView v;
      v.loaded = true;
      v.progress.error = "no history: this window was opened with --history off";
      return v;
    }();
    draw_progress_panel(run.history ? *run.history : kOff, ui.show_progress, d, out);
  }
  draw_input_banner(h, run, frame, vmax);
  draw_input_settings(run, ui, out);
  draw_mapping_wizard(run, out);
  draw_open_dialog(ui, out);
  // The keys before the welcome and the tour, which take theirs (a key that ends them is not
  // acted on again here).
  handle_keys(ui, out, run, h);
  draw_first_launch(run, ui, out, d);
  update_keyboard_focus(ui, run);
  if (run.input && run.input->pilot == "keyboard" && !run.replay)
    out.push_back(HeldFlightKeys{held_flight_keys()});
}

void set_plots_paused(UiState& ui, const History& h, bool paused) {
  ui.plots_paused = paused;
  ui.plots_paused_at = paused && !h.empty() ? h.newest().t : -1.0;
}

}  // namespace mixpilot::ui
