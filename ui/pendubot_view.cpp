#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {
namespace {

// Joint angles q1 (from the upward vertical) and q1 + q2 (SPEC §3.1) → elbow and tip in
// pixels (y grows downwards on screen).
void links(ImVec2 base, float scale, const Scene& sc, double q1, double q2, ImVec2& elbow,
           ImVec2& tip) {
  elbow = ImVec2(base.x + scale * float(sc.link1 * std::sin(q1)),
                 base.y - scale * float(sc.link1 * std::cos(q1)));
  tip = ImVec2(elbow.x + scale * float(sc.link2 * std::sin(q1 + q2)),
               elbow.y - scale * float(sc.link2 * std::cos(q1 + q2)));
}

}  // namespace

void draw_pendubot(const Scene& sc, const History& h, ImVec2 min, ImVec2 max, ImVec2 frame) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(min, max, true);
  dl->AddRectFilled(min, max, colour::kBackground);
  if (h.empty() || h.newest().x.size() < 4) {
    dl->PopClipRect();
    return;
  }
  const Telemetry& s = h.newest();
  const ImVec2 base(0.5f * (frame.x + max.x), 0.5f * (frame.y + max.y));
  const float scale = 0.42f * std::min(max.x - frame.x, max.y - frame.y) / float(sc.link1 + sc.link2);
  dl->AddCircle(base, scale * float(sc.link1 + sc.link2), colour::kGrid, 64, scaled(1.0f));
  ImVec2 e, t;
  const float upper = scaled(10.0f), lower = scaled(8.0f);  // the links' widths
  if (s.reference.size() >= 2) {  // the reference pose as a ghost
    links(base, scale, sc, s.reference(0), s.reference(1), e, t);
    dl->AddLine(base, e, colour::rgb(0xEE, 0xEE, 0xEE, 70), upper);
    dl->AddLine(e, t, colour::rgb(0xEE, 0xEE, 0xEE, 70), lower);
  }
  links(base, scale, sc, s.x(0), s.x(1), e, t);
  const bool lqr = channel_value(s, "LQR active", 0.0) > 0.5;
  const ImU32 c = lqr ? colour::kPlanner : colour::kMpc;
  dl->AddLine(base, e, c, upper);
  dl->AddLine(e, t, c, lower);
  dl->AddCircleFilled(base, scaled(7.0f), colour::kText, 16);
  dl->AddCircleFilled(e, scaled(6.0f), colour::kText, 16);
  // Torque: an arc at the shoulder, its length ∝ u / u_max.
  const double u = s.u.size() > 0 ? s.u(0) : 0.0;
  const double umax = std::max(1e-9, channel_value(s, "torque bound", 1.0));
  const float r = scaled(28.0f);
  const float a0 = -0.5f * float(M_PI);
  dl->PathArcTo(base, r, a0, a0 - float(std::clamp(u / umax, -1.0, 1.0) * M_PI), 24);
  dl->PathStroke(colour::kCaution, 0, scaled(3.0f));
  // The numbers at the bottom left, as many to a line as the view's width holds.
  char parts[4][96];
  std::snprintf(parts[0], sizeof parts[0], "controller: %s", lqr ? "LQR" : "NMPC");
  std::snprintf(parts[1], sizeof parts[1], "torque %.3f N m (bound %.3f)", u, umax);
  std::snprintf(parts[2], sizeof parts[2], "dq1 %.2f (bound %.2f) rad/s", s.x(2),
                channel_value(s, "dq1 bound", 0.0));
  std::snprintf(parts[3], sizeof parts[3], "dq2 %.2f (bound %.2f) rad/s", s.x(3),
                channel_value(s, "dq2 bound", 0.0));
  const float inset = ImGui::GetStyle().WindowPadding.x, gap = ImGui::CalcTextSize("    ").x;
  const float width = max.x - frame.x - 2 * inset;
  std::string lines[4];
  int n = 0;
  for (const char* part : parts) {
    const std::string joined = n > 0 ? lines[n - 1] + "    " + part : std::string();
    if (n > 0 && ImGui::CalcTextSize(lines[n - 1].c_str()).x + gap + ImGui::CalcTextSize(part).x <= width)
      lines[n - 1] = joined;
    else
      lines[n++] = part;
  }
  // A part wider than the view (a narrow view, large text) wraps at its words.
  const float spacing = ImGui::GetStyle().ItemSpacing.y;
  float y = max.y - inset;
  for (int i = n - 1; i >= 0; --i) {
    y -= ImGui::CalcTextSize(lines[i].c_str(), nullptr, false, width).y + spacing;
    dl->AddText(ImGui::GetFont(), ImGui::GetFontSize(), ImVec2(frame.x + inset, y), colour::kText,
                lines[i].c_str(), nullptr, width);
  }
  dl->PopClipRect();
}

}  // namespace mixpilot::ui
