#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <span>
#include <string>

#include "ui/panels.hpp"
#include "ui/plot.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

float button_width(const char* label) {
  return ImGui::CalcTextSize(label, nullptr, true).x + 2.0f * ImGui::GetStyle().FramePadding.x;
}

float radio_width(const char* label) {
  const float text = ImGui::CalcTextSize(label, nullptr, true).x;
  return ImGui::GetFrameHeight() + (text > 0 ? ImGui::GetStyle().ItemInnerSpacing.x + text : 0.0f);
}

void same_line_or_wrap(float width, float spacing) {
  // Decided before SameLine(): a SameLine() undone by NewLine() would count the spacing after
  // the last item as content (as if it ran past the row's end).
  if (spacing < 0.0f) spacing = ImGui::GetStyle().ItemSpacing.x;
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  if (ImGui::GetItemRectMax().x + spacing + width <= right) ImGui::SameLine(0.0f, spacing);
}

std::string elide_middle(const std::string& text, float width) {
  if (ImGui::CalcTextSize(text.c_str()).x <= width) return text;
  const std::string dots = "\u2026";
  // Cut whole UTF-8 code points: never split a continuation byte (10xxxxxx).
  auto cut = [&](std::size_t keep) {
    std::size_t head = keep / 2, tail = text.size() - (keep - keep / 2);
    while (head > 0 && (static_cast<unsigned char>(text[head]) & 0xC0) == 0x80) --head;
    while (tail < text.size() && (static_cast<unsigned char>(text[tail]) & 0xC0) == 0x80) ++tail;
    return text.substr(0, head) + dots + text.substr(tail);
  };
  std::size_t lo = 0, hi = text.size();  // longest kept byte count that fits
  while (lo < hi) {
    const std::size_t mid = (lo + hi + 1) / 2;
    if (ImGui::CalcTextSize(cut(mid).c_str()).x <= width) lo = mid; else hi = mid - 1;
  }
  return cut(lo);
}

