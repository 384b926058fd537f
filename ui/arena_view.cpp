#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "models/attitude.hpp"
#include "ui/chase_camera.hpp"
#include "ui/panels.hpp"
#include "ui/reason.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {
namespace {

constexpr double kTrailS = 6.0;  // [s] the trails of the vehicle and the ghost

// A pinhole camera: world point → pixel in the view rectangle, or nothing behind the eye.
struct View {
  Eigen::Vector3d eye, forward, right, up;
  double focal = 1.0;  // [px] for a unit depth
  ImVec2 centre;
  double near = 0.05;

  View(const Eigen::Vector3d& eye_, const Eigen::Vector3d& target, Eigen::Vector3d up_hint,
       ImVec2 min, ImVec2 max, double fov_deg)
      : eye(eye_) {
    forward = (target - eye).normalized();
    if (std::abs(forward.dot(up_hint.normalized())) > 0.999) up_hint = Eigen::Vector3d::UnitY();
    right = forward.cross(up_hint).normalized();
    up = right.cross(forward);
    centre = ImVec2(0.5f * (min.x + max.x), 0.5f * (min.y + max.y));
    focal = 0.5 * (max.y - min.y) / std::tan(0.5 * fov_deg * M_PI / 180.0);
  }
  bool project(const Eigen::Vector3d& p, ImVec2& out) const {
    const Eigen::Vector3d d = p - eye;
    const double z = d.dot(forward);
    if (z < near) return false;
    out = ImVec2(float(centre.x + focal * d.dot(right) / z), float(centre.y - focal * d.dot(up) / z));
    return true;
  }
  double pixels(double metres, const Eigen::Vector3d& at) const {
    return focal * metres / std::max(near, (at - eye).dot(forward));
  }
};

void line(ImDrawList* dl, const View& v, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
          ImU32 c, float w) {
  ImVec2 pa, pb;
  if (v.project(a, pa) && v.project(b, pb)) dl->AddLine(pa, pb, c, scaled(w));
}

ImU32 with_alpha(ImU32 c, float alpha) {
  return (c & 0x00FFFFFF) | (ImU32(std::clamp(alpha, 0.0f, 1.0f) * 255.0f + 0.5f) << 24);
}

// `a` moved towards `b` by `f` ∈ [0, 1], with opacity `alpha`.
ImU32 mix(ImU32 a, ImU32 b, float f, float alpha) {
  const ImVec4 x = ImGui::ColorConvertU32ToFloat4(a), y = ImGui::ColorConvertU32ToFloat4(b);
  const auto m = [f](float p, float q) { return p + (q - p) * f; };
  return ImGui::ColorConvertFloat4ToU32(ImVec4(m(x.x, y.x), m(x.y, y.y), m(x.z, y.z), alpha));
}

// A horizontal disc of radius r at `c` (a shadow on the floor), as the camera sees it.
void floor_disc(ImDrawList* dl, const View& v, const Eigen::Vector3d& c, double r, ImU32 col) {
  constexpr int kPoints = 28;
  ImVec2 pts[kPoints];
  for (int i = 0; i < kPoints; ++i) {
    const double a = 2.0 * M_PI * i / kPoints;
    if (!v.project(c + r * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0), pts[i])) return;
  }
  dl->AddConvexPolyFilled(pts, kPoints, col);
}

Eigen::Matrix3d attitude(const Eigen::VectorXd& x) { return models::attitude(x).toRotationMatrix(); }

