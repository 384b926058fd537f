// A replay's transport bar (UI.md §1, §6): the timeline with its event ticks and the playhead,
// play / pause, previous / next event, fly from here (SPEC §10), the speeds 0.25×–8× and the
// "λ below" threshold.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

const char* to_string(EventKind k) {
  switch (k) {
    case EventKind::collision: return "collision";
    case EventKind::fallback: return "fallback";
    case EventKind::low_lambda: return "λ below threshold";
    case EventKind::lost: return "lost";
    case EventKind::input_lost: return "input lost";
  }
  return "?";
}

std::vector<TimelineEvent> timeline_events(const History& h, double lambda_threshold) {
  std::vector<TimelineEvent> out;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const Telemetry& s = h[i];
    if (s.events & kEventCollision) out.push_back({s.t, EventKind::collision});
    if (s.events & (kEventFallback | kEventOverrun)) out.push_back({s.t, EventKind::fallback});
    if (s.events & kEventLost) out.push_back({s.t, EventKind::lost});
    if (s.events & kEventInputLost) out.push_back({s.t, EventKind::input_lost});
    if (s.mode == ModeKind::mixed_initiative && s.lambda < lambda_threshold &&
        (i == 0 || h[i - 1].lambda >= lambda_threshold))
      out.push_back({s.t, EventKind::low_lambda});
  }
  return out;
}

double event_after(const std::vector<TimelineEvent>& events, double t, int direction) {
  // Half a millisecond of slack: the playhead sits on an event's time after a jump to it.
  constexpr double kSlack = 5e-4;
  if (direction > 0) {
    for (const TimelineEvent& e : events)
      if (e.t > t + kSlack) return e.t;
  } else {
    for (auto it = events.rbegin(); it != events.rend(); ++it)
      if (it->t < t - kSlack) return it->t;
  }
  return -1.0;
}

namespace {

ImU32 event_colour(EventKind k) {
  switch (k) {
    case EventKind::collision: return colour::kCritical;
    case EventKind::fallback: return colour::kCaution;
    case EventKind::low_lambda: return colour::kPlanner;
    case EventKind::lost: return colour::kCritical;
    case EventKind::input_lost: return colour::kPilot;
  }
  return colour::kText;
}

// A tick's shape tells its kind without colour: collision ▲, fallback ■, λ below ▼, lost ✕,
// input lost ○.
void tick(ImDrawList* dl, float x, float top, float bottom, EventKind k) {
  const ImU32 c = event_colour(k);
  const float s = scaled(5.0f);
  dl->AddLine(ImVec2(x, top), ImVec2(x, bottom), c, scaled(1.5f));
  switch (k) {
    case EventKind::collision:
      dl->AddTriangleFilled(ImVec2(x, top - s), ImVec2(x - s, top + s), ImVec2(x + s, top + s), c);
      break;
    case EventKind::fallback:
      dl->AddRectFilled(ImVec2(x - 0.8f * s, top - 0.8f * s), ImVec2(x + 0.8f * s, top + 0.8f * s), c);
      break;
    case EventKind::low_lambda:
      dl->AddTriangleFilled(ImVec2(x - s, top - s), ImVec2(x + s, top - s), ImVec2(x, top + s), c);
      break;
    case EventKind::lost:
      dl->AddLine(ImVec2(x - s, top - s), ImVec2(x + s, top + s), c, scaled(2.0f));
      dl->AddLine(ImVec2(x - s, top + s), ImVec2(x + s, top - s), c, scaled(2.0f));
      break;
    case EventKind::input_lost:
      dl->AddCircle(ImVec2(x, top), s, c, 12, scaled(2.0f));
      break;
  }
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
  for (const TimelineEvent& e : r.events)
    tick(dl, x_of(e.t), min.y + scaled(6), max.y - scaled(2), e.kind);
  dl->AddCircleFilled(ImVec2(x_of(r.t), ty), scaled(7.0f), colour::kText, 16);

  // The controls, wrapping onto more rows where the bar is narrow.
  if (ImGui::Button(r.playing ? "Pause (Space)" : "Play (Space)")) out.push_back(TogglePlay{});
  same_line_or_wrap(button_width("< previous event ["));
  if (ImGui::Button("< previous event [")) out.push_back(JumpToEvent{-1});
  same_line_or_wrap(button_width("] next event >"));
  if (ImGui::Button("] next event >")) out.push_back(JumpToEvent{+1});
  same_line_or_wrap(button_width("Export clip (E)"));
  if (ImGui::Button("Export clip (E)")) out.push_back(clip_around(r.t, r.duration));
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Saves %g s either side of the playhead as a video beside the recording",
                      kClipHalfWidth);
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
  }
  const float slider_w = 7.5f * ImGui::GetFontSize();
  same_line_or_wrap(slider_w);
  ImGui::SetNextItemWidth(slider_w);
  float threshold = float(r.lambda_threshold);
  if (ImGui::SliderFloat("##lambda", &threshold, 0.05f, 0.95f, "λ below %.2f"))
    out.push_back(SetLambdaThreshold{threshold});
  // The legend: each tick's shape and colour.
  const float lh = ImGui::GetTextLineHeight();
  const float mark = scaled(14.0f);
  for (EventKind k : {EventKind::collision, EventKind::fallback, EventKind::low_lambda,
                      EventKind::lost, EventKind::input_lost}) {
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
