#include <algorithm>
#include <cmath>
#include <cstdio>

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

void draw_pendubot(const Scene& sc, const History& h, ImVec2 min, ImVec2 max) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(min, max, true);
  dl->AddRectFilled(min, max, colour::kBackground);
  if (h.empty() || h.newest().x.size() < 4) {
    dl->PopClipRect();
    return;
  }
  const Telemetry& s = h.newest();
  const ImVec2 base(0.5f * (min.x + max.x), 0.5f * (min.y + max.y));
  const float scale = 0.42f * std::min(max.x - min.x, max.y - min.y) / float(sc.link1 + sc.link2);
  dl->AddCircle(base, scale * float(sc.link1 + sc.link2), colour::kGrid, 64, 1.0f);
  ImVec2 e, t;
  if (s.reference.size() >= 2) {  // the reference pose as a ghost
    links(base, scale, sc, s.reference(0), s.reference(1), e, t);
    dl->AddLine(base, e, colour::rgb(0xEE, 0xEE, 0xEE, 70), 10.0f);
    dl->AddLine(e, t, colour::rgb(0xEE, 0xEE, 0xEE, 70), 8.0f);
  }
  links(base, scale, sc, s.x(0), s.x(1), e, t);
  const bool lqr = channel_value(s, "LQR active", 0.0) > 0.5;
  const ImU32 c = lqr ? colour::kPlanner : colour::kMpc;
  dl->AddLine(base, e, c, 10.0f);
  dl->AddLine(e, t, c, 8.0f);
  dl->AddCircleFilled(base, 7.0f, colour::kText, 16);
  dl->AddCircleFilled(e, 6.0f, colour::kText, 16);
  // Torque: an arc at the shoulder, its length ∝ u / u_max.
  const double u = s.u.size() > 0 ? s.u(0) : 0.0;
  const double umax = std::max(1e-9, channel_value(s, "torque bound", 1.0));
  const float r = 28.0f;
  const float a0 = -0.5f * float(M_PI);
  dl->PathArcTo(base, r, a0, a0 - float(std::clamp(u / umax, -1.0, 1.0) * M_PI), 24);
  dl->PathStroke(colour::kCaution, 0, 3.0f);
  char buf[160];
  std::snprintf(buf, sizeof buf, "controller: %s    torque %.3f N m (bound %.3f)", lqr ? "LQR" : "NMPC",
                u, umax);
  const float y0 = max.y - 2.0f * ImGui::GetTextLineHeightWithSpacing() - 8.0f;
  dl->AddText(ImVec2(min.x + 8, y0), colour::kText, buf);
  std::snprintf(buf, sizeof buf, "dq1 %.2f (bound %.2f) rad/s    dq2 %.2f (bound %.2f) rad/s", s.x(2),
                channel_value(s, "dq1 bound", 0.0), s.x(3), channel_value(s, "dq2 bound", 0.0));
  dl->AddText(ImVec2(min.x + 8, y0 + ImGui::GetTextLineHeightWithSpacing()), colour::kText, buf);
  dl->PopClipRect();
}

}  // namespace mixpilot::ui
