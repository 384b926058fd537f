#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

void draw_authority_bar(double lambda, ImVec2 min, ImVec2 max) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const double l = std::clamp(lambda, 0.0, 1.0);
  // The pilot's share λ fills from the left in the pilot's colour, the planner's share 1 − λ
  // the rest in the planner's colour; the needle sits at λ.
  const float x = float(min.x + l * (max.x - min.x));
  dl->AddRectFilled(min, max, colour::kPlanner, 4.0f);
  dl->AddRectFilled(min, ImVec2(x, max.y), colour::kPilot, 4.0f, ImDrawFlags_RoundCornersLeft);
  const float mid = 0.5f * (min.x + max.x);  // the 0.5 tick
  dl->AddLine(ImVec2(mid, min.y - 3), ImVec2(mid, max.y + 3), colour::kText, 1.0f);
  dl->AddLine(ImVec2(x, min.y - 5), ImVec2(x, max.y + 5), colour::kText, 3.0f);  // the needle
  char label[64];
  std::snprintf(label, sizeof label, "%s %.2f", l >= 0.5 ? "PILOT" : "PLANNER", l);
  const ImVec2 ts = ImGui::CalcTextSize(label);
  const ImVec2 at(mid - 0.5f * ts.x, 0.5f * (min.y + max.y) - 0.5f * ts.y);
  dl->AddRectFilled(ImVec2(at.x - 6, at.y - 1), ImVec2(at.x + ts.x + 6, at.y + ts.y + 1),
                    colour::rgb(0x10, 0x12, 0x15, 200), 3.0f);
  dl->AddText(at, colour::kText, label);
  dl->AddText(ImVec2(min.x + 2, max.y + 4), colour::kPilot, "pilot share λ");
  const ImVec2 ps = ImGui::CalcTextSize("planner share 1 − λ");
  dl->AddText(ImVec2(max.x - ps.x - 2, max.y + 4), colour::kPlanner, "planner share 1 − λ");
}

namespace {

void gimbal(ImDrawList* dl, ImVec2 c, float half, const char* label, double hx, double hy,
            double mx, double my, bool has_mpc) {
  dl->AddRectFilled(ImVec2(c.x - half, c.y - half), ImVec2(c.x + half, c.y + half),
                    colour::rgb(0x20, 0x23, 0x28, 230), 6.0f);
  dl->AddLine(ImVec2(c.x - half, c.y), ImVec2(c.x + half, c.y), colour::kGrid);
  dl->AddLine(ImVec2(c.x, c.y - half), ImVec2(c.x, c.y + half), colour::kGrid);
  const auto at = [&](double x, double y) {
    return ImVec2(c.x + float(std::clamp(x, -1.0, 1.0)) * (half - 6),
                  c.y - float(std::clamp(y, -1.0, 1.0)) * (half - 6));
  };
  const ImVec2 ph = at(hx, hy);
  dl->AddCircleFilled(ph, 6.0f, colour::kPilot, 16);
  if (has_mpc) {  // the MPC's applied command: a diamond, joined to the pilot's by the correction
    const ImVec2 pm = at(mx, my);
    dl->AddLine(ph, pm, colour::kMpc, 1.5f);
    const float d = 8.0f;
    dl->AddQuad(ImVec2(pm.x, pm.y - d), ImVec2(pm.x + d, pm.y), ImVec2(pm.x, pm.y + d),
                ImVec2(pm.x - d, pm.y), colour::kMpc, 2.5f);
  }
  dl->AddText(ImVec2(c.x - half, c.y + half + 2), colour::kText, label);
}

}  // namespace

