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
    case RunState::lost: return "LOST";
  }
  return "?";
}

namespace {

// Fixed panes stay behind (ImGui puts each such window at the back when it is created);
// overlays come after them and never take the focus.
constexpr ImGuiWindowFlags kPane = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                   ImGuiWindowFlags_NoSavedSettings |
                                   ImGuiWindowFlags_NoBringToFrontOnFocus;
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

void pill(const char* text, ImU32 c) {
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const ImVec2 ts = ImGui::CalcTextSize(text);
  const ImVec2 size(ts.x + 20, ts.y + 8);
  ImGui::GetWindowDrawList()->AddRectFilled(p, ImVec2(p.x + size.x, p.y + size.y), c, 10.0f);
  ImGui::GetWindowDrawList()->AddText(ImVec2(p.x + 10, p.y + 4), colour::rgb(0x10, 0x10, 0x10),
                                      text);
  ImGui::Dummy(size);
}

void top_bar(const Scene& sc, const History& h, const RunInfo& run, UiRequest& req, ImVec2 pos,
             ImVec2 size) {
  ImGui::SetNextWindowPos(pos);
  ImGui::SetNextWindowSize(size);
  ImGui::Begin("##top", nullptr, kPane);
  pill(to_string(run.state), state_colour(run.state));
  ImGui::SameLine();
  ImGui::Text("%s   ·   %s   ·   %s", sc.title.c_str(), to_string(sc.mode),
              sc.input_source.c_str());
  const Telemetry* s = h.empty() ? nullptr : &h.newest();
  ImGui::PushFont(mono_font());
  ImGui::Text("t %6.2f / %.0f s   speed %.2fx", s ? s->t : 0.0, sc.duration, run.speed);
  ImGui::PopFont();
  if (run.state == RunState::ready) {
    if (ImGui::Button("Start (Space)")) req.start = true;
  } else if (run.state == RunState::flying || run.state == RunState::paused) {
    if (ImGui::Button(run.state == RunState::paused ? "Resume (Space)" : "Pause (Space)"))
      req.toggle_pause = true;
  }
  ImGui::SameLine();
  if (run.can_restart) {
    if (ImGui::Button("Restart (R)")) req.restart = true;
    ImGui::SameLine();
  }
  for (double sp : {0.25, 0.5, 1.0}) {
    char label[16];
    std::snprintf(label, sizeof label, "%gx", sp);
    if (ImGui::RadioButton(label, run.speed == sp)) req.speed = sp;
    ImGui::SameLine();
  }
  if (run.recording) ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "● REC");
  else ImGui::NewLine();
  if (!run.message.empty()) ImGui::TextUnformatted(run.message.c_str());
  ImGui::End();
}

// The HUD under the authority bar: deviation, time in B, RTI time, fallbacks, misses.
void hud(const Scene& sc, const History& h, const RunInfo& run, ImVec2 pos, ImVec2 size) {
  ImGui::SetNextWindowPos(pos);
  ImGui::Begin("##hud", nullptr, kOverlay | ImGuiWindowFlags_AlwaysAutoResize);
  const Telemetry* s = h.empty() ? nullptr : &h.newest();
  const ImVec2 bar_min = ImGui::GetCursorScreenPos();
  if (sc.mode == ModeKind::mixed_initiative) {
    draw_authority_bar(s ? s->lambda : 1.0, bar_min, ImVec2(bar_min.x + size.x - 16, bar_min.y + 30));
    ImGui::Dummy(ImVec2(size.x - 16, 30 + ImGui::GetTextLineHeightWithSpacing()));
  }
  std::int64_t fallbacks = 0, in_ball = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    fallbacks += (h[i].events & kEventFallback) ? 1 : 0;
    in_ball += channel_value(h[i], "deviation") <= sc.ball_radius ? 1 : 0;
  }
  const std::size_t n = h.size();
  const double dev = s ? channel_value(*s, "deviation") : 0.0;
  ImGui::PushFont(mono_font());
  if (sc.mode == ModeKind::mixed_initiative)
    ImGui::Text("deviation %.3f m (r %.2f)   in B %5.1f %% of the last %.0f s", dev,
                sc.ball_radius,
                n ? 100.0 * double(in_ball) / double(n) : 100.0,
                n ? h.newest().t - h[0].t + sc.dt : 0.0);
  ImGui::Text("RTI %5.0f us   fallbacks %lld   deadline misses %lld", s ? s->stats.total_us : 0.0,
              static_cast<long long>(fallbacks), static_cast<long long>(run.deadline_misses));
  ImGui::PopFont();
  ImGui::End();
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
  };
  for (const auto& [k, v] : kMeanings)
    if (key == k) return v;
  return "";
}

