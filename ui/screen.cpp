#include "ui/screen.hpp"

#include <algorithm>
#include <cstdio>

#include "ui/panels.hpp"
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
    case RunState::lost: return colour::kCritical;
    case RunState::replay: return colour::kPilot;
    default: return colour::rgb(0x80, 0x88, 0x90);
  }
}

// `text` shortened in its middle ("start…end") to fit `width` pixels of the current font.
std::string elide_middle(const std::string& text, float width) {
  if (ImGui::CalcTextSize(text.c_str()).x <= width) return text;
  const std::string dots = "\u2026";
  // Cut whole UTF-8 code points: never split a continuation byte (10xxxxxx).
  auto cut = [&](std::size_t keep) {
    std::size_t head = keep / 2, tail = text.size() - (keep - keep / 2);
    while (head > 0 && (static_cast<unsigned char>(text[head]) & 0xC0) == 0x80) --head;
    while (tail < text.size() && (static_cast<unsigned char>(text[tail]) & 0xC0) == 0x80) ++tail;
    return text.substr(0, head) + dots + text.substr(tail);
  };
  std::size_t lo = 0, hi = text.size();  // longest kept byte count that fits
  while (lo < hi) {
    const std::size_t mid = (lo + hi + 1) / 2;
    if (ImGui::CalcTextSize(cut(mid).c_str()).x <= width) lo = mid; else hi = mid - 1;
  }
  return cut(lo);
}

void pill(const char* text, ImU32 c) {
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const ImVec2 ts = ImGui::CalcTextSize(text);
  const ImVec2 size(ts.x + 20, ts.y + 8);
  ImGui::GetWindowDrawList()->AddRectFilled(p, ImVec2(p.x + size.x, p.y + size.y), c, 10.0f);
  ImGui::GetWindowDrawList()->AddText(ImVec2(p.x + 10, p.y + 4), colour::rgb(0x10, 0x10, 0x10),
                                      text);
  ImGui::Dummy(size);
}

void top_bar(const Scene& sc, const History& h, const RunInfo& run, UiState& ui, UiRequest& req,
             ImVec2 pos, ImVec2 size) {
  ImGui::SetNextWindowPos(pos);
  ImGui::SetNextWindowSize(size);
  ImGui::Begin("##top", nullptr, kPane);
  pill(to_string(run.state), state_colour(run.state));
  ImGui::SameLine();
  // File and help at the right end; the title gives way to them (elided, full text on hover).
  const ImGuiStyle& st = ImGui::GetStyle();
  const float right_w = ImGui::CalcTextSize("Open... (Ctrl+O)").x +
                        ImGui::CalcTextSize("Help (F1)").x + 4 * st.FramePadding.x +
                        2 * st.ItemSpacing.x + st.WindowPadding.x;
  const std::string title =
      sc.title + "   ·   " + to_string(sc.mode) + "   ·   " + sc.input_source;
  const float title_w = size.x - right_w - ImGui::GetCursorPosX();
  ImGui::TextUnformatted(elide_middle(title, title_w).c_str());
  if (ImGui::IsItemHovered() && ImGui::CalcTextSize(title.c_str()).x > title_w)
    ImGui::SetTooltip("%s", title.c_str());
  ImGui::SameLine(std::max(ImGui::GetCursorPosX(), size.x - right_w));
  if (ImGui::Button("Open... (Ctrl+O)")) ui.open_dialog.open = true;
  ImGui::SameLine();
  if (ImGui::Button("Help (F1)")) ui.show_help = !ui.show_help;

  const Telemetry* s = h.empty() ? nullptr : &h.newest();
  ImGui::PushFont(mono_font());
  ImGui::Text("t %6.2f / %.0f s   speed %.2fx", s ? s->t : 0.0, sc.duration, run.speed);
  ImGui::PopFont();
  if (run.replay) {
    if (ImGui::Button("Back to live (Esc)")) req.leave_replay = true;
  } else {
    if (run.state == RunState::ready) {
      if (ImGui::Button("Start (Space)")) req.start = true;
    } else if (run.state == RunState::flying || run.state == RunState::paused) {
      if (ImGui::Button(run.state == RunState::paused ? "Resume (Space)" : "Pause (Space)"))
        req.toggle_pause = true;
    }
    ImGui::SameLine();
    if (run.can_restart && run.state != RunState::ready) {
      if (ImGui::Button("Restart (R)")) req.restart = true;
      ImGui::SameLine();
    }
    for (double sp : {0.25, 0.5, 1.0}) {
      char label[16];
      std::snprintf(label, sizeof label, "%gx", sp);
      if (ImGui::RadioButton(label, run.speed == sp)) req.speed = sp;
      ImGui::SameLine();
    }
  }
  if (run.recording) {
    ImGui::SameLine();
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "● REC");
  }
  if (!run.message.empty()) {
    if (run.message_is_error)
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "%s", run.message.c_str());
    else
      ImGui::TextUnformatted(run.message.c_str());
  }
  ImGui::End();
}