void draw_sticks(const Telemetry& s, double hover, ImVec2 min, ImVec2 max) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float half = std::min(0.25f * (max.x - min.x), 0.5f * (max.y - min.y) - 12.0f);
  const float cy = min.y + half + 2;
  // Normalised by a 30° tilt for roll and pitch (SPEC §6, angle mode).
  const double tilt = 30.0 * M_PI / 180.0;
  // Thrust: the mean commanded and applied rotor speeds, ±20 % around hover (the thesis's ν has
  // no yaw, SPEC §6).
  const double th = s.pilot.rotor_speed.mean() / hover - 1.0;
  const double tm = s.applied.rotor_speed.mean() / hover - 1.0;
  gimbal(dl, ImVec2(min.x + 0.25f * (max.x - min.x), cy), half, "thrust", 0.0, 5.0 * th, 0.0,
         5.0 * tm, s.solved);
  gimbal(dl, ImVec2(min.x + 0.75f * (max.x - min.x), cy), half, "roll / pitch",
         s.pilot.roll / tilt, s.pilot.pitch / tilt, s.applied.roll / tilt, s.applied.pitch / tilt,
         s.solved);
}

namespace {

struct Series {
  const char* name;  // the channel's name (core/modes: Telemetry::channels)
  ImU32 colour;
};

int channel_index(const Telemetry& s, const char* name) {
  for (int i = 0; i < s.num_channels; ++i)
    if (std::strcmp(s.channels[std::size_t(i)].name, name) == 0) return i;
  return -1;
}

// One rolling plot of channels over [t_end − window, t_end].
void plot(const History& h, const char* title, std::initializer_list<Series> named, double window,
          double t_end, float height) {
  struct Indexed {
    int channel;
    ImU32 colour;
  };
  Indexed series[4];
  int count = 0;
  for (const Series& s : named)
    if (const int i = h.empty() ? -1 : channel_index(h.newest(), s.name); i >= 0 && count < 4)
      series[count++] = {i, s.colour};
  ImGui::TextUnformatted(title);
  const ImVec2 title_at = ImGui::GetItemRectMax();
  const ImVec2 min = ImGui::GetCursorScreenPos();
  const ImVec2 max(min.x + ImGui::GetContentRegionAvail().x, min.y + height);
  ImGui::Dummy(ImVec2(max.x - min.x, height));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(min, max, colour::rgb(0x12, 0x14, 0x18));
  if (h.empty()) return;
  const double t1 = t_end, t0 = t1 - window;
  const std::size_t first = h.first_at_or_after(t0);
  const std::size_t end = h.first_at_or_after(t1 + 1e-9);  // past the right edge
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = first; i < end; ++i) {
    for (int k = 0; k < count; ++k) {
      const Indexed& s = series[k];
      if (s.channel >= h[i].num_channels) continue;
      lo = std::min(lo, h[i].channels[std::size_t(s.channel)].value);
      hi = std::max(hi, h[i].channels[std::size_t(s.channel)].value);
    }
  }
  if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi)) return;
  if (hi - lo < 1e-9) {
    lo -= 0.5;
    hi += 0.5;
  }
  const double pad = 0.08 * (hi - lo);
  lo -= pad;
  hi += pad;
  const auto to_px = [&](double t, double v) {
    return ImVec2(float(min.x + (t - t0) / window * (max.x - min.x)),
                  float(max.y - (v - lo) / (hi - lo) * (max.y - min.y)));
  };
  // One polyline per series through each pixel column's extremes, in the order they occur:
  // thousands of samples cost a few hundred points, and no spike is lost.
  for (int k = 0; k < count; ++k) {
    const Indexed& s = series[k];
    int column = -1;
    float y_lo = 0, y_hi = 0;
    bool lo_first = true;
    const auto flush = [&] {
      if (column < 0) return;
      const float a = lo_first ? y_lo : y_hi, b = lo_first ? y_hi : y_lo;
      dl->PathLineTo(ImVec2(float(column), a));
      if (b != a) dl->PathLineTo(ImVec2(float(column), b));
    };
    for (std::size_t i = first; i < end; ++i) {
      if (s.channel >= h[i].num_channels) continue;
      const ImVec2 p = to_px(h[i].t, h[i].channels[std::size_t(s.channel)].value);
      const int c = int(p.x);
      if (c != column) {
        flush();
        column = c;
        y_lo = y_hi = p.y;
        lo_first = true;
      } else if (p.y < y_lo) {
        y_lo = p.y;
        lo_first = false;
      } else if (p.y > y_hi) {
        y_hi = p.y;
      }
    }
    flush();
    // An integer width lets ImGui draw the line from its anti-aliased texture: a third of the
    // triangles of a fractional width, which a software rasterizer feels.
    dl->PathStroke(s.colour, 0, 2.0f);
  }
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.3g", hi - pad);
  dl->AddText(ImVec2(min.x + 3, min.y + 1), colour::rgb(170, 170, 170), buf);
  std::snprintf(buf, sizeof buf, "%.3g", lo + pad);
  dl->AddText(ImVec2(min.x + 3, max.y - ImGui::GetTextLineHeight() - 1), colour::rgb(170, 170, 170), buf);
  // The legend: each series' name and its value at the right edge, or under the mouse.
  const Telemetry* at = end > 0 ? &h[end - 1] : nullptr;
  if (ImGui::IsMouseHoveringRect(min, max) && first < end) {
    const double tm = t0 + double(ImGui::GetIO().MousePos.x - min.x) / double(max.x - min.x) * window;
    const std::size_t k = std::min(end - 1, h.first_at_or_after(tm));
    at = &h[k];
    const float x = to_px(at->t, 0.0).x;
    dl->AddLine(ImVec2(x, min.y), ImVec2(x, max.y), colour::rgb(0xDD, 0xDD, 0xDD, 140), 1.0f);
  }
  float x = title_at.x + 12;
  const float legend_y = title_at.y - ImGui::GetTextLineHeight();
  for (int k = 0; at && k < count; ++k) {
    const Indexed& s = series[k];
    if (s.channel >= at->num_channels) continue;
    const Channel& c = at->channels[std::size_t(s.channel)];
    std::snprintf(buf, sizeof buf, "%s %.3g %s", c.name, c.value, c.unit);
    dl->AddText(ImVec2(x, legend_y), s.colour, buf);
    x += ImGui::CalcTextSize(buf).x + 12;
  }
}