View make_view(const Scene& sc, const Telemetry& s, UiState& ui, ImVec2 min, ImVec2 max) {
  const Eigen::Vector3d centre = 0.5 * (sc.arena_min + sc.arena_max);
  const double size = (sc.arena_max - sc.arena_min).norm();
  const Eigen::Vector3d p = s.x.size() >= 3 ? Eigen::Vector3d(s.x.head<3>()) : centre;
  switch (ui.camera) {
    case Camera::chase:  // behind the vehicle's heading (turned clear of obstacles), above it
      if (s.x.size() < 3) return View(centre + Eigen::Vector3d(-2.2, 0, 1), centre,
                                      Eigen::Vector3d::UnitZ(), min, max, 60.0);
      return View(chase_eye(s, {ui.chase_turn, ui.chase_rise}), p, Eigen::Vector3d::UnitZ(), min,
                  max, 60.0);
    case Camera::top:
      return View(centre + Eigen::Vector3d(0, 0, 1.1 * size), centre, Eigen::Vector3d::UnitY(),
                  min, max, 50.0);
    case Camera::side:
      return View(centre + Eigen::Vector3d(0, -1.3 * size, 0), centre, Eigen::Vector3d::UnitZ(),
                  min, max, 50.0);
    case Camera::orbit:
    default: {
      const double d = ui.orbit_distance > 0 ? ui.orbit_distance : 1.2 * size;
      const Eigen::Vector3d dir(std::cos(ui.orbit_pitch) * std::cos(ui.orbit_yaw),
                                std::cos(ui.orbit_pitch) * std::sin(ui.orbit_yaw),
                                std::sin(ui.orbit_pitch));
      return View(centre + d * dir, centre, Eigen::Vector3d::UnitZ(), min, max, 50.0);
    }
  }
}

void draw_world(ImDrawList* dl, const View& v, const Scene& sc) {
  const Eigen::Vector3d& lo = sc.arena_min;
  const Eigen::Vector3d& hi = sc.arena_max;
  const double step = std::max(0.25, std::round((hi - lo).head<2>().maxCoeff() / 12.0 * 4.0) / 4.0);
  for (double x = std::ceil(lo.x() / step) * step; x <= hi.x() + 1e-9; x += step)
    line(dl, v, {x, lo.y(), lo.z()}, {x, hi.y(), lo.z()}, colour::kGrid, 1.0f);
  for (double y = std::ceil(lo.y() / step) * step; y <= hi.y() + 1e-9; y += step)
    line(dl, v, {lo.x(), y, lo.z()}, {hi.x(), y, lo.z()}, colour::kGrid, 1.0f);
  // The arena's box: its 12 edges.
  for (int e = 0; e < 12; ++e) {
    const int axis = e / 4, a = e % 4;
    Eigen::Vector3d p0, p1;
    for (int k = 0, bit = 0; k < 3; ++k) {
      if (k == axis) {
        p0[k] = lo[k];
        p1[k] = hi[k];
      } else {
        p0[k] = p1[k] = ((a >> bit) & 1) ? hi[k] : lo[k];
        ++bit;
      }
    }
    line(dl, v, p0, p1, colour::kWall, 1.5f);
  }
}

// A sphere lit from the upper left: a fan from the highlight to the rim, lighter to darker, so
// it reads as a ball rather than a disc; `fog` ∈ [0, 1] dims it with its distance.
void shaded_sphere(ImDrawList* dl, ImVec2 c, float r, ImU32 base, float fog, float alpha) {
  constexpr int kRim = 40;
  const ImU32 body = mix(base, colour::kBackground, 0.45f * fog, 1.0f);
  const ImU32 light = mix(body, colour::rgb(255, 255, 255), 0.55f, alpha);
  const ImVec2 hl(c.x - 0.38f * r, c.y - 0.42f * r);
  const ImVec2 uv = ImGui::GetFontTexUvWhitePixel();
  const auto first = ImDrawIdx(dl->_VtxCurrentIdx);
  dl->PrimReserve(kRim * 3, kRim + 1);
  dl->PrimWriteVtx(hl, uv, light);
  for (int i = 0; i < kRim; ++i) {
    const float a = 2.0f * float(M_PI) * float(i) / kRim;
    // Darker away from the light (towards the lower right), never black.
    const float away = 0.5f + 0.5f * std::cos(a - 0.25f * float(M_PI));
    dl->PrimWriteVtx(ImVec2(c.x + r * std::cos(a), c.y + r * std::sin(a)), uv,
                     mix(body, colour::rgb(0x10, 0x10, 0x14), 0.15f + 0.5f * away, alpha));
  }
  for (int i = 0; i < kRim; ++i) {
    dl->PrimWriteIdx(first);
    dl->PrimWriteIdx(ImDrawIdx(first + 1 + i));
    dl->PrimWriteIdx(ImDrawIdx(first + 1 + (i + 1) % kRim));
  }
  dl->AddCircle(c, r, mix(body, colour::rgb(255, 255, 255), 0.25f, alpha), kRim, scaled(1.0f));
}

