// A replay's Debrief panel (SPEC §10 "Debrief events"): what happened in the flight, one row per
// event with its mark (the timeline's), its time and its words. A click, or [ and ] from the
// keyboard, selects an event and puts the playhead at its start; the selected row is highlighted
// and "Export clip" saves it.
#include <algorithm>
#include <cstdio>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

void draw_debrief_panel(const RunInfo& run, UiState& ui, float max_height, Requests& out) {
  const ReplayInfo& r = *run.replay;
  const ImGuiStyle& st = ImGui::GetStyle();
  if (!r.events_ready) {
    ImGui::TextDisabled("listed once the replay has loaded");
    return;
  }
  if (r.events.empty()) {
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextDisabled("nothing to debrief: no takeover, near miss, collision or input loss");
    ImGui::PopTextWrapPos();
    return;
  }
  char head[64];
  std::snprintf(head, sizeof head, "%zu event%s   [ ] step, click jumps", r.events.size(),
                r.events.size() == 1 ? "" : "s");
  ImGui::TextDisabled("%s", head);

  // Each row: the mark, the start time (mono), then the words wrapping in their own column.
  ImFont* mono = mono_font();
  const float em = ImGui::GetFontSize();
  const float mark_w = 1.2f * em;
  char time[24];
  std::snprintf(time, sizeof time, "%6.1f s", r.duration);
  const float time_w = mono->CalcTextSizeA(em, FLT_MAX, 0.0f, time).x + st.ItemInnerSpacing.x;
  const float width = ImGui::GetContentRegionAvail().x - st.ScrollbarSize;
  const float words_w = std::max(4.0f * em, width - mark_w - time_w);
  const auto row_height = [&](const DebriefRow& e) {
    return ImGui::GetFont()->CalcTextSizeA(em, FLT_MAX, words_w, e.text.c_str()).y;
  };
  float content = 0.0f;
  for (const DebriefRow& e : r.events) content += row_height(e) + st.ItemSpacing.y;
  const float room = std::max(ImGui::GetFrameHeight(), max_height - ImGui::GetCursorPosY() -
                                                           st.WindowPadding.y);
  const bool scroll_to = r.selected != ui.debrief_shown_selected;
  // A list taller than the room scrolls, its scrollbar there from the first frame (ImGui would
  // add it a frame later, after measuring what the list holds).
  ImGui::BeginChild("##events", ImVec2(0.0f, std::min(content, room)), false,
                    content > room ? ImGuiWindowFlags_AlwaysVerticalScrollbar : 0);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float row_w = ImGui::GetContentRegionAvail().x;
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    const DebriefRow& e = r.events[i];
    const bool selected = int(i) == r.selected;
    const ImVec2 p = ImGui::GetCursorScreenPos();
    const float h = row_height(e);
    ImGui::PushID(int(i));
    if (ImGui::Selectable("##event", selected, ImGuiSelectableFlags_None, ImVec2(row_w, h)))
      // Made in place: converting it into a Request trips a false GCC 12 -Wmaybe-uninitialized.
      out.emplace_back(std::in_place_type<ReplayRequest>, SelectEvent{int(i)});
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("%.2f to %.2f s: click to jump there", e.t, e.end);
    ImGui::PopID();
    if (selected && scroll_to) ImGui::SetScrollHereY(0.5f);
    const float line = ImGui::GetTextLineHeight();
    if (selected)  // a bar in the event's colour along the selected row
      dl->AddRectFilled(ImVec2(p.x, p.y), ImVec2(p.x + scaled(3.0f), p.y + h), event_colour(e.kind));
    draw_event_mark(dl, ImVec2(p.x + 0.5f * mark_w + scaled(1.5f), p.y + 0.5f * line),
                    0.3f * em, e.kind);
    std::snprintf(time, sizeof time, "%.1f s", e.t);
    const float tw = mono->CalcTextSizeA(em, FLT_MAX, 0.0f, time).x;
    dl->AddText(mono, em, ImVec2(p.x + mark_w + time_w - st.ItemInnerSpacing.x - tw, p.y),
                colour::kText, time);
    dl->AddText(ImGui::GetFont(), em, ImVec2(p.x + mark_w + time_w, p.y), colour::kText,
                e.text.c_str(), nullptr, words_w);
  }
  ImGui::EndChild();
  if (scroll_to) ui.debrief_shown_selected = r.selected;
}

}  // namespace mixpilot::ui
