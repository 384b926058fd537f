// A replay's transport bar (UI.md §1, §6): the timeline with the debrief's event ticks (SPEC
// §10; the selected event's span under its tick) and the playhead,
// play / pause, previous / next event, fly from here (SPEC §10), the speeds 0.25×–8× and the
// "λ below" threshold.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

std::vector<DebriefRow> debrief_rows(const std::vector<DebriefEvent>& events, double ball_radius) {
  std::vector<DebriefRow> rows;
  rows.reserve(events.size());
  for (const DebriefEvent& e : events)
    rows.push_back({e.start, e.end, e.kind, describe(e, ball_radius), e});
  // The builder lists them as they closed; a list reads by start (ties: as they closed).
  std::stable_sort(rows.begin(), rows.end(),
                   [](const DebriefRow& a, const DebriefRow& b) { return a.t < b.t; });
  return rows;
}

int event_after(const std::vector<DebriefRow>& events, double t, int direction) {
  // Half a millisecond of slack: the playhead sits on an event's time after a jump to it.
  constexpr double kSlack = 5e-4;
  if (direction > 0) {
    for (std::size_t i = 0; i < events.size(); ++i)
      if (events[i].t > t + kSlack) return int(i);
  } else {
    for (std::size_t i = events.size(); i-- > 0;)
      if (events[i].t < t - kSlack) return int(i);
  }
  return -1;
}

ExportClip clip_of(const ReplayInfo& r) {
  if (r.selected < 0 || std::size_t(r.selected) >= r.events.size()) return clip_around(r.t, r.duration);
  const DebriefRow& e = r.events[std::size_t(r.selected)];
  return ExportClip{std::max(0.0, e.t - kClipHalfWidth), std::min(r.duration, e.end + kClipHalfWidth)};
}

// Colour says how serious an event was (its log level: warning, error, note), in colours
// told apart in greyscale and by the colour blind (colour::kMustTellApart); the mark's shape
// says which kind it was.
ImU32 event_colour(DebriefKind k) {
  switch (log_level(k)) {
    case LogLevel::warn: return colour::kCaution;
    case LogLevel::error:
    case LogLevel::fatal: return colour::kCritical;
    case LogLevel::debug:
    case LogLevel::info: return colour::kNote;
  }
  return colour::kNote;
}

// A mark's shape tells its kind without colour: takeover ▼, near miss ◆, collision ▲,
// fallback ■, input lost ○, vehicle lost ✕, safe hold ●, marker ⚑, instructor ◇.
void draw_event_mark(ImDrawList* dl, ImVec2 c, float s, DebriefKind k) {
  const ImU32 col = event_colour(k);
  const float x = c.x, y = c.y;
  switch (k) {
    case DebriefKind::takeover:
      dl->AddTriangleFilled(ImVec2(x - s, y - s), ImVec2(x + s, y - s), ImVec2(x, y + s), col);
      break;
    case DebriefKind::near_miss:
      dl->AddQuadFilled(ImVec2(x, y - s), ImVec2(x + s, y), ImVec2(x, y + s), ImVec2(x - s, y), col);
      break;
    case DebriefKind::collision:
      dl->AddTriangleFilled(ImVec2(x, y - s), ImVec2(x - s, y + s), ImVec2(x + s, y + s), col);
      break;
    case DebriefKind::fallback:
      dl->AddRectFilled(ImVec2(x - 0.8f * s, y - 0.8f * s), ImVec2(x + 0.8f * s, y + 0.8f * s), col);
      break;
    case DebriefKind::input_lost: dl->AddCircle(c, s, col, 12, scaled(2.0f)); break;
    case DebriefKind::lost:
      dl->AddLine(ImVec2(x - s, y - s), ImVec2(x + s, y + s), col, scaled(2.0f));
      dl->AddLine(ImVec2(x - s, y + s), ImVec2(x + s, y - s), col, scaled(2.0f));
      break;
    case DebriefKind::safe_hold: dl->AddCircleFilled(c, s, col, 12); break;
    case DebriefKind::marker:
      dl->AddLine(ImVec2(x - 0.6f * s, y - s), ImVec2(x - 0.6f * s, y + s), col, scaled(1.5f));
      dl->AddTriangleFilled(ImVec2(x - 0.6f * s, y - s), ImVec2(x + s, y - 0.5f * s),
                            ImVec2(x - 0.6f * s, y), col);
      break;
    case DebriefKind::instructor:
      dl->AddQuad(ImVec2(x, y - s), ImVec2(x + s, y), ImVec2(x, y + s), ImVec2(x - s, y), col,
                  scaled(1.5f));
      break;
  }
}