void draw_vehicle(ImDrawList* dl, const View& v, const Telemetry& s) {
  const Eigen::Vector3d p = s.x.head<3>();
  const Eigen::Matrix3d R = attitude(s.x);
  const double arm = 0.23;
  // Rotor speeds: the state's last four (MikroKopter) or the input (Crazyflie), shaded by Ω.
  Eigen::Vector4d omega = Eigen::Vector4d::Zero();
  if (s.x.size() >= 16) omega = s.x.tail<4>();
  else if (s.u.size() == 4) omega = s.u;
  // Shaded against the bound Ω_max (grey at rest … yellow at the bound).
  const double omax = std::max(1e-9, channel_value(s, "rotor speed bound", omega.maxCoeff()));
  const Eigen::Vector3d arms[4] = {{arm, 0, 0}, {0, arm, 0}, {-arm, 0, 0}, {0, -arm, 0}};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d tip = p + R * arms[i];
    line(dl, v, p, tip, colour::kText, 3.0f);
    ImVec2 pt;
    if (v.project(tip, pt)) {
      const float f = float(std::clamp(omega[i] / omax, 0.0, 1.0));
      const ImU32 c = ImGui::ColorConvertFloat4ToU32(
          ImVec4(0.45f + 0.49f * f, 0.45f + 0.44f * f, 0.45f - 0.19f * f, 0.85f));
      const float r = std::clamp(float(v.pixels(0.05, tip)), scaled(3.0f), scaled(12.0f));
      dl->AddCircle(pt, r, c, 16, scaled(2.5f));
    }
  }
  // The nose, so the heading reads.
  line(dl, v, p, p + R * Eigen::Vector3d(1.6 * arm, 0, 0), colour::kCritical, 2.0f);
  ImVec2 pp;
  if (v.project(p, pp)) dl->AddCircleFilled(pp, scaled(4.0f), colour::kText, 12);
}

// The ghost (ui/ghost.hpp) at the flight's time t: its trail of the last `trail_s` seconds
// dashed, then the vehicle translucent — arms, filled rotors, a hub — in the ghost's colour,
// drawn before the flight's vehicle so that one stays on top. Returns where its hub is on
// screen, for its label.
std::optional<ImVec2> draw_ghost(ImDrawList* dl, const View& v, const Ghost& g, double t,
                                 double trail_s) {
  const std::optional<std::size_t> at = ghost_column(g, t);
  if (!at) return std::nullopt;
  const auto j = Eigen::Index(*at);
  // Dashes of 8 steps (0.12 s at Δt = 15 ms) with gaps of 4.
  const Eigen::Index from = std::max<Eigen::Index>(1, j - Eigen::Index(trail_s / g.dt));
  for (Eigen::Index i = from; i <= j; ++i) {
    if ((i % 12) >= 8) continue;
    const Eigen::Vector3d a = g.states.col(i - 1).head<3>(), b = g.states.col(i).head<3>();
    if (a.allFinite() && b.allFinite()) line(dl, v, a, b, with_alpha(colour::kGhost, 0.8f), 2.5f);
  }
  const Eigen::VectorXd x = g.states.col(j);
  if (!x.head<3>().allFinite()) return std::nullopt;
  const Eigen::Vector3d p = x.head<3>();
  const Eigen::Matrix3d R = attitude(x);
  const double arm = 0.23;
  const Eigen::Vector3d arms[4] = {{arm, 0, 0}, {0, arm, 0}, {-arm, 0, 0}, {0, -arm, 0}};
  // Each part drawn once, none over another (the arms start clear of the hub, the nose beyond
  // the front rotor), so the whole vehicle is equally see-through.
  for (const Eigen::Vector3d& a : arms) {
    const Eigen::Vector3d tip = p + R * a;
    line(dl, v, p + 0.25 * R * a, tip, with_alpha(colour::kGhost, 0.6f), 3.0f);
    ImVec2 pt;
    if (v.project(tip, pt)) {
      const float r = std::clamp(float(v.pixels(0.05, tip)), scaled(3.0f), scaled(12.0f));
      dl->AddCircleFilled(pt, r, with_alpha(colour::kGhost, 0.35f), 16);
      dl->AddCircle(pt, r, with_alpha(colour::kGhost, 0.7f), 16, scaled(1.5f));
    }
  }
  line(dl, v, p + R * Eigen::Vector3d(1.25 * arm, 0, 0), p + R * Eigen::Vector3d(1.6 * arm, 0, 0),
       with_alpha(colour::kGhost, 0.6f), 2.0f);
  ImVec2 pp;
  if (!v.project(p, pp)) return std::nullopt;
  dl->AddCircleFilled(pp, scaled(4.0f), with_alpha(colour::kGhost, 0.6f), 12);
  return pp;
}