void draw_authority_bar(double lambda, ImVec2 min, ImVec2 max, bool names, bool probe,
                        const AuthorityBounds& bounds) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const double l = std::clamp(lambda, 0.0, 1.0);
  // The pilot's share λ fills from the left in the pilot's light blue, the planner's share
  // 1 − λ the rest in the planner's dark orange (told apart by lightness too: greyscale, colour
  // blindness); the needle sits at λ, cased in black, and an outline shows the whole bar.
  const auto x_of = [&](double v) { return float(min.x + std::clamp(v, 0.0, 1.0) * (max.x - min.x)); };
  const float x = x_of(l);
  const float round = scaled(4.0f);
  dl->AddRectFilled(min, max, colour::kPlannerFill, round);
  dl->AddRectFilled(min, ImVec2(x, max.y), colour::kPilot, round, ImDrawFlags_RoundCornersLeft);
  // The instructor's bounds: what λ cannot reach shaded and hatched, each bound a tick.
  const bool ceiling = bounds.ceiling < 1.0, floor = bounds.floor > 0.0;
  const auto out_of_reach = [&](float a, float b) {
    if (b - a < 1.0f) return;
    dl->AddRectFilled(ImVec2(a, min.y), ImVec2(b, max.y), colour::rgb(0x10, 0x12, 0x15, 120));
    dl->PushClipRect(ImVec2(a, min.y), ImVec2(b, max.y), true);
    const float h = max.y - min.y;
    for (float s = a - h; s < b; s += scaled(7.0f))
      dl->AddLine(ImVec2(s, max.y), ImVec2(s + h, min.y), colour::rgb(0x10, 0x12, 0x15, 110),
                  scaled(1.5f));
    dl->PopClipRect();
  };
  if (ceiling) out_of_reach(x_of(bounds.ceiling), max.x);
  if (floor) out_of_reach(min.x, x_of(bounds.floor));
  const auto bound_tick = [&](double v) {
    const float bx = x_of(v);
    dl->AddLine(ImVec2(bx, min.y - scaled(4)), ImVec2(bx, max.y + scaled(4)), colour::kCaution,
                scaled(2.5f));
  };
  if (ceiling) bound_tick(bounds.ceiling);
  if (floor) bound_tick(bounds.floor);
  const float mid = 0.5f * (min.x + max.x);  // the 0.5 tick
  dl->AddLine(ImVec2(mid, min.y - scaled(3)), ImVec2(mid, max.y + scaled(3)), colour::kText, scaled(1.0f));
  dl->AddRect(ImVec2(min.x - scaled(1), min.y - scaled(1)), ImVec2(max.x + scaled(1), max.y + scaled(1)),
              colour::kBarOutline, round + scaled(1), 0, scaled(1.0f));
  // The needle, cased.
  dl->AddLine(ImVec2(x, min.y - scaled(6)), ImVec2(x, max.y + scaled(6)), colour::kNeedleCasing, scaled(6.0f));
  dl->AddLine(ImVec2(x, min.y - scaled(5)), ImVec2(x, max.y + scaled(5)), colour::kText, scaled(3.0f));
  char bound_text[64] = "";
  if (floor && ceiling)
    std::snprintf(bound_text, sizeof bound_text, "floor %.2f · ceiling %.2f", bounds.floor,
                  bounds.ceiling);
  else if (ceiling)
    std::snprintf(bound_text, sizeof bound_text, "ceiling %.2f", bounds.ceiling);
  else if (floor)
    std::snprintf(bound_text, sizeof bound_text, "floor %.2f", bounds.floor);
  // Under the ticks, between the shares' names, where it fits; else in the label.
  const float below = max.y + scaled(4);
  const char* planner = probe ? "assistance off" : "planner share 1 − λ";
  const float gap = ImGui::CalcTextSize("  ").x;
  const float left_end = min.x + scaled(2) + ImGui::CalcTextSize("pilot share λ").x + gap;
  const float right_start = max.x - scaled(2) - ImGui::CalcTextSize(planner).x - gap;
  const float bw = ImGui::CalcTextSize(bound_text).x;
  const bool bound_below = names && bound_text[0] != '\0' && right_start - left_end >= bw;
  char label[128];
  const auto make_label = [&](bool with_bounds) {
    std::snprintf(label, sizeof label, "%s%s %.2f%s%s", probe ? "PROBE · " : "",
                  l >= 0.5 ? "PILOT" : "PLANNER", l, with_bounds ? " · " : "",
                  with_bounds ? bound_text : "");
    return ImGui::CalcTextSize(label);
  };
  ImVec2 ts = make_label(bound_text[0] != '\0' && !bound_below);
  // Too wide for the bar (a narrow HUD, large text): the ticks alone show the bounds (the HUD
  // names them on the instructor's line).
  if (ts.x + scaled(12) > max.x - min.x) ts = make_label(false);
  const ImVec2 at(mid - 0.5f * ts.x, 0.5f * (min.y + max.y) - 0.5f * ts.y);
  dl->AddRectFilled(ImVec2(at.x - scaled(6), at.y - scaled(1)),
                    ImVec2(at.x + ts.x + scaled(6), at.y + ts.y + scaled(1)),
                    colour::rgb(0x10, 0x12, 0x15, 200), scaled(3.0f));
  dl->AddText(at, colour::kText, label);
  if (!names) return;
  dl->AddText(ImVec2(min.x + scaled(2), below), colour::kPilot, "pilot share λ");
  // A probe: the planner's reference has no weight in the cost (SPEC §10).
  const ImVec2 ps = ImGui::CalcTextSize(planner);
  dl->AddText(ImVec2(max.x - ps.x - scaled(2), below), probe ? colour::kCaution : colour::kPlanner,
              planner);
  if (bound_below) {
    // Centred under its tick (between both ticks), kept between the names.
    const double centre = floor && ceiling ? 0.5 * (bounds.floor + bounds.ceiling)
                          : ceiling        ? bounds.ceiling
                                           : bounds.floor;
    const float bx = std::clamp(x_of(centre) - 0.5f * bw, left_end, right_start - bw);
    dl->AddText(ImVec2(bx, below), colour::kCaution, bound_text);
  }
}

