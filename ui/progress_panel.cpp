// The Progress panel (SPEC §10): one trainee's flights of one scenario from the history's
// snapshot (ui/progress.hpp) — skill per attempt for assisted and probe flights, the assistance
// dependence D, the best run, the trend, and the last flights with their recordings to replay.
// A function of the snapshot: it formats numbers into fixed buffers and allocates nothing.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ui/panels.hpp"
#include "ui/progress.hpp"
#include "ui/plot.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

namespace {

// The series' colours (UI.md §9): an assisted flight is what the MPC applied with the planner's
// help, a probe is the pilot alone, D is the planner's share.
constexpr ImU32 kAssisted = colour::kMpc;
constexpr ImU32 kProbe = colour::kPilot;
constexpr ImU32 kDependence = colour::kPlanner;
constexpr ImU32 kMuted = colour::rgb(170, 170, 170);

void coloured(ImU32 c, const char* text) {
  ImGui::PushStyleColor(ImGuiCol_Text, c);
  ImGui::TextUnformatted(text);
  ImGui::PopStyleColor();
}

void tooltip(const char* text) {
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

const char* kind_of(const ProgressFlight& f) { return f.probe ? "probe" : "assisted"; }

// Skill (0-100, left axis) per attempt, assisted and probe flights as two series, D (0-1, right
// axis) as a third; the best run ringed; the attempt under the mouse said in a line above.
void skill_plot(const ProgressView& v, float height) {
  const std::vector<ProgressFlight>& fl = v.flights;
  const ImVec2 top = ImGui::GetCursorScreenPos();
  const float width = ImGui::GetContentRegionAvail().x;
  const float label_w = ImGui::CalcTextSize("100").x + scaled(6);
  const ImVec2 min(top.x + label_w, top.y + ImGui::GetTextLineHeightWithSpacing());
  const ImVec2 max(top.x + width - (v.has_dependence ? label_w : scaled(4)), top.y + height);
  const int n = int(fl.size());
  // The attempt under the mouse, said in the line above the plot.
  int hover = -1;
  if (n > 0 && ImGui::IsMouseHoveringRect(min, max)) {
    const float mx = ImGui::GetIO().MousePos.x;
    hover = std::clamp(int(std::lround((mx - min.x) / (max.x - min.x) * float(std::max(n - 1, 1)))),
                       0, n - 1);
  }
  char line[192];
  if (hover >= 0) {
    const ProgressFlight& f = fl[std::size_t(hover)];
    int k = std::snprintf(line, sizeof line, "attempt %d, %s, %s: skill %.1f", f.attempt,
                          kind_of(f), f.when.c_str(), f.skill);
    if (std::isfinite(f.dependence) && k > 0 && k < int(sizeof line))
      std::snprintf(line + k, sizeof line - std::size_t(k), ", D %.2f", f.dependence);
    ImGui::TextUnformatted(line);
  } else {
    // The legend while nothing is hovered.
    coloured(kAssisted, "\u25CF assisted");
    ImGui::SameLine();
    coloured(kProbe, "\u25C6 probe (unassisted)");
    if (v.has_dependence) {
      ImGui::SameLine();
      coloured(kDependence, "- - D, right axis");
    }
    ImGui::SameLine();
    ImGui::TextDisabled("(hover: one attempt)");
  }
  ImGui::SetCursorScreenPos(top);
  ImGui::Dummy(ImVec2(width, height));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  // No fill of its own: the window's background is the plot's (a software rasterizer pays for
  // every pixel blended twice).
  dl->AddRect(min, max, colour::kGrid);
  for (int g = 0; g <= 4; ++g) {  // skill 0, 25, ... 100
    const float y = max.y - float(g) / 4.0f * (max.y - min.y);
    dl->AddLine(ImVec2(min.x, y), ImVec2(max.x, y), colour::kGrid, 1.0f);
  }
  const float th = ImGui::GetTextLineHeight();
  dl->AddText(ImVec2(top.x, min.y - 0.5f * th), kMuted, "100");
  dl->AddText(ImVec2(top.x + ImGui::CalcTextSize("10").x, max.y - 0.5f * th), kMuted, "0");
  if (v.has_dependence) {
    dl->AddText(ImVec2(max.x + scaled(4), min.y - 0.5f * th), kDependence, "D 1");
    dl->AddText(ImVec2(max.x + scaled(4), max.y - 0.5f * th), kDependence, "D 0");
  }
  if (n == 0) {
    const char* none = "no flights of this scenario yet";
    const ImVec2 s = ImGui::CalcTextSize(none);
    dl->AddText(ImVec2(0.5f * (min.x + max.x - s.x), 0.5f * (min.y + max.y - s.y)), kMuted, none);
    return;
  }
  const auto x_of = [&](int i) {
    return n == 1 ? 0.5f * (min.x + max.x)
                  : min.x + float(i) / float(n - 1) * (max.x - min.x);
  };
  const auto y_of = [&](double skill) {
    return max.y - float(std::clamp(skill, 0.0, 100.0) / 100.0) * (max.y - min.y);
  };
  const float line_w = std::max(1.0f, std::round(scaled(2.0f)));
  const float r = scaled(3.5f);
  // D first, under the skills: dashed, in the planner's colour (told from the skills in
  // greyscale too).
  if (v.has_dependence) {
    std::vector<ImVec2> line;
    for (int i = 0; i < n; ++i) {
      const double d = fl[std::size_t(i)].dependence;
      if (!std::isfinite(d)) continue;
      line.emplace_back(x_of(i), y_of(100.0 * d));
    }
    stroke_dashed(dl, line, kDependence, line_w, scaled(6.0f), scaled(4.0f));
    for (const ImVec2& p : line) dl->AddCircleFilled(p, 0.6f * r, kDependence);
  }
  for (const bool probe : {false, true}) {
    const ImU32 c = probe ? kProbe : kAssisted;
    for (int i = 0; i < n; ++i) {
      const ProgressFlight& f = fl[std::size_t(i)];
      if (f.probe == probe && std::isfinite(f.skill))
        dl->PathLineTo(ImVec2(x_of(i), y_of(f.skill)));
    }
    dl->PathStroke(c, 0, line_w);
    for (int i = 0; i < n; ++i) {
      const ProgressFlight& f = fl[std::size_t(i)];
      if (f.probe != probe || !std::isfinite(f.skill)) continue;
      const ImVec2 p(x_of(i), y_of(f.skill));
      if (probe)  // a diamond: told apart from the dots in greyscale too
        dl->AddQuadFilled(ImVec2(p.x, p.y - 1.3f * r), ImVec2(p.x + 1.3f * r, p.y),
                          ImVec2(p.x, p.y + 1.3f * r), ImVec2(p.x - 1.3f * r, p.y), c);
      else
        dl->AddCircleFilled(p, r, c);
    }
  }
  if (v.best >= 0) {
    const ImVec2 p(x_of(v.best), y_of(fl[std::size_t(v.best)].skill));
    dl->AddCircle(p, 2.4f * r, colour::kText, 0, scaled(1.5f));
  }
  if (hover >= 0) {
    const float x = x_of(hover);
    dl->AddLine(ImVec2(x, min.y), ImVec2(x, max.y), colour::rgb(0xDD, 0xDD, 0xDD, 140), scaled(1.0f));
  }
}

// The flights, newest first; each with a recording can be replayed.
void flights_table(const ProgressView& v, float height, Requests& out) {
  constexpr ImGuiTableFlags kFlags = ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY |
                                     ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_BordersInnerV;
  if (!ImGui::BeginTable("##flights", 7, kFlags, ImVec2(0, height))) return;
  ImGui::TableSetupScrollFreeze(0, 1);
  ImGui::TableSetupColumn("#");
  ImGui::TableSetupColumn("when");
  ImGui::TableSetupColumn("kind");
  ImGui::TableSetupColumn("skill");
  ImGui::TableSetupColumn("D");
  ImGui::TableSetupColumn("ended");
  ImGui::TableSetupColumn("recording", ImGuiTableColumnFlags_WidthStretch);
  // The headers, each saying what its column means.
  static const char* const kColumnMeanings[] = {
      "The attempt: its place among the trainee's flights of this scenario",
      "When it was flown (local time)",
      "assisted: the planner shared the controls; probe: the pilot alone (SPEC §10)",
      "The score, 0-100: progress x quality / (1 + collisions)",
      "Assistance dependence: the share of the flight the planner flew (0-1)",
      "How the flight ended: completed, interrupted or lost",
      "Its recording, replayed by its button"};
  ImGui::TableNextRow(ImGuiTableRowFlags_Headers);
  for (int c = 0; c < 7; ++c) {
    ImGui::TableSetColumnIndex(c);
    ImGui::TableHeader(ImGui::TableGetColumnName(c));
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", kColumnMeanings[c]);
  }
  const int n = int(v.flights.size());
  ImGuiListClipper clip;
  clip.Begin(n);
  char text[32];
  while (clip.Step()) {
    for (int row = clip.DisplayStart; row < clip.DisplayEnd; ++row) {
      const int i = n - 1 - row;
      const ProgressFlight& f = v.flights[std::size_t(i)];
      ImGui::PushID(i);
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%d%s", f.attempt, i == v.best ? " best" : "");
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(f.when.c_str());
      ImGui::TableNextColumn();
      coloured(f.probe ? kProbe : kAssisted, kind_of(f));
      if (f.from_step >= 0) {  // a branch, marked as in `mixpilot history`
        ImGui::SameLine(0.0f, 0.0f);
        ImGui::TextUnformatted(" ^");
        if (ImGui::IsItemHovered())
          ImGui::SetTooltip("A branch: flown on from step %lld of another flight (fly from "
                            "here), scored from there on",
                            static_cast<long long>(f.from_step));
      }
      ImGui::TableNextColumn();
      ImGui::PushFont(mono_font());
      if (std::isfinite(f.skill)) std::snprintf(text, sizeof text, "%5.1f", f.skill);
      else std::snprintf(text, sizeof text, "    -");
      ImGui::TextUnformatted(text);
      ImGui::TableNextColumn();
      if (std::isfinite(f.dependence)) std::snprintf(text, sizeof text, "%4.2f", f.dependence);
      else std::snprintf(text, sizeof text, "   -");
      ImGui::TextUnformatted(text);
      ImGui::PopFont();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(f.ended.c_str());
      ImGui::TableNextColumn();
      if (f.recording.empty()) {
        ImGui::TextDisabled("not recorded");
      } else {
        if (ImGui::SmallButton("Replay")) out.push_back(ReplayRecording{f.recording});
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("replay %s", f.recording.c_str());
      }
      ImGui::PopID();
    }
  }
  ImGui::EndTable();
}

}  // namespace

void draw_progress_panel(const HistoryView& h, bool& open, ImVec2 display, Requests& out) {
  const float em = ImGui::GetFontSize();
  const float margin = em;
  const ImVec2 size(std::min(48.0f * em, display.x - 2 * margin),
                    std::min(34.0f * em, display.y - 2 * margin));
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(size, ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.98f);  // the plots behind would show through its text
  if (!ImGui::Begin("Progress (H)", &open,
                    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse |
                        ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize)) {
    ImGui::End();
    return;
  }
  const ProgressView& v = h.progress;
  ImGui::PushTextWrapPos(0.0f);
  if (!h.loaded) {
    ImGui::TextDisabled("reading the history...");
  } else if (!v.error.empty()) {
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "%s", v.error.c_str());
  } else {
    ImGui::Text("%s on %s: %d flight%s, %d assisted, %d probe%s (unassisted)", v.trainee.c_str(),
                v.scenario.c_str(), int(v.flights.size()), v.flights.size() == 1 ? "" : "s",
                v.assisted, v.probes, v.probes == 1 ? "" : "s");
    tooltip("A probe flight pins the pilot's authority to 1: its skill is the pilot's own. "
            "An assisted flight shares control with the planner.");
    if (v.best >= 0) {
      const ProgressFlight& b = v.flights[std::size_t(v.best)];
      ImGui::Text("Best run: skill %.1f, attempt %d (%s), %s", b.skill, b.attempt, kind_of(b),
                  b.when.c_str());
      tooltip("The highest skill of these flights (ringed in the plot). Skill: progress x "
              "quality / (1 + collisions), 0-100.");
      if (!b.recording.empty()) {
        ImGui::SameLine();
        if (ImGui::SmallButton("Replay best")) out.push_back(ReplayRecording{b.recording});
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("replay %s", b.recording.c_str());
        tooltip("Opens its recording in the replay, as File > Open does");
      }
    }
    ImGui::TextUnformatted("Trend:");
    ImGui::SameLine();
    coloured(kAssisted, v.assisted_trend.words.c_str());
    tooltip("A least-squares line through the skills of the last attempts: its slope per attempt");
    if (v.probes > 0) {
      ImGui::TextUnformatted("Trend:");
      ImGui::SameLine();
      coloured(kProbe, v.probe_trend.words.c_str());
    }
    if (v.has_dependence)
      ImGui::TextDisabled("D: the share of a flight the planner flew (0 none, 1 all of it)");
  }
  ImGui::PopTextWrapPos();
  ImGui::Spacing();
  const float avail = ImGui::GetContentRegionAvail().y;
  const float plot_h = std::max(6.0f * em, 0.5f * avail);
  skill_plot(v, plot_h);
  ImGui::Spacing();
  ImGui::TextUnformatted("Flights, newest first");
  flights_table(v, std::max(4.0f * em, ImGui::GetContentRegionAvail().y), out);
  ImGui::End();
}

}  // namespace mixpilot::ui
