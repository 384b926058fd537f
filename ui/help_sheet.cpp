// The shortcut sheet (F1 or ?, UI.md §10): every line of the key table (ui/shortcuts.hpp), how
// the keyboard reaches the panels, the text size, and the welcome again.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ui/first_launch.hpp"
#include "ui/panels.hpp"
#include "ui/shortcuts.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

namespace {

void tip(const char* text) {
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", text);
}

}  // namespace

void draw_help_sheet(const RunInfo& run, UiState& ui, Requests& out, ImVec2 d) {
  const float em = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(0.5f * d.x, 0.5f * d.y), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(44.0f * em, d.x - 2.0f * em), 0.0f), ImGuiCond_Always);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(d.x - 2.0f * em, d.y - 2.0f * em));
  ImGui::Begin(kHelpWindow, &ui.show_help,
               ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize);
  float key_w = 0.0f;
  ImGui::PushFont(mono_font());
  for (const Shortcut& s : shortcuts())
    if (s.keys) key_w = std::max(key_w, ImGui::CalcTextSize(s.keys).x);
  ImGui::PopFont();
  if (ImGui::BeginTable("##keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    ImGui::TableSetupColumn("key", ImGuiTableColumnFlags_WidthFixed, key_w);
    ImGui::TableSetupColumn("what", ImGuiTableColumnFlags_WidthStretch);
    for (const Shortcut& s : shortcuts()) {
      if (!s.keys) continue;  // the line above names it
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::PushFont(mono_font());
      ImGui::TextUnformatted(s.keys);
      ImGui::PopFont();
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", s.what);
    }
    ImGui::EndTable();
  }
  ImGui::Separator();
  // The text size: a factor on the display's scale, kept for the next start.
  ImGui::AlignTextToFramePadding();
  ImGui::Text("Text size %.0f %%", 100.0 * double(run.text_scale));
  ImGui::SameLine();
  // Built in place: GCC 12 sees maybe-uninitialized members in a moved nested variant.
  if (ImGui::Button(" - "))
    out.emplace_back(std::in_place_type<AppRequest>, SetTextScale{next_text_scale(run.text_scale, -1)});
  tip("Smaller text and controls (Ctrl+-)");
  ImGui::SameLine();
  if (ImGui::Button(" + "))
    out.emplace_back(std::in_place_type<AppRequest>, SetTextScale{next_text_scale(run.text_scale, +1)});
  tip("Larger text and controls (Ctrl+=)");
  same_line_or_wrap(button_width("As the display's"));
  if (ImGui::Button("As the display's"))
    out.emplace_back(std::in_place_type<AppRequest>, SetTextScale{1.0f});
  tip("The text size the display's scale gives (Ctrl+0)");
  if (ImGui::Button("Show the welcome again")) show_welcome(ui);
  tip("The first launch's three ways in and its tour of the screen");
  ImGui::End();
}

}  // namespace mixpilot::ui