// The HUD under the authority bar: deviation, time in B, RTI time, fallbacks, misses, and a
// remote vehicle's round-trip time.
// Returns the screen y of its bottom edge.
float hud(const Scene& sc, const History& h, const RunInfo& run, ImVec2 pos, ImVec2 size) {
  ImGui::SetNextWindowPos(pos);
  ImGui::Begin("##hud", nullptr, kOverlay | ImGuiWindowFlags_AlwaysAutoResize);
  const Telemetry* s = h.empty() ? nullptr : &h.newest();
  const ImVec2 bar_min = ImGui::GetCursorScreenPos();
  if (sc.mode == ModeKind::mixed_initiative) {
    // Before the first solve (the initial state) the pilot has the authority.
    draw_authority_bar(s && s->solved ? s->lambda : 1.0, bar_min, ImVec2(bar_min.x + size.x - 16, bar_min.y + 30));
    ImGui::Dummy(ImVec2(size.x - 16, 30 + ImGui::GetTextLineHeightWithSpacing()));
  }
  // Over the last minute at most (a replay's history is the whole flight up to the playhead).
  std::int64_t in_ball = 0;
  const std::size_t from = h.empty() ? 0 : h.first_at_or_after(h.newest().t - 60.0 + 0.5 * sc.dt);
  for (std::size_t i = from; i < h.size(); ++i) {
    in_ball += channel_value(h[i], "deviation") <= sc.ball_radius ? 1 : 0;
  }
  const std::size_t n = h.size() - from;
  const double dev = s ? channel_value(*s, "deviation") : 0.0;
  ImGui::PushFont(mono_font());
  if (sc.mode == ModeKind::mixed_initiative) {
    char deviation[64], ball[64];
    std::snprintf(deviation, sizeof deviation, "deviation %.3f m (r %.2f)", dev, sc.ball_radius);
    std::snprintf(ball, sizeof ball, "in B %5.1f %% of the last %.0f s",
                  n ? 100.0 * double(in_ball) / double(n) : 100.0,
                  n ? h.newest().t - h[from].t + sc.dt : 0.0);
    // One line where the arena is wide enough, two where it is not.
    ImGui::TextUnformatted(deviation);
    const float one_line = ImGui::CalcTextSize(deviation).x + ImGui::CalcTextSize("   ").x +
                           ImGui::CalcTextSize(ball).x;
    if (one_line <= size.x - 16) ImGui::SameLine(0, ImGui::CalcTextSize("   ").x);
    ImGui::TextUnformatted(ball);
  }
  ImGui::Text("RTI %5.0f us   fallbacks %lld", s ? s->stats.total_us : 0.0,
              static_cast<long long>(run.fallbacks));
  ImGui::SameLine();
  // Deadline misses in the caution colour once there are any (UI.md §8).
  if (run.deadline_misses > 0) ImGui::PushStyleColor(ImGuiCol_Text, colour::kCaution);
  ImGui::Text("  deadline misses %lld", static_cast<long long>(run.deadline_misses));
  if (run.deadline_misses > 0) ImGui::PopStyleColor();
  // A remote vehicle (SPEC §9): the round-trip time the predictor uses, and the newest sample.
  if (const double rtt = s ? channel_value(*s, "RTT estimate", -1.0) : -1.0; rtt >= 0.0) {
    ImGui::Text("remote vehicle: RTT %5.1f ms estimated, last sample %5.1f ms", 1e3 * rtt,
                1e3 * channel_value(*s, "RTT sample", 0.0));
  }
  ImGui::PopFont();
  const float bottom = ImGui::GetCursorScreenPos().y;
  ImGui::End();
  return bottom;
}

