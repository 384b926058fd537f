#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "models/attitude.hpp"
#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {
namespace {

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

Eigen::Matrix3d attitude(const Eigen::VectorXd& x) { return models::attitude(x).toRotationMatrix(); }

View make_view(const Scene& sc, const Telemetry& s, UiState& ui, ImVec2 min, ImVec2 max) {
  const Eigen::Vector3d centre = 0.5 * (sc.arena_min + sc.arena_max);
  const double size = (sc.arena_max - sc.arena_min).norm();
  const Eigen::Vector3d p = s.x.size() >= 3 ? Eigen::Vector3d(s.x.head<3>()) : centre;
  switch (ui.camera) {
    case Camera::chase: {  // behind the vehicle's heading, above it
      const Eigen::Vector3d fwd = attitude(s.x).col(0);
      Eigen::Vector3d back(-fwd.x(), -fwd.y(), 0.0);
      if (back.norm() < 1e-6) back = Eigen::Vector3d(-1, 0, 0);
      back.normalize();
      return View(p + 2.2 * back + Eigen::Vector3d(0, 0, 1.0), p, Eigen::Vector3d::UnitZ(), min,
                  max, 60.0);
    }
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

void draw_sphere(ImDrawList* dl, const View& v, const Eigen::Vector3d& c, double r, ImU32 col) {
  ImVec2 pc;
  if (!v.project(c, pc)) return;
  const float pr = float(v.pixels(r, c));
  dl->AddCircleFilled(pc, pr, (col & 0x00FFFFFF) | 0x70000000, 32);
  dl->AddCircle(pc, pr, col, 32, scaled(1.5f));
  ImVec2 pf;  // its shadow on the floor, so its height reads
  if (v.project({c.x(), c.y(), 0.0}, pf)) dl->AddLine(pc, pf, (col & 0x00FFFFFF) | 0x60000000, scaled(1.0f));
}

void draw_vehicle(ImDrawList* dl, const View& v, const Scene& sc, const Telemetry& s) {
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
  ImVec2 pp, pf;
  if (v.project(p, pp)) dl->AddCircleFilled(pp, scaled(4.0f), colour::kText, 12);
  if (v.project(p, pp) && v.project({p.x(), p.y(), sc.arena_min.z()}, pf))
    dl->AddLine(pp, pf, colour::rgb(200, 200, 200, 90), scaled(1.0f));
}

}  // namespace

bool project_in_arena(const Scene& sc, const Telemetry& newest, const UiState& ui, ImVec2 min,
                      ImVec2 max, const Eigen::Vector3d& p, ImVec2& px) {
  UiState copy = ui;
  return make_view(sc, newest, copy, min, max).project(p, px);
}

void draw_arena(const Scene& sc, const History& h, UiState& ui, ImVec2 min, ImVec2 max,
                ImVec2 frame) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(min, max, true);
  dl->AddRectFilled(min, max, colour::kBackground);
  if (h.empty()) {
    dl->PopClipRect();
    return;
  }
  const Telemetry& s = h.newest();
  const View v = make_view(sc, s, ui, frame, max);
  draw_world(dl, v, sc);
  for (const SceneSphere& o : sc.spheres) draw_sphere(dl, v, o.center, o.radius, colour::kObstacle);
  if (sc.moving) {
    static thread_local std::vector<Eigen::Vector3d> centres;
    sc.moving(s.t, centres);
    for (const auto& c : centres) draw_sphere(dl, v, c, sc.moving_radius, colour::kCritical);
  }
  for (Eigen::Index i = 1; i < sc.reference.cols(); ++i)
    line(dl, v, sc.reference.col(i - 1), sc.reference.col(i), colour::kReference, 1.0f);
  // The safe tube along the horizon and the ball B around the current reference point.
  if (sc.ball_radius > 0 && s.predicted_reference.cols() > 0) {
    for (Eigen::Index i = 0; i < s.predicted_reference.cols(); i += 4) {
      ImVec2 pc;
      const Eigen::Vector3d c = s.predicted_reference.col(i);
      if (v.project(c, pc))
        dl->AddCircle(pc, float(v.pixels(sc.ball_radius, c)), colour::rgb(0xEE, 0xEE, 0xEE, 50), 24,
                      scaled(1.0f));
    }
    ImVec2 pb;
    if (s.reference.size() >= 3 && v.project(s.reference.head<3>(), pb)) {
      const float r = float(v.pixels(sc.ball_radius, s.reference.head<3>()));
      dl->AddCircleFilled(pb, r, colour::rgb(0xEE, 0xEE, 0xEE, 28), 32);
      dl->AddCircle(pb, r, colour::rgb(0xEE, 0xEE, 0xEE, 150), 32, scaled(1.5f));
    }
  }
  // The trail of the last seconds, coloured by λ in mixed initiative.
  const double t0 = s.t - 6.0;
  for (std::size_t i = std::max<std::size_t>(1, h.first_at_or_after(t0) + 1); i < h.size(); ++i) {
    const Telemetry& a = h[i - 1];
    const Telemetry& b = h[i];
    if (a.x.size() < 3) continue;
    const ImU32 c = sc.mode == ModeKind::mixed_initiative ? authority_colour(b.lambda) : colour::kPilot;
    line(dl, v, a.x.head<3>(), b.x.head<3>(), c, 3.0f);
  }
  for (Eigen::Index i = 1; i < s.predicted.cols(); ++i)
    line(dl, v, s.predicted.col(i - 1), s.predicted.col(i), colour::kMpc, 2.0f);
  draw_vehicle(dl, v, sc, s);
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
