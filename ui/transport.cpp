// A replay's transport bar (UI.md §1, §6): the timeline with its event ticks and the playhead,
// play / pause, previous / next event, the speeds 0.25×–8× and the "λ below" threshold.
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
  const float s = 5.0f;
  dl->AddLine(ImVec2(x, top), ImVec2(x, bottom), c, 1.5f);
  switch (k) {
    case EventKind::collision:
      dl->AddTriangleFilled(ImVec2(x, top - s), ImVec2(x - s, top + s), ImVec2(x + s, top + s), c);
      break;
    case EventKind::fallback:
      dl->AddRectFilled(ImVec2(x - s + 1, top - s + 1), ImVec2(x + s - 1, top + s - 1), c);
      break;
    case EventKind::low_lambda:
      dl->AddTriangleFilled(ImVec2(x - s, top - s), ImVec2(x + s, top - s), ImVec2(x, top + s), c);
      break;
    case EventKind::lost:
      dl->AddLine(ImVec2(x - s, top - s), ImVec2(x + s, top + s), c, 2.0f);
      dl->AddLine(ImVec2(x - s, top + s), ImVec2(x + s, top - s), c, 2.0f);
      break;
    case EventKind::input_lost:
      dl->AddCircle(ImVec2(x, top), s, c, 12, 2.0f);
      break;
  }
}

}  // namespace

void draw_transport(const RunInfo& run, UiRequest& req) {
  const ReplayInfo& r = *run.replay;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float w = ImGui::GetContentRegionAvail().x;
  const ImVec2 min = ImGui::GetCursorScreenPos();
  const float height = 26.0f;
  const ImVec2 max(min.x + w, min.y + height);
  // The scrubber: click or drag anywhere on it to move the playhead (within what is loaded).
  ImGui::InvisibleButton("##timeline", ImVec2(w, height));
  const double span = std::max(r.duration, 1e-9);
  const auto x_of = [&](double t) { return float(min.x + std::clamp(t / span, 0.0, 1.0) * w); };
  const auto t_at_mouse = [&] {
    return double(std::clamp((ImGui::GetIO().MousePos.x - min.x) / w, 0.0f, 1.0f)) * span;
  };
  if (ImGui::IsItemActive()) req.seek = std::min(t_at_mouse(), r.loaded * span);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%.2f s", t_at_mouse());
  const float ty = min.y + 0.5f * height;
  dl->AddRectFilled(ImVec2(min.x, ty - 3), ImVec2(max.x, ty + 3), colour::rgb(0x30, 0x34, 0x3A), 3.0f);
  dl->AddRectFilled(ImVec2(min.x, ty - 3), ImVec2(x_of(r.loaded * span), ty + 3),
                    colour::rgb(0x50, 0x56, 0x60), 3.0f);
  dl->AddRectFilled(ImVec2(min.x, ty - 3), ImVec2(x_of(r.t), ty + 3), colour::kPilot, 3.0f);
  for (const TimelineEvent& e : r.events) tick(dl, x_of(e.t), min.y + 6, max.y - 2, e.kind);
  dl->AddCircleFilled(ImVec2(x_of(r.t), ty), 7.0f, colour::kText, 16);

  if (ImGui::Button(r.playing ? "Pause (Space)" : "Play (Space)")) req.toggle_pause = true;
  ImGui::SameLine();
  if (ImGui::Button("< previous event [")) req.jump = -1;
  ImGui::SameLine();
  if (ImGui::Button("] next event >")) req.jump = +1;
  ImGui::SameLine();
  ImGui::PushFont(mono_font());
  ImGui::Text("%7.2f / %.2f s", r.t, r.duration);
  ImGui::PopFont();
  for (double sp : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0}) {
    char label[16];
    std::snprintf(label, sizeof label, "%gx", sp);
    ImGui::SameLine();
    if (ImGui::RadioButton(label, run.speed == sp)) req.speed = sp;
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(110);
  float threshold = float(r.lambda_threshold);
  if (ImGui::SliderFloat("##lambda", &threshold, 0.05f, 0.95f, "λ below %.2f"))
    req.lambda_threshold = threshold;
  // The legend: each tick's shape and colour.
  ImGui::SameLine();
  for (EventKind k : {EventKind::collision, EventKind::fallback, EventKind::low_lambda,
                      EventKind::lost, EventKind::input_lost}) {
    const ImVec2 p = ImGui::GetCursorScreenPos();
    const float lh = ImGui::GetTextLineHeight();
    tick(dl, p.x + 6, p.y + 0.5f * lh, p.y + lh, k);
    ImGui::Dummy(ImVec2(14, lh));
    ImGui::SameLine();
    ImGui::TextUnformatted(to_string(k));
    ImGui::SameLine();
  }
  ImGui::NewLine();
  if (r.loaded < 1.0)
    ImGui::TextDisabled("flying the recording again to show it: %.0f %%", 100.0 * r.loaded);
}

}  // namespace mixpilot::ui