// A screen rectangle [min, max).
struct Box {
  ImVec2 min, max;
};
bool overlap(const Box& a, const Box& b) {
  return a.min.x < b.max.x && b.min.x < a.max.x && a.min.y < b.max.y && b.min.y < a.max.y;
}

// The ghost's name tag: "ghost" in its colour on a dark backing, diagonally off its hub with a
// leader, on the side away from the vehicle at `away` (so it never seems to name the vehicle):
// the first corner of that side, up then down, then of the other side, near then farther out,
// clear of `keep_clear` (the reason's label, an overlay) and, where it can be, of `rather_not`
// (the vehicle); inside the pane [min, max).
void draw_ghost_label(ImDrawList* dl, ImVec2 hub, ImVec2 away, ImVec2 min, ImVec2 max,
                      std::initializer_list<Box> keep_clear, Box rather_not) {
  const char* label = "ghost";
  const ImVec2 size = ImGui::CalcTextSize(label);
  const float pad = scaled(3.0f), near = scaled(22.0f);
  if (size.x + 4.0f * pad > max.x - min.x || size.y + 4.0f * pad > max.y - min.y) return;
  const auto place = [&](ImVec2 corner, float off) {
    const float x = corner.x < 0 ? hub.x - off - size.x : hub.x + off;
    const float y = corner.y < 0 ? hub.y - off - size.y : hub.y + off;
    return ImVec2(std::clamp(x, min.x + 2.0f * pad, max.x - 2.0f * pad - size.x),
                  std::clamp(y, min.y + 2.0f * pad, max.y - 2.0f * pad - size.y));
  };
  const auto clear = [&](ImVec2 at, bool of_vehicle) {
    const Box b{ImVec2(at.x - pad, at.y - pad), ImVec2(at.x + size.x + pad, at.y + size.y + pad)};
    return (!of_vehicle || !overlap(rather_not, b)) &&
           std::none_of(keep_clear.begin(), keep_clear.end(),
                        [&](const Box& a) { return overlap(a, b); });
  };
  const float side = hub.x >= away.x ? 1.0f : -1.0f;
  const ImVec2 corners[] = {ImVec2(side, -1), ImVec2(side, +1), ImVec2(-side, -1), ImVec2(-side, +1)};
  std::optional<ImVec2> found;
  for (const bool of_vehicle : {true, false})
    for (const float off : {near, 2.5f * near})
      for (const ImVec2 corner : corners)
        if (!found && clear(place(corner, off), of_vehicle)) found = place(corner, off);
  const ImVec2 at = found.value_or(place(corners[0], near));
  // The leader from just off the hub (which stays as see-through as the rest) to the tag's
  // nearest corner.
  const ImVec2 end(hub.x < at.x ? at.x - pad : at.x + size.x + pad,
                   hub.y < at.y ? at.y - pad : at.y + size.y + pad);
  const float dx = end.x - hub.x, dy = end.y - hub.y, len = std::sqrt(dx * dx + dy * dy);
  const float gap = scaled(6.0f);
  if (len > gap)
    dl->AddLine(ImVec2(hub.x + gap * dx / len, hub.y + gap * dy / len), end,
                with_alpha(colour::kGhost, 0.7f), scaled(1.0f));
  dl->AddRectFilled(ImVec2(at.x - pad, at.y - pad), ImVec2(at.x + size.x + pad, at.y + size.y + pad),
                    colour::rgb(0x10, 0x10, 0x14, 190), pad);
  dl->AddText(at, colour::kGhost, label);
}