// What each score field means (README, Scoring), for the score card.
const char* meaning(const std::string& key) {
  static const std::pair<const char*, const char*> kMeanings[] = {
      {"duration_s", "time flown [s]"},
      {"progress", "share of the reference flown"},
      {"time_in_ball", "share of the time inside the ball B"},
      {"max_deviation_m", "largest distance from the reference [m]"},
      {"rms_deviation_m", "RMS distance from the reference [m]"},
      {"mean_lambda", "mean authority of the pilot (1: all pilot)"},
      {"min_lambda", "least authority of the pilot"},
      {"collisions", "contacts with obstacles, walls or floor"},
      {"min_clearance_m", "closest approach to an obstacle [m]"},
      {"override_rms", "RMS of what the MPC changed in the pilot's tilt [rad]"},
      {"stick_smoothness", "RMS change of the pilot's command per step [rad]"},
      {"rti_median_us", "median RTI time per step [us]"},
      {"rti_p99_us", "99th percentile RTI time [us]"},
      {"deadline_misses", "steps whose RTI time exceeded the control period"},
      {"fallbacks", "steps that applied the previous solution's input"},
      {"skill", "the score: progress x quality / (1 + collisions), 0-100"},
      {"lost", "1: the vehicle was lost"},
      {"lost_at_s", "when it was lost [s]"},
      {"rtt_s", "round-trip time to the vehicle (remote: the median sample) [s]"},
      {"rtt_estimated_s", "the online round-trip estimate at the end [s]"},
  };
  for (const auto& [k, v] : kMeanings)
    if (key == k) return v;
  return "";
}

void score_card(const RunInfo& run, UiState& ui, ImVec2 display) {
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  bool open = true;
  ImGui::Begin("Score card", &open,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove);
  if (ImGui::BeginTable("##score", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (const auto& [key, value] : run.metrics) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(key.c_str());
      ImGui::TableNextColumn();
      ImGui::PushFont(mono_font());
      ImGui::Text("%10.4g", value);
      ImGui::PopFont();
      ImGui::TableNextColumn();
      ImGui::TextDisabled("%s", meaning(key));
    }
    ImGui::EndTable();
  }
  ImGui::End();
  if (!open) ui.score_card_closed = true;
}