namespace {

// One stick's square at `c` with its label centred under it, within the column [lo, hi): the
// short label where the long one would not fit.
void gimbal(ImDrawList* dl, ImVec2 c, float half, float lo, float hi, const char* label,
            const char* short_label, double hx, double hy, double mx, double my, bool has_mpc) {
  dl->AddRectFilled(ImVec2(c.x - half, c.y - half), ImVec2(c.x + half, c.y + half),
                    colour::rgb(0x20, 0x23, 0x28, 230), scaled(6.0f));
  dl->AddLine(ImVec2(c.x - half, c.y), ImVec2(c.x + half, c.y), colour::kGrid, scaled(1.0f));
  dl->AddLine(ImVec2(c.x, c.y - half), ImVec2(c.x, c.y + half), colour::kGrid, scaled(1.0f));
  const float inset = scaled(6.0f);
  const auto at = [&](double x, double y) {
    return ImVec2(c.x + float(std::clamp(x, -1.0, 1.0)) * (half - inset),
                  c.y - float(std::clamp(y, -1.0, 1.0)) * (half - inset));
  };
  const ImVec2 ph = at(hx, hy);
  dl->AddCircleFilled(ph, scaled(6.0f), colour::kPilot, 16);
  if (has_mpc) {  // the MPC's applied command: a diamond, joined to the pilot's by the correction
    const ImVec2 pm = at(mx, my);
    dl->AddLine(ph, pm, colour::kMpc, scaled(1.5f));
    const float d = scaled(8.0f);
    dl->AddQuad(ImVec2(pm.x, pm.y - d), ImVec2(pm.x + d, pm.y), ImVec2(pm.x, pm.y + d),
                ImVec2(pm.x - d, pm.y), colour::kMpc, scaled(2.5f));
  }
  if (ImGui::CalcTextSize(label).x > hi - lo) label = short_label;
  const float w = ImGui::CalcTextSize(label).x;
  dl->AddText(ImVec2(std::clamp(c.x - 0.5f * w, lo, std::max(lo, hi - w)), c.y + half + scaled(2)),
              colour::kText, label);
}

}  // namespace

void draw_sticks(const Telemetry& s, double hover, ImVec2 min, ImVec2 max) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  // Two square gimbals side by side, each with its label under it.
  const float label = ImGui::GetTextLineHeight() + scaled(2);
  const float half = std::max(1.0f, std::min(0.25f * (max.x - min.x) - scaled(4),
                                             0.5f * (max.y - min.y - label)));
  const float cy = min.y + half;
  // Normalised by a 30° tilt for roll and pitch (SPEC §6, angle mode).
  const double tilt = 30.0 * M_PI / 180.0;
  // Thrust: the mean commanded and applied rotor speeds, ±20 % around hover (the thesis's ν has
  // no yaw, SPEC §6).
  const double th = s.pilot.rotor_speed.mean() / hover - 1.0;
  const double tm = s.applied.rotor_speed.mean() / hover - 1.0;
  const float mid = 0.5f * (min.x + max.x);
  gimbal(dl, ImVec2(min.x + 0.25f * (max.x - min.x), cy), half, min.x, mid, "thrust", "thrust", 0.0,
         5.0 * th, 0.0, 5.0 * tm, s.solved);
  gimbal(dl, ImVec2(min.x + 0.75f * (max.x - min.x), cy), half, mid, max.x, "roll / pitch", "tilt",
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

// One rolling plot of channels over [t_end − window, t_end] in a slot `slot` pixels high: its
// title, a legend that wraps under it (each series' value at the right edge, or under the
// mouse), and the curves in what is left (at least `min_height`).
void plot(const History& h, const char* title, std::span<const Series> named, double window,
          double t_end, float slot, float min_height) {
  struct Indexed {
    int channel;
    ImU32 colour;
  };
  Indexed series[4];
  int count = 0;
  for (const Series& s : named)
    if (const int i = h.empty() ? -1 : channel_index(h.newest(), s.name); i >= 0 && count < 4)
      series[count++] = {i, s.colour};
  const ImVec2 top = ImGui::GetCursorScreenPos();
  const float width = ImGui::GetContentRegionAvail().x;
  const double t1 = t_end, t0 = t1 - window;
  const std::size_t first = h.empty() ? 0 : h.first_at_or_after(t0);
  const std::size_t end = h.empty() ? 0 : h.first_at_or_after(t1 + 1e-9);  // past the right edge
  // The sample the legend reads: under the mouse anywhere over the slot, else the newest shown.
  const Telemetry* at = end > 0 ? &h[end - 1] : nullptr;
  const bool hovered =
      ImGui::IsMouseHoveringRect(top, ImVec2(top.x + width, top.y + slot)) && first < end;
  if (hovered) {
    const double tm = t0 + double(ImGui::GetIO().MousePos.x - top.x) / double(width) * window;
    at = &h[std::min(end - 1, h.first_at_or_after(tm))];
  }
  ImGui::TextUnformatted(title);
  char buf[96];
  for (int k = 0; at && k < count; ++k) {
    const Indexed& s = series[k];
    if (s.channel >= at->num_channels) continue;
    const Channel& c = at->channels[std::size_t(s.channel)];
    std::snprintf(buf, sizeof buf, "%s %.3g %s", c.name, c.value, c.unit);
    same_line_or_wrap(ImGui::CalcTextSize(buf).x);
    ImGui::PushStyleColor(ImGuiCol_Text, s.colour);
    ImGui::TextUnformatted(buf);
    ImGui::PopStyleColor();
  }
  const ImVec2 min = ImGui::GetCursorScreenPos();
  const float height = std::max(min_height, top.y + slot - min.y);
  const ImVec2 max(min.x + width, min.y + height);
  ImGui::Dummy(ImVec2(width, height));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(min, max, colour::rgb(0x12, 0x14, 0x18));
  if (h.empty()) return;
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
  const PlotFrame frame{min, max, t0, t1, lo, hi};
  // One polyline per series through each pixel column's extremes (ui/plot.hpp).
  // An integer width lets ImGui draw the line from its anti-aliased texture: a third of the
  // triangles of a fractional width, which a software rasterizer feels.
  const float line_width = std::max(1.0f, std::round(scaled(2.0f)));
  for (int k = 0; k < count; ++k) {
    const Indexed& s = series[k];
    // Samples without the channel are left out (stroke_thinned asks for its points in order).
    std::size_t n = 0;
    for (std::size_t i = first; i < end; ++i) n += s.channel < h[i].num_channels;
    std::size_t next = first;
    stroke_thinned(dl, n, [&](std::size_t) {
      while (s.channel >= h[next].num_channels) ++next;
      const Telemetry& v = h[next++];
      return frame.to_px(v.t, v.channels[std::size_t(s.channel)].value);
    }, s.colour, line_width);
  }
  const float inset = scaled(3.0f);
  std::snprintf(buf, sizeof buf, "%.3g", hi - pad);
  dl->AddText(ImVec2(min.x + inset, min.y + scaled(1)), colour::rgb(170, 170, 170), buf);
  std::snprintf(buf, sizeof buf, "%.3g", lo + pad);
  dl->AddText(ImVec2(min.x + inset, max.y - ImGui::GetTextLineHeight() - scaled(1)),
              colour::rgb(170, 170, 170), buf);
  if (hovered) {
    const float x = frame.px_x(at->t);
    dl->AddLine(ImVec2(x, min.y), ImVec2(x, max.y), colour::rgb(0xDD, 0xDD, 0xDD, 140), scaled(1.0f));
  }
}

const ImU32 kCycle[] = {colour::kPilot, colour::kPlanner, colour::kMpc, colour::kCaution,
                        colour::kObstacle, colour::kCritical};

// A series' colour from what it stands for (the i-th of its plot for SeriesRole::other).
ImU32 role_colour(SeriesRole role, int i) {
  switch (role) {
    case SeriesRole::pilot: return colour::kPilot;
    case SeriesRole::applied: return colour::kMpc;
    case SeriesRole::soft_limit: return colour::kCaution;
    case SeriesRole::hard_limit: return colour::kCritical;
    case SeriesRole::timing: return colour::kCaution;
    case SeriesRole::other: break;
  }
  return kCycle[i % 6];
}

}  // namespace