// The vehicle's height made visible: a line down to the floor and a ring where it lands.
void draw_drop_line(ImDrawList* dl, const View& v, const Scene& sc, const Eigen::Vector3d& p) {
  const Eigen::Vector3d foot(p.x(), p.y(), sc.arena_min.z());
  const ImU32 c = colour::rgb(220, 220, 220, 150);
  line(dl, v, p, foot, c, 1.5f);
  constexpr int kPoints = 20;
  for (int i = 0; i < kPoints; ++i) {
    const double a0 = 2.0 * M_PI * i / kPoints, a1 = 2.0 * M_PI * (i + 1) / kPoints;
    line(dl, v, foot + 0.08 * Eigen::Vector3d(std::cos(a0), std::sin(a0), 0),
         foot + 0.08 * Eigen::Vector3d(std::cos(a1), std::sin(a1), 0), c, 1.5f);
  }
}

// An obstacle as the camera sees it.
struct Ball {
  Eigen::Vector3d centre;
  double radius = 0.0;
  ImU32 colour = 0;
  double depth = 0.0;   // of its centre along the camera's axis [m]
  bool blocks = false;  // it stands between the camera and the vehicle
};

// Whether the sphere (c, r) hides part of the vehicle from the view's eye (ui/chase_camera.hpp).
bool blocks_view(const View& v, const Eigen::Vector3d& c, double r, const Eigen::Vector3d& p,
                 double size) {
  return blocks_sight(v.eye, c, r, p, size);
}

// Why λ fell (SPEC §10): the prediction λ was computed from (SPEC §5.4: the previous step's),
// bold up to node i*, node i* marked (a diamond), the ball B around η^r_{i*} and the gap
// η_{i*} − η^r_{i*}. Nothing when a cap decided λ or the prediction is not in the history.
// Drawn under the vehicle; returns where node i* is on screen, for its label.
std::optional<ImVec2> draw_reason(ImDrawList* dl, const View& v, const Scene& sc,
                                  const History& h, std::size_t i) {
  const LambdaReason& r = h[i].reason;
  const Telemetry* p = reason_prediction(h, i);
  if (r.cap != LambdaCap::none || r.node < 0 || !p || r.node >= p->predicted.cols() ||
      r.node >= p->predicted_reference.cols())
    return std::nullopt;
  const Eigen::Vector3d eta = p->predicted.col(r.node), ref = p->predicted_reference.col(r.node);
  for (int k = 1; k <= r.node; ++k)
    line(dl, v, p->predicted.col(k - 1), p->predicted.col(k), colour::kMpc, 4.0f);
  ImVec2 pr, pe;
  if (v.project(ref, pr)) {
    // Dashed, so it is not taken for B around the current reference point.
    const float rad = float(v.pixels(sc.ball_radius, ref));
    constexpr int kDashes = 24;
    for (int j = 0; j < kDashes; ++j) {
      const float a0 = 2.0f * float(M_PI) * float(2 * j) / (2 * kDashes);
      dl->PathArcTo(pr, rad, a0, a0 + float(M_PI) / kDashes, 4);
      dl->PathStroke(colour::rgb(0xEE, 0xEE, 0xEE, 220), 0, scaled(1.5f));
    }
    dl->AddCircleFilled(pr, scaled(3.0f), colour::kText, 12);
  }
  // Outlined, so it stands out of the trail (the planner's orange where λ is low).
  line(dl, v, ref, eta, colour::rgb(0xF0, 0xF0, 0xF0, 230), 6.5f);
  line(dl, v, ref, eta, colour::kCritical, 3.5f);
  if (!v.project(eta, pe)) return std::nullopt;
  const float m = scaled(7.0f);
  const ImVec2 top(pe.x, pe.y - m), right(pe.x + m, pe.y), bottom(pe.x, pe.y + m), left(pe.x - m, pe.y);
  dl->AddQuadFilled(top, right, bottom, left, colour::kCritical);
  dl->AddQuad(top, right, bottom, left, colour::kText, scaled(1.5f));
  return pe;
}