const ImU32 kCycle[] = {colour::kPilot, colour::kPlanner, colour::kMpc, colour::kCaution,
                        colour::kObstacle, colour::kCritical};

}  // namespace

void draw_plots(const Scene& sc, const History& h, UiState& ui) {
  bool paused = ui.plots_paused;
  if (ImGui::Checkbox("pause plots (P)", &paused)) set_plots_paused(ui, h, paused);
  if (h.empty()) return;
  const double t_end = ui.plots_paused ? ui.plots_paused_at : h.newest().t;
  const float height = 80.0f;
  if (sc.mode == ModeKind::mixed_initiative) {
    plot(h, "authority λ", {{"lambda", colour::kPilot}}, ui.plot_window, t_end, height);
    plot(h, "deviation |p − η_r| vs r",
         {{"deviation", colour::kPilot}, {"ball radius r", colour::kCaution}}, ui.plot_window,
         t_end, height);
    plot(h, "roll φ_h vs φ*₁", {{"roll pilot", colour::kPilot}, {"roll MPC", colour::kMpc}},
         ui.plot_window, t_end, height);
    plot(h, "pitch θ_h vs θ*₁", {{"pitch pilot", colour::kPilot}, {"pitch MPC", colour::kMpc}},
         ui.plot_window, t_end, height);
    plot(h, "rotor speed Ω vs bound",
         {{"rotor speed max", colour::kMpc}, {"rotor speed bound", colour::kCritical}},
         ui.plot_window, t_end, height);
    plot(h, "RTI time", {{"RTI time", colour::kCaution}}, ui.plot_window, t_end, height);
    return;
  }
  const Telemetry& n = h.newest();
  for (int i = 0; i < n.num_channels; ++i)
    plot(h, n.channels[std::size_t(i)].name, {{n.channels[std::size_t(i)].name, kCycle[i % 6]}},
         ui.plot_window, t_end, 56.0f);
}

}  // namespace mixpilot::ui