void score_card(const RunInfo& run, ImVec2 display) {
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::Begin("Score card", nullptr,
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
}

void keys(UiState& ui, UiRequest& req, const RunInfo& run) {
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Space)))
    (run.state == RunState::ready ? req.start : req.toggle_pause) = true;
  if (ImGui::IsKeyPressed('R') && run.can_restart) req.restart = true;
  if (ImGui::IsKeyPressed('1')) ui.camera = Camera::chase;
  if (ImGui::IsKeyPressed('2')) ui.camera = Camera::orbit;
  if (ImGui::IsKeyPressed('3')) ui.camera = Camera::top;
  if (ImGui::IsKeyPressed('4')) ui.camera = Camera::side;
  if (ImGui::IsKeyPressed('D')) ui.show_sticks = !ui.show_sticks;
}

}  // namespace

UiRequest draw_screen(const Scene& sc, const History& h, const RunInfo& run, UiState& ui) {
  UiRequest req;
  const ImVec2 d = ImGui::GetIO().DisplaySize;
  const float top = 96.0f, right = std::clamp(0.3f * d.x, 280.0f, 460.0f);
  top_bar(sc, h, run, req, ImVec2(0, 0), ImVec2(d.x, top));

  ImGui::SetNextWindowPos(ImVec2(0, top));
  ImGui::SetNextWindowSize(ImVec2(d.x - right, d.y - top));
  ImGui::Begin("##view", nullptr, kPane | ImGuiWindowFlags_NoScrollbar);
  const ImVec2 vmin(0, top), vmax(d.x - right, d.y);
  if (sc.mode == ModeKind::pendubot_swingup) draw_pendubot(sc, h, vmin, vmax);
  else draw_arena(sc, h, ui, vmin, vmax);
  ImGui::End();

  const float hud_w = std::min(0.6f * (d.x - right), 640.0f);
  hud(sc, h, run, ImVec2(0.5f * (d.x - right - hud_w), top + 8), ImVec2(hud_w, 110));

  if (sc.mode == ModeKind::mixed_initiative && ui.show_sticks && !h.empty()) {
    const float w = 300, ht = 170;
    ImGui::SetNextWindowPos(ImVec2(0.5f * (d.x - right - w), d.y - ht - 8));
    ImGui::SetNextWindowSize(ImVec2(w, ht));
    ImGui::Begin("##sticks", nullptr, kOverlay);
    const ImVec2 p = ImGui::GetCursorScreenPos();
    draw_sticks(h.newest(), sc.hover_rotor_speed, p, ImVec2(p.x + w - 16, p.y + ht - 16));
    ImGui::End();
  }

  ImGui::SetNextWindowPos(ImVec2(d.x - right, top));
  ImGui::SetNextWindowSize(ImVec2(right, d.y - top));
  ImGui::Begin("##plots", nullptr, kPane);
  draw_plots(sc, h, ui);
  ImGui::End();
  if (!run.metrics.empty()) score_card(run, d);
  keys(ui, req, run);
  return req;
}

}  // namespace mixpilot::ui