// The shortcut sheet (F1 or ?), UI.md §10.
void help_sheet(UiState& ui, ImVec2 display) {
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::Begin("Keyboard and mouse (F1)", &ui.show_help,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove);
  static const std::pair<const char*, const char*> kKeys[] = {
      {"Space", "start / pause / resume the flight; play / pause a replay"},
      {"R", "restart the flight"},
      {"Ctrl+R", "record the next flight or not"},
      {"Ctrl+O", "open a scenario (.toml) or a recording (.mcap)"},
      {"1  2  3  4", "camera: chase, orbit, top, side"},
      {"mouse drag, wheel", "orbit the arena, zoom"},
      {"D", "show / hide the sticks"},
      {"P", "pause / resume the plots"},
      {"Left / Right", "replay: step 100 ms (Shift 10 ms, Alt 500 ms)"},
      {"Home / End", "replay: start / end"},
      {"Up / Down", "replay: faster / slower (0.25x to 8x)"},
      {"[  ]", "replay: previous / next event"},
      {"Esc", "leave the replay; close this sheet"},
      {"F1  ?", "this sheet"},
  };
  if (ImGui::BeginTable("##keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (const auto& [key, what] : kKeys) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::PushFont(mono_font());
      ImGui::TextUnformatted(key);
      ImGui::PopFont();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(what);
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

bool pressed(int key) { return ImGui::IsKeyPressed(key); }
bool pressed(ImGuiKey_ key) { return ImGui::IsKeyPressed(ImGui::GetKeyIndex(key)); }

// The replay speeds, slowest first (↑ / ↓ move along them).
constexpr double kReplaySpeeds[] = {0.25, 0.5, 1.0, 2.0, 4.0, 8.0};

void replay_keys(const RunInfo& run, UiRequest& req) {
  const ReplayInfo& r = *run.replay;
  const ImGuiIO& io = ImGui::GetIO();
  const double step = io.KeyShift ? 0.01 : io.KeyAlt ? 0.5 : 0.1;
  if (pressed(ImGuiKey_LeftArrow)) req.seek = std::max(0.0, r.t - step);
  if (pressed(ImGuiKey_RightArrow)) req.seek = std::min(r.loaded * r.duration, r.t + step);
  if (pressed(ImGuiKey_Home)) req.seek = 0.0;
  if (pressed(ImGuiKey_End)) req.seek = r.loaded * r.duration;
  const auto at = std::find(std::begin(kReplaySpeeds), std::end(kReplaySpeeds), run.speed);
  if (pressed(ImGuiKey_UpArrow))
    req.speed = at == std::end(kReplaySpeeds) || at + 1 == std::end(kReplaySpeeds) ? 8.0 : *(at + 1);
  if (pressed(ImGuiKey_DownArrow))
    req.speed = at == std::end(kReplaySpeeds) || at == std::begin(kReplaySpeeds) ? 0.25 : *(at - 1);
  if (pressed('[')) req.jump = -1;
  if (pressed(']')) req.jump = +1;
  if (pressed(ImGuiKey_Escape) && !ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId)) req.leave_replay = true;
}

void keys(UiState& ui, UiRequest& req, const RunInfo& run, const History& h) {
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard || ui.open_dialog.open) return;
  if (pressed(kKeyF1)) ui.show_help = !ui.show_help;
  for (int i = 0; i < io.InputQueueCharacters.Size; ++i)
    if (io.InputQueueCharacters[i] == '?') ui.show_help = !ui.show_help;
  if (io.KeyCtrl) {
    if (pressed('O')) ui.open_dialog.open = true;
    if (pressed('R') && run.session) req.record = run.session->record ? 0 : 1;
    return;
  }
  if (pressed(ImGuiKey_Escape) && ui.show_help) ui.show_help = false;
  else if (run.replay) replay_keys(run, req);
  if (pressed(ImGuiKey_Space))
    (run.state == RunState::ready ? req.start : req.toggle_pause) = true;
  if (pressed('R') && run.can_restart && !run.replay) req.restart = true;
  if (pressed('1')) ui.camera = Camera::chase;
  if (pressed('2')) ui.camera = Camera::orbit;
  if (pressed('3')) ui.camera = Camera::top;
  if (pressed('4')) ui.camera = Camera::side;
  const bool keyboard_flies = run.input && run.input->pilot == "keyboard" && !run.replay;
  if (pressed('D') && !keyboard_flies) ui.show_sticks = !ui.show_sticks;
  if (pressed('I') && run.input) {
    ui.show_settings = !ui.show_settings;
    ui.draft_loaded = false;
  }
  if (pressed('P')) set_plots_paused(ui, h, !ui.plots_paused);
}

}  // namespace

void view_rect(ImVec2 display, const RunInfo& run, ImVec2& min, ImVec2& max) {
  const float top = 96.0f, right = std::clamp(0.3f * display.x, 280.0f, 460.0f);
  const float bottom = run.replay ? 78.0f : 0.0f;  // the replay's transport bar
  min = ImVec2(0, top);
  max = ImVec2(display.x - right, display.y - bottom);
}