namespace {

// A tick on the timeline: a line down from the mark.
void tick(ImDrawList* dl, float x, float top, float bottom, DebriefKind k) {
  dl->AddLine(ImVec2(x, top), ImVec2(x, bottom), event_colour(k), scaled(1.5f));
  draw_event_mark(dl, ImVec2(x, top), scaled(5.0f), k);
}

}  // namespace

void draw_transport(const RunInfo& run, Requests& out) {
  const ReplayInfo& r = *run.replay;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float w = ImGui::GetContentRegionAvail().x;
  const ImVec2 min = ImGui::GetCursorScreenPos();
  const float height = 1.75f * ImGui::GetFontSize();
  const ImVec2 max(min.x + w, min.y + height);
  // The scrubber: click or drag anywhere on it to move the playhead (within what is loaded).
  ImGui::InvisibleButton("##timeline", ImVec2(w, height));
  const double span = std::max(r.duration, 1e-9);
  const auto x_of = [&](double t) { return float(min.x + std::clamp(t / span, 0.0, 1.0) * w); };
  const auto t_at_mouse = [&] {
    return double(std::clamp((ImGui::GetIO().MousePos.x - min.x) / w, 0.0f, 1.0f)) * span;
  };
  if (ImGui::IsItemActive()) out.push_back(Seek{std::min(t_at_mouse(), r.loaded * span)});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%.2f s", t_at_mouse());
  const float ty = min.y + 0.5f * height, th = scaled(3.0f);
  dl->AddRectFilled(ImVec2(min.x, ty - th), ImVec2(max.x, ty + th), colour::rgb(0x30, 0x34, 0x3A), th);
  dl->AddRectFilled(ImVec2(min.x, ty - th), ImVec2(x_of(r.loaded * span), ty + th),
                    colour::rgb(0x50, 0x56, 0x60), th);
  dl->AddRectFilled(ImVec2(min.x, ty - th), ImVec2(x_of(r.t), ty + th), colour::kPilot, th);
  // The selected event's span along the track, then every event's tick.
  if (r.selected >= 0 && std::size_t(r.selected) < r.events.size()) {
    const DebriefRow& e = r.events[std::size_t(r.selected)];
    const ImU32 c = event_colour(e.kind);
    dl->AddRectFilled(ImVec2(x_of(e.t) - scaled(2), ty - 2.5f * th),
                      ImVec2(std::max(x_of(e.end), x_of(e.t)) + scaled(2), ty + 2.5f * th),
                      (c & 0x00FFFFFFu) | 0xA0000000u, th);
  }
  for (const DebriefRow& e : r.events)
    tick(dl, x_of(e.t), min.y + scaled(6), max.y - scaled(2), e.kind);
  dl->AddCircleFilled(ImVec2(x_of(r.t), ty), scaled(7.0f), colour::kText, 16);

  // The controls, wrapping onto more rows where the bar is narrow.
  const auto tip = [](const char* text) {
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", text);
  };
  if (ImGui::Button(r.playing ? "Pause (Space)" : "Play (Space)")) out.push_back(TogglePlay{});
  tip(r.playing ? "Stop the playhead" : "Play the recording from the playhead");
  same_line_or_wrap(button_width("< previous event ["));
  if (ImGui::Button("< previous event [")) out.push_back(JumpToEvent{-1});
  tip("Select the debrief's event before the playhead and go to its start");
  same_line_or_wrap(button_width("] next event >"));
  if (ImGui::Button("] next event >")) out.push_back(JumpToEvent{+1});
  tip("Select the debrief's event after the playhead and go to its start");
  // "Export clip" saves the selected event with kClipHalfWidth either side, or the playhead's.
  const bool event_clip = r.selected >= 0 && std::size_t(r.selected) < r.events.size();
  const char* clip_label = event_clip ? "Export event clip (E)" : "Export clip (E)";
  same_line_or_wrap(button_width(clip_label));
  if (ImGui::Button(clip_label)) out.push_back(clip_of(r));
  if (ImGui::IsItemHovered()) {
    if (event_clip)
      ImGui::SetTooltip("Saves the selected event with %g s either side as a video beside the "
                        "recording", kClipHalfWidth);
    else
      ImGui::SetTooltip("Saves %g s either side of the playhead as a video beside the recording",
                        kClipHalfWidth);
  }
  // Fly from here (SPEC §10): a new flight from the playhead's moment, READY there.
  if (r.can_fly_from_here) {
    same_line_or_wrap(button_width("Fly from here (T)"));
    ImGui::BeginDisabled(r.taking_over >= 0.0);
    if (ImGui::Button("Fly from here (T)")) out.push_back(FlyFromHere{});
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("Take the controls at this moment: a new flight from here, with the pilot\n"
                        "you pick, recorded as a branch of this one and scored from here on");
  }
  ImGui::PushFont(mono_font());
  char time[48];
  std::snprintf(time, sizeof time, "%7.2f / %.2f s", r.t, r.duration);
  same_line_or_wrap(ImGui::CalcTextSize(time).x);
  ImGui::TextUnformatted(time);
  ImGui::PopFont();
  for (double sp : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0}) {
    char label[16];
    std::snprintf(label, sizeof label, "%gx", sp);
    same_line_or_wrap(radio_width(label));
    if (ImGui::RadioButton(label, run.speed == sp)) out.push_back(SetPlaySpeed{sp});
    tip("Replay speed (Up / Down)");
  }
  const float slider_w = 7.5f * ImGui::GetFontSize();
  same_line_or_wrap(slider_w);
  ImGui::SetNextItemWidth(slider_w);
  float threshold = float(r.lambda_threshold);
  if (ImGui::SliderFloat("##lambda", &threshold, 0.05f, 0.95f, "λ below %.2f"))
    out.push_back(SetLambdaThreshold{threshold});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("A takeover: the pilot's authority λ below this (the planner flies more)");
  // The legend: each tick's shape and colour, of the kinds this flight's events have.
  const float lh = ImGui::GetTextLineHeight();
  const float mark = scaled(14.0f);
  bool present[kDebriefKindCount] = {};
  for (const DebriefRow& e : r.events) present[int(e.kind)] = true;
  for (int i = 0; i < kDebriefKindCount; ++i) {
    if (!present[i]) continue;
    const auto k = DebriefKind(i);
    same_line_or_wrap(mark + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize(to_string(k)).x);
    ImGui::AlignTextToFramePadding();
    const ImVec2 p = ImGui::GetCursorScreenPos();
    const float y = p.y + ImGui::GetStyle().FramePadding.y;
    tick(dl, p.x + 0.5f * mark, y + 0.5f * lh, y + lh, k);
    ImGui::Dummy(ImVec2(mark, lh));
    ImGui::SameLine(0, ImGui::GetStyle().ItemInnerSpacing.x);
    ImGui::TextUnformatted(to_string(k));
  }
  if (r.loaded < 1.0)
    ImGui::TextDisabled("flying the recording again to show it: %.0f %%", 100.0 * r.loaded);
  if (r.taking_over >= 0.0)
    ImGui::TextDisabled("flying the recording to %.2f s to fly on from there: %.0f %%", r.t,
                        100.0 * r.taking_over);
}

}  // namespace mixpilot::ui