void draw_plots(const Scene& sc, const History& h, UiState& ui) {
  bool paused = ui.plots_paused;
  if (ImGui::Checkbox("pause plots (P)", &paused)) set_plots_paused(ui, h, paused);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Freeze the plots to read them (the flight goes on)");
  if (h.empty()) return;
  const double t_end = ui.plots_paused ? ui.plots_paused_at : h.newest().t;
  // The plots share the pane's height; below a readable height each (its two axis labels and
  // a curve between them) the pane scrolls.
  const float min_height = 3.0f * ImGui::GetTextLineHeight();
  const ImGuiStyle& st = ImGui::GetStyle();
  const auto slot = [&](int plots) {
    return std::max(0.0f, (ImGui::GetContentRegionAvail().y + st.ItemSpacing.y) / float(plots) -
                              st.ItemSpacing.y);
  };
  if (!sc.plots.empty()) {
    const float s = slot(int(sc.plots.size()));
    for (const PlotSpec& spec : sc.plots) {
      Series series[4];
      std::size_t n = 0;
      for (std::size_t i = 0; i < spec.series.size() && n < 4; ++i)
        series[n++] = {spec.series[i].channel, role_colour(spec.series[i].role, int(i))};
      plot(h, spec.title, std::span<const Series>(series, n), ui.plot_window, t_end, s, min_height);
    }
    return;
  }
  const Telemetry& n = h.newest();
  const float s = slot(std::max(1, n.num_channels));
  for (int i = 0; i < n.num_channels; ++i) {
    const Series one[] = {{n.channels[std::size_t(i)].name, kCycle[i % 6]}};
    plot(h, n.channels[std::size_t(i)].name, one, ui.plot_window, t_end, s, min_height);
  }
}

}  // namespace mixpilot::ui