// Node i*'s label, over the vehicle: the gap and how far ahead, diagonally off the node (clear
// of the rotors) with a leader to it: up and right, else the first other corner clear of
// [clear_min, clear_max) (an overlay); inside the pane [min, max) (its text is never cut),
// where it fits at all. Returns where it was drawn.
std::optional<Box> draw_reason_label(ImDrawList* dl, const LambdaReason& r, ImVec2 node,
                                     ImVec2 min, ImVec2 max, ImVec2 clear_min, ImVec2 clear_max) {
  char label[64];
  if (r.node > 0)
    std::snprintf(label, sizeof label, "%.2f m off the reference in %.3g s", r.d_res, r.ahead);
  else
    std::snprintf(label, sizeof label, "%.2f m off the reference now", r.d_res);
  const ImVec2 size = ImGui::CalcTextSize(label);
  const float pad = scaled(3.0f), m = scaled(7.0f);
  if (size.x + 4.0f * pad > max.x - min.x || size.y + 4.0f * pad > max.y - min.y)
    return std::nullopt;
  const auto place = [&](float sx, float sy) {
    const float x = sx > 0 ? node.x + 4.0f * m : node.x - 4.0f * m - size.x;
    const float y = sy < 0 ? node.y - 5.0f * m - size.y : node.y + 5.0f * m;
    return ImVec2(std::clamp(x, min.x + 2.0f * pad, max.x - 2.0f * pad - size.x),
                  std::clamp(y, min.y + 2.0f * pad, max.y - 2.0f * pad - size.y));
  };
  const auto clear = [&](ImVec2 p) {
    return p.x + size.x + pad <= clear_min.x || p.x - pad >= clear_max.x ||
           p.y + size.y + pad <= clear_min.y || p.y - pad >= clear_max.y;
  };
  ImVec2 at = place(+1, -1);
  for (const ImVec2 corner : {ImVec2(-1, -1), ImVec2(-1, +1), ImVec2(+1, +1)})
    if (!clear(at)) at = place(corner.x, corner.y);
  if (!clear(at)) at = place(+1, -1);
  // The leader meets the label's nearest corner.
  const ImVec2 end(node.x < at.x ? at.x - pad : at.x + size.x + pad,
                   node.y < at.y ? at.y - pad : at.y + size.y + pad);
  dl->AddLine(node, end, colour::kText, scaled(1.0f));
  dl->AddRectFilled(ImVec2(at.x - pad, at.y - pad), ImVec2(at.x + size.x + pad, at.y + size.y + pad),
                    colour::rgb(0x10, 0x10, 0x14, 210), pad);
  dl->AddRect(ImVec2(at.x - pad, at.y - pad), ImVec2(at.x + size.x + pad, at.y + size.y + pad),
              colour::kCritical, pad, 0, scaled(1.0f));
  dl->AddText(at, colour::kText, label);
  return Box{ImVec2(at.x - pad, at.y - pad), ImVec2(at.x + size.x + pad, at.y + size.y + pad)};
}

}  // namespace

bool project_in_arena(const Scene& sc, const Telemetry& newest, const UiState& ui, ImVec2 min,
                      ImVec2 max, const Eigen::Vector3d& p, ImVec2& px) {
  UiState copy = ui;
  return make_view(sc, newest, copy, min, max).project(p, px);
}