UiRequest draw_screen(const Scene& sc, const History& h, const RunInfo& run, UiState& ui) {
  UiRequest req;
  const ImVec2 d = ImGui::GetIO().DisplaySize;
  ImVec2 vmin, vmax;
  view_rect(d, run, vmin, vmax);
  const float top = vmin.y, right = d.x - vmax.x, bottom = d.y - vmax.y;
  top_bar(sc, h, run, ui, req, ImVec2(0, 0), ImVec2(d.x, top));

  ImGui::SetNextWindowPos(vmin);
  ImGui::SetNextWindowSize(ImVec2(vmax.x - vmin.x, vmax.y - vmin.y));
  ImGui::Begin("##view", nullptr, kPane | ImGuiWindowFlags_NoScrollbar);
  if (sc.mode == ModeKind::pendubot_swingup) draw_pendubot(sc, h, vmin, vmax);
  else draw_arena(sc, h, ui, vmin, vmax);
  ImGui::End();

  // The session panel at the view's top left while no flight is under way.
  const bool panel = run.session && !run.replay && run.state != RunState::flying &&
                     run.state != RunState::paused;
  const float panel_w = 300.0f;
  if (panel) {
    ImGui::SetNextWindowPos(ImVec2(8, top + 8));
    ImGui::SetNextWindowSize(ImVec2(panel_w, 0));
    ImGui::Begin("Session", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                     ImGuiWindowFlags_AlwaysAutoResize);
    draw_session_panel(run, ui, req);
    ImGui::End();
  }

  const float view_w = d.x - right;
  const float hud_w = std::min(0.6f * view_w, 640.0f);
  const float hud_x = std::max(0.5f * (view_w - hud_w), panel ? panel_w + 16 : 0.0f);
  const float hud_bottom =
      hud(sc, h, run, ImVec2(hud_x, top + 8), ImVec2(std::min(hud_w, view_w - hud_x - 8), 110));

  // The sticks below the HUD, shrunk (down to a readable size) when the window is short.
  const float sticks_ht = std::min(170.0f, d.y - bottom - 8 - hud_bottom);
  if (sc.mode == ModeKind::mixed_initiative && ui.show_sticks && !h.empty() &&
      sticks_ht >= 100.0f) {
    const float ht = sticks_ht, w = ht * 300.0f / 170.0f;
    ImGui::SetNextWindowPos(ImVec2(0.5f * (view_w - w), d.y - bottom - ht - 8));
    ImGui::SetNextWindowSize(ImVec2(w, ht));
    ImGui::Begin("##sticks", nullptr, kOverlay);
    const ImVec2 p = ImGui::GetCursorScreenPos();
    draw_sticks(h.newest(), sc.hover_rotor_speed, p, ImVec2(p.x + w - 16, p.y + ht - 16));
    ImGui::End();
  }

  ImGui::SetNextWindowPos(ImVec2(d.x - right, top));
  ImGui::SetNextWindowSize(ImVec2(right, d.y - top - bottom));
  ImGui::Begin("##plots", nullptr, kPane);
  draw_plots(sc, h, ui);
  ImGui::End();

  if (run.replay) {
    ImGui::SetNextWindowPos(ImVec2(0, d.y - bottom));
    ImGui::SetNextWindowSize(ImVec2(d.x, bottom));
    ImGui::Begin("##transport", nullptr, kPane);
    draw_transport(run, req);
    ImGui::End();
  }
  if (run.metrics.empty()) ui.score_card_closed = false;
  else if (!ui.score_card_closed) score_card(run, ui, d);
  if (ui.show_help) help_sheet(ui, d);
  draw_input_banner(h, run, vmin, vmax);
  draw_input_settings(run, ui, req);
  draw_mapping_wizard(run, req);
  draw_open_dialog(ui, req);
  keys(ui, req, run, h);
  if (run.input && run.input->pilot == "keyboard" && !run.replay) req.flight_keys = held_flight_keys();
  return req;
}

void set_plots_paused(UiState& ui, const History& h, bool paused) {
  ui.plots_paused = paused;
  ui.plots_paused_at = paused && !h.empty() ? h.newest().t : -1.0;
}

}  // namespace mixpilot::ui