void draw_arena(const Scene& sc, const History& h, UiState& ui, ImVec2 min, ImVec2 max,
                ImVec2 frame, ImVec2 clear_min, ImVec2 clear_max, bool camera_hint) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(min, max, true);
  dl->AddRectFilled(min, max, colour::kBackground);
  if (h.empty()) {
    dl->PopClipRect();
    return;
  }
  const Telemetry& s = h.newest();
  const View v = make_view(sc, s, ui, frame, max);
  const bool has_vehicle = s.x.size() >= 3;
  const Eigen::Vector3d p = has_vehicle ? Eigen::Vector3d(s.x.head<3>()) : Eigen::Vector3d::Zero();
  const double vehicle_size = kVehicleSightRadius;
  draw_world(dl, v, sc);

  // The obstacles, far to near: shaded, dimmer with distance, with shadows and drop lines to
  // the floor so their heights read. Those between the camera and the vehicle come last and
  // faded (glass), so the vehicle stays in sight.
  std::vector<Ball> balls;
  for (const SceneSphere& o : sc.spheres) balls.push_back({o.center, o.radius, colour::kObstacle});
  if (sc.moving) {
    static thread_local std::vector<Eigen::Vector3d> centres;
    sc.moving(s.t, centres);
    for (const auto& c : centres) balls.push_back({c, sc.moving_radius, colour::kCritical});
  }
  double far = 1e-9;
  for (Ball& b : balls) {
    b.depth = (b.centre - v.eye).dot(v.forward);
    b.blocks = has_vehicle && blocks_view(v, b.centre, b.radius, p, vehicle_size);
    far = std::max(far, b.depth);
  }
  std::sort(balls.begin(), balls.end(), [](const Ball& a, const Ball& b) { return a.depth > b.depth; });
  const double floor_z = sc.arena_min.z();
  for (const Ball& b : balls)
    if (b.centre.z() - b.radius >= floor_z - 1e-9)
      floor_disc(dl, v, {b.centre.x(), b.centre.y(), floor_z}, b.radius, colour::rgb(0, 0, 0, 70));
  if (has_vehicle && p.z() > floor_z)
    floor_disc(dl, v, {p.x(), p.y(), floor_z}, 0.28, colour::rgb(0, 0, 0, 120));
  for (const Ball& b : balls) {
    ImVec2 pc;
    if (b.blocks || !v.project(b.centre, pc)) continue;
    line(dl, v, b.centre, {b.centre.x(), b.centre.y(), floor_z}, with_alpha(b.colour, 0.45f), 1.0f);
    shaded_sphere(dl, pc, float(v.pixels(b.radius, b.centre)), b.colour,
                  float(std::clamp(b.depth / far, 0.0, 1.0)), 0.92f);
  }
  if (has_vehicle) draw_drop_line(dl, v, sc, p);

  for (Eigen::Index i = 1; i < sc.reference.cols(); ++i)
    line(dl, v, sc.reference.col(i - 1), sc.reference.col(i), colour::kReference, 1.0f);
  // The safe tube along the horizon and the ball B around the current reference point.
  if (sc.ball_radius > 0) {
    // The horizon's reference exists once the planner has solved.
    for (Eigen::Index i = 0; s.solved && i < s.predicted_reference.cols(); i += 4) {
      ImVec2 pc;
      const Eigen::Vector3d c = s.predicted_reference.col(i);
      if (v.project(c, pc))
        dl->AddCircle(pc, float(v.pixels(sc.ball_radius, c)), colour::rgb(0xEE, 0xEE, 0xEE, 50), 24,
                      scaled(1.0f));
    }
    ImVec2 pb;
    if (s.reference.size() >= 3 && v.project(s.reference.head<3>(), pb)) {
      const float r = float(v.pixels(sc.ball_radius, s.reference.head<3>()));
      ui.marks.ball_centre = pb;  // what the tour points at
      ui.marks.ball_radius = r;
      dl->AddCircleFilled(pb, r, colour::rgb(0xEE, 0xEE, 0xEE, 28), 32);
      dl->AddCircle(pb, r, colour::rgb(0xEE, 0xEE, 0xEE, 150), 32, scaled(1.5f));
    }
  }
  // The trail of the last seconds, coloured by λ in mixed initiative.
  const double t0 = s.t - kTrailS;
  for (std::size_t i = std::max<std::size_t>(1, h.first_at_or_after(t0) + 1); i < h.size(); ++i) {
    const Telemetry& a = h[i - 1];
    const Telemetry& b = h[i];
    if (a.x.size() < 3) continue;
    const ImU32 c = sc.shared_authority ? authority_colour(b.lambda) : colour::kPilot;
    line(dl, v, a.x.head<3>(), b.x.head<3>(), c, 3.0f);
  }
  for (Eigen::Index i = 1; i < s.predicted.cols(); ++i)
    line(dl, v, s.predicted.col(i - 1), s.predicted.col(i), colour::kMpc, 2.0f);
  const std::optional<std::size_t> why = sc.shared_authority ? shown_reason(h) : std::nullopt;
  const std::optional<ImVec2> node = why ? draw_reason(dl, v, sc, h, *why) : std::nullopt;
  const std::optional<ImVec2> ghost = sc.ghost ? draw_ghost(dl, v, *sc.ghost, s.t, kTrailS)
                                                : std::nullopt;
  if (has_vehicle) draw_vehicle(dl, v, s);
  const std::optional<Box> said =
      node ? draw_reason_label(dl, h[*why].reason, *node, min, max, clear_min, clear_max)
           : std::nullopt;
  if (ghost) {
    // Its tag clear of the vehicle (arms and rotors), the reason's label and the overlay.
    ImVec2 pv(-1e9f, -1e9f);
    const float reach = has_vehicle && v.project(p, pv) ? float(v.pixels(0.3, p)) : 0.0f;
    draw_ghost_label(dl, *ghost, pv, min, max, {said.value_or(Box{}), Box{clear_min, clear_max}},
                     Box{ImVec2(pv.x - reach, pv.y - reach), ImVec2(pv.x + reach, pv.y + reach)});
  }
  // What stands between the camera and the vehicle: a tint and its outline, over the rest.
  for (const Ball& b : balls) {
    ImVec2 pc;
    if (!b.blocks || !v.project(b.centre, pc)) continue;
    const float r = float(v.pixels(b.radius, b.centre));
    dl->AddCircleFilled(pc, r, with_alpha(b.colour, 0.10f), 48);
    dl->AddCircle(pc, r, with_alpha(b.colour, 0.6f), 48, scaled(1.5f));
  }
  // Mouse: drag orbits (switching to the orbit camera), the wheel zooms.
  if (ImGui::IsMouseHoveringRect(min, max) && !ImGui::IsAnyItemActive()) {
    ImGuiIO& io = ImGui::GetIO();
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      ui.camera = Camera::orbit;
      ui.orbit_yaw -= io.MouseDelta.x * 0.01f;
      ui.orbit_pitch = std::clamp(ui.orbit_pitch + io.MouseDelta.y * 0.01f, -0.1f, 1.5f);
    }
    if (io.MouseWheel != 0.0f) {
      const float base = ui.orbit_distance > 0 ? ui.orbit_distance
                                               : float(1.2 * (sc.arena_max - sc.arena_min).norm());
      ui.orbit_distance = std::clamp(base * std::pow(0.9f, io.MouseWheel), 0.5f, 100.0f);
    }
  }
  if (!camera_hint) {
    dl->PopClipRect();
    return;
  }
  // The camera and its keys at the bottom left; the keys shorter where the view is narrow.
  const float inset = ImGui::GetStyle().WindowPadding.x;
  std::string hint = std::string("camera: ") + to_string(ui.camera) + "  (1 chase · 2 orbit · 3 top · 4 side)";
  if (ImGui::CalcTextSize(hint.c_str()).x > max.x - min.x - 2 * inset)
    hint = std::string("camera: ") + to_string(ui.camera) + "  (keys 1-4)";
  dl->AddText(ImVec2(min.x + inset, max.y - inset - ImGui::GetTextLineHeight()),
              colour::rgb(200, 200, 200), hint.c_str());
  dl->PopClipRect();
}

}  // namespace mixpilot::ui
