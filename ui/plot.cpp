#include "ui/plot.hpp"

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <numeric>

#include "ui/theme.hpp"

namespace mixpilot::ui {

void stroke_dashed(ImDrawList* dl, std::span<const ImVec2> points, ImU32 colour, float width,
                   float on, float off) {
  const double period = double(on) + double(off);
  if (!(on > 0.0f) || !(off >= 0.0f)) return;
  // Where along the pattern [0, period) the pen is, carried from one segment to the next. Each
  // pass either ends the segment or reaches the next edge of a dash exactly (no drift, however
  // long the line).
  double phase = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const ImVec2 a = points[i - 1], b = points[i];
    if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y))
      continue;
    const double dx = double(b.x) - a.x, dy = double(b.y) - a.y, len = std::sqrt(dx * dx + dy * dy);
    double at = 0.0;
    while (at < len) {
      const bool drawing = phase < on;
      const double to_edge = (drawing ? double(on) : period) - phase;
      const double from = at;
      if (len - at < to_edge) {
        phase += len - at;
        at = len;
      } else {
        at += to_edge;
        phase = drawing ? double(on) : 0.0;
      }
      if (drawing && at > from) {
        const double s = from / len, e = at / len;
        dl->AddLine(ImVec2(float(a.x + s * dx), float(a.y + s * dy)),
                    ImVec2(float(a.x + e * dx), float(a.y + e * dy)), colour, width);
      }
    }
  }
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> out;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return out;
  target = std::max(target, 2);
  // Of the steps 1, 2, 2.5 and 5 × 10^k, the one whose tick count is nearest the target (the
  // smaller step on a tie).
  const double mag = std::pow(10.0, std::floor(std::log10((hi - lo) / double(target))));
  double step = mag, best = 1e300;
  for (const double m : {0.5, 1.0, 2.0, 2.5, 5.0, 10.0, 20.0}) {
    const double s = m * mag;
    const double count = std::floor(hi / s + 1e-9) - std::ceil(lo / s - 1e-9) + 1.0;
    const double miss = std::abs(count - double(target));
    if (miss < best - 1e-9) {
      best = miss;
      step = s;
    }
  }
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (int i = 0;; ++i) {
    const double v = first + double(i) * step;  // no accumulated error, however many
    if (v > hi + 1e-9 * step || i > 1000) break;
    out.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  }
  return out;
}

std::string tick_label(double value, double step) {
  char buf[32];
  const double a = std::abs(step);
  if (a > 0 && (a < 1e-4 || a >= 1e6)) {
    std::snprintf(buf, sizeof buf, "%.3g", value);
    return buf;
  }
  // As many decimals as the step has: 0.25 → 2, 0.5 → 1, 20 → 0.
  int decimals = 0;
  for (double s = a; decimals < 6 && std::abs(s - std::round(s)) > 1e-6 * std::max(1.0, s);
       s *= 10.0)
    ++decimals;
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  std::string s = buf;
  if (s == "-0" || s.rfind("-0.", 0) == 0) {  // no "−0.00"
    bool zero = true;
    for (const char c : s) zero &= c == '-' || c == '0' || c == '.';
    if (zero) s.erase(0, 1);
  }
  if (!s.empty() && s[0] == '-') s.replace(0, 1, "\u2212");  // a minus sign, not a hyphen
  return s;
}

void add_text_upward(ImDrawList* dl, ImVec2 centre, ImU32 colour, const char* text) {
  const ImVec2 size = ImGui::CalcTextSize(text);
  // Laid out level about the middle of the display (inside the clip rectangle, which culls
  // glyphs as they are added), then turned a quarter left about its centre and moved to
  // `centre` (screen y points down: right → up, down → right).
  const ImVec2 at = ImVec2(0.5f * ImGui::GetIO().DisplaySize.x, 0.5f * ImGui::GetIO().DisplaySize.y);
  const int first = dl->VtxBuffer.Size;
  dl->AddText(ImVec2(at.x - 0.5f * size.x, at.y - 0.5f * size.y), colour, text);
  for (int i = first; i < dl->VtxBuffer.Size; ++i) {
    ImVec2& p = dl->VtxBuffer[i].pos;
    const float dx = p.x - at.x, dy = p.y - at.y;
    p = ImVec2(centre.x + dy, centre.y - dx);
  }
}

namespace {

namespace fc = figure_colour;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool valid() const { return lo <= hi; }
};

// The axis's range: as given, else the data's padded by 4 % each side (a flat one by ±0.5, or
// ±5 % of its value).
void settle(const PlotAxis& axis, Range data, double& lo, double& hi) {
  if (!data.valid()) data = {0.0, 1.0};
  if (data.hi - data.lo < 1e-12) {
    const double half = data.lo == 0.0 ? 0.5 : 0.05 * std::abs(data.lo);
    data.lo -= half;
    data.hi += half;
  }
  const double pad = 0.04 * (data.hi - data.lo);
  lo = std::isfinite(axis.min) ? axis.min : data.lo - pad;
  hi = std::isfinite(axis.max) ? axis.max : data.hi + pad;
  if (!(hi > lo)) hi = lo + 1.0;
}

void draw_marker(ImDrawList* dl, ImVec2 c, Marker m, float r, ImU32 colour) {
  const float w = std::max(1.0f, scaled(1.5f));
  switch (m) {
    case Marker::none: break;
    case Marker::circle: dl->AddCircleFilled(c, r, colour, 20); break;
    case Marker::square:
      dl->AddRectFilled(ImVec2(c.x - r, c.y - r), ImVec2(c.x + r, c.y + r), colour);
      break;
    case Marker::diamond: {
      const float d = 1.3f * r;
      dl->AddQuadFilled(ImVec2(c.x, c.y - d), ImVec2(c.x + d, c.y), ImVec2(c.x, c.y + d),
                        ImVec2(c.x - d, c.y), colour);
      break;
    }
    case Marker::triangle:
      dl->AddTriangleFilled(ImVec2(c.x, c.y - 1.2f * r), ImVec2(c.x + 1.1f * r, c.y + 0.8f * r),
                            ImVec2(c.x - 1.1f * r, c.y + 0.8f * r), colour);
      break;
    case Marker::cross:
      dl->AddLine(ImVec2(c.x - r, c.y - r), ImVec2(c.x + r, c.y + r), colour, 1.6f * w);
      dl->AddLine(ImVec2(c.x - r, c.y + r), ImVec2(c.x + r, c.y - r), colour, 1.6f * w);
      break;
    case Marker::star: {  // five points: the goal (the thesis's ⋆)
      ImVec2 p[10];
      for (int i = 0; i < 10; ++i) {
        const double a = -M_PI / 2 + double(i) * M_PI / 5;
        const float rr = (i % 2 == 0 ? 1.6f : 0.65f) * r;
        p[i] = ImVec2(c.x + rr * float(std::cos(a)), c.y + rr * float(std::sin(a)));
      }
      for (int i = 0; i < 10; i += 2)  // the points, then the pentagon between them
        dl->AddTriangleFilled(p[(i + 9) % 10], p[i], p[i + 1], colour);
      const ImVec2 inner[5] = {p[1], p[3], p[5], p[7], p[9]};
      dl->AddConvexPolyFilled(inner, 5, colour);
      break;
    }
  }
}

// The dash pattern of `d` for lines `w` wide: on and off lengths [px].
void dash_pattern(Dash d, float w, float& on, float& off) {
  switch (d) {
    case Dash::dashed: on = 5.0f * w; off = 3.5f * w; return;
    case Dash::dotted: on = 1.2f * w; off = 2.2f * w; return;
    case Dash::solid: break;
  }
  on = 1.0f;
  off = 0.0f;
}

void stroke(ImDrawList* dl, std::span<const ImVec2> pts, Dash d, ImU32 colour, float w) {
  if (d == Dash::solid) {
    stroke_thinned(dl, pts.size(), [&](std::size_t i) { return pts[i]; }, colour, w);
    return;
  }
  float on = 0, off = 0;
  dash_pattern(d, w, on, off);
  stroke_dashed(dl, pts, colour, w, on, off);
}

// Gaussian kernel density of `v` on `grid` (Silverman's bandwidth, no mass beyond the data).
std::vector<double> density(const std::vector<double>& v, const std::vector<double>& grid) {
  std::vector<double> out(grid.size(), 0.0);
  const std::size_t n = v.size();
  if (n == 0) return out;
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / double(n);
  double var = 0;
  for (const double x : v) var += (x - mean) * (x - mean);
  const double sd = std::sqrt(var / double(std::max<std::size_t>(n - 1, 1)));
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  const double iqr = s[(3 * n) / 4 < n ? (3 * n) / 4 : n - 1] - s[n / 4];
  double spread = std::min(sd, iqr / 1.34);
  if (!(spread > 0)) spread = sd > 0 ? sd : std::max(1e-9, std::abs(mean) * 1e-3);
  const double h = 1.06 * spread * std::pow(double(n), -0.2);
  for (std::size_t g = 0; g < grid.size(); ++g) {
    double sum = 0;
    for (const double x : s) {
      const double z = (grid[g] - x) / h;
      if (std::abs(z) < 6.0) sum += std::exp(-0.5 * z * z);
    }
    out[g] = sum;
  }
  return out;
}

struct LegendEntry {
  enum Kind { line, band, circle, violin } kind = line;
  std::string label;
  ImU32 colour = 0;
  Dash dash = Dash::solid;
  float width = 1.5f;
  Marker marker = Marker::none;
  float marker_size = 4.0f;
};

std::vector<LegendEntry> legend_of(const Chart& c) {
  std::vector<LegendEntry> out;
  const auto seen = [&](const std::string& l) {
    return l.empty() || std::any_of(out.begin(), out.end(),
                                    [&](const LegendEntry& e) { return e.label == l; });
  };
  for (const PlotLine& l : c.lines)
    if (!seen(l.label))
      out.push_back({LegendEntry::line, l.label, l.colour, l.dash, l.width, l.marker, l.marker_size});
  for (const PlotBand& b : c.bands)
    if (!seen(b.label)) out.push_back({LegendEntry::band, b.label, b.colour});
  for (const PlotCircle& o : c.circles)
    if (!seen(o.label)) out.push_back({LegendEntry::circle, o.label, o.colour});
  for (const PlotViolin& v : c.violins)
    if (!seen(v.label)) out.push_back({LegendEntry::violin, v.label, v.colour});
  return out;
}

float swatch_width() { return 2.2f * ImGui::GetFontSize(); }

// The legend's rows over [x0, x1) from y: lays them out (and draws them when `dl`); returns
// the height they take.
float legend(ImDrawList* dl, const std::vector<LegendEntry>& entries, float x0, float x1, float y) {
  if (entries.empty()) return 0.0f;
  const float line_h = ImGui::GetTextLineHeight();
  const float gap = 0.5f * ImGui::GetFontSize(), sep = 1.4f * ImGui::GetFontSize();
  float x = x0, rows = 1;
  for (const LegendEntry& e : entries) {
    const float w = swatch_width() + gap + ImGui::CalcTextSize(e.label.c_str()).x;
    if (x > x0 && x + w > x1) {
      x = x0;
      ++rows;
    }
    const float row_y = y + (rows - 1) * line_h * 1.15f;
    if (dl) {
      const float mid = row_y + 0.5f * line_h, sw = swatch_width();
      switch (e.kind) {
        case LegendEntry::line: {
          if (e.width > 0) {
            const ImVec2 pts[2] = {ImVec2(x, mid), ImVec2(x + sw, mid)};
            stroke(dl, pts, e.dash, e.colour, std::max(1.0f, scaled(e.width)));
          }
          draw_marker(dl, ImVec2(x + 0.5f * sw, mid), e.marker, scaled(e.marker_size), e.colour);
          break;
        }
        case LegendEntry::band:
          dl->AddRectFilled(ImVec2(x, row_y + 0.15f * line_h), ImVec2(x + sw, row_y + 0.85f * line_h),
                            e.colour);
          break;
        case LegendEntry::circle: {
          const float r = 0.38f * line_h;
          dl->AddCircleFilled(ImVec2(x + 0.5f * sw, mid), r, fc::with_alpha(e.colour, 70), 24);
          dl->AddCircle(ImVec2(x + 0.5f * sw, mid), r, e.colour, 24, std::max(1.0f, scaled(1.5f)));
          break;
        }
        case LegendEntry::violin:
          dl->AddRectFilled(ImVec2(x + 0.2f * sw, row_y + 0.1f * line_h),
                            ImVec2(x + 0.8f * sw, row_y + 0.9f * line_h), fc::with_alpha(e.colour, 110));
          dl->AddRect(ImVec2(x + 0.2f * sw, row_y + 0.1f * line_h),
                      ImVec2(x + 0.8f * sw, row_y + 0.9f * line_h), e.colour, 0, 0,
                      std::max(1.0f, scaled(1.2f)));
          break;
      }
      dl->AddText(ImVec2(x + sw + gap, row_y), fc::kText, e.label.c_str());
    }
    x += w + sep;
  }
  return rows * line_h * 1.15f;
}

}  // namespace

void draw_chart(const Chart& c, ImVec2 min, ImVec2 max) {
  if (c.y.log) {
    // Drawn as the linear chart of log10(y), with ticks at 1, 2, 5 × 10^k labelled by value.
    Chart t = c;
    t.y.log = false;
    const auto lg = [](double v) { return v > 0 ? std::log10(v) : std::numeric_limits<double>::quiet_NaN(); };
    Range r;
    for (PlotLine& l : t.lines)
      for (double& y : l.y) r.add(y = lg(y));
    for (PlotViolin& v : t.violins) {
      std::vector<double> kept;
      for (const double y : v.values)
        if (y > 0) kept.push_back(std::log10(y));
      v.values = std::move(kept);
      for (const double y : v.values) r.add(y);
    }
    for (PlotNote& n : t.notes) n.y = lg(n.y);
    t.circles.clear();  // no circles on a logarithmic axis
    double lo = 0, hi = 0;
    t.y.min = t.y.max = std::numeric_limits<double>::quiet_NaN();
    settle(t.y, r, lo, hi);
    if (std::isfinite(c.y.min) && c.y.min > 0) lo = std::log10(c.y.min);
    if (std::isfinite(c.y.max) && c.y.max > 0) hi = std::log10(c.y.max);
    t.y.min = lo;
    t.y.max = hi;
    if (t.y.ticks.empty()) {
      for (int k = int(std::floor(lo)); k <= int(std::ceil(hi)); ++k)
        for (const double m : {1.0, 2.0, 5.0}) {
          const double v = m * std::pow(10.0, k);
          if (std::log10(v) >= lo - 1e-9 && std::log10(v) <= hi + 1e-9)
            t.y.ticks.emplace_back(std::log10(v), tick_label(v, v));
        }
    }
    draw_chart(t, min, max);
    return;
  }
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float fs = ImGui::GetFontSize(), line_h = ImGui::GetTextLineHeight();
  const float tick_len = 0.35f * fs, gap = 0.3f * fs;
  const float line_w = std::max(1.0f, scaled(1.0f));

  // The data's ranges.
  Range rx, ry;
  for (const PlotLine& l : c.lines) {
    for (std::size_t i = 0; i < std::min(l.x.size(), l.y.size()); ++i) {
      if (!std::isfinite(l.x[i]) || !std::isfinite(l.y[i])) continue;
      rx.add(l.x[i]);
      ry.add(l.y[i]);
    }
  }
  for (const PlotCircle& o : c.circles) {
    rx.add(o.x - o.r);
    rx.add(o.x + o.r);
    ry.add(o.y - o.r);
    ry.add(o.y + o.r);
  }
  for (const PlotViolin& v : c.violins) {
    rx.add(v.x - v.half_width);
    rx.add(v.x + v.half_width);
    for (const double y : v.values) ry.add(y);
  }
  for (const PlotBand& b : c.bands) {
    rx.add(b.x0);
    rx.add(b.x1);
  }
  double x0, x1, y0, y1;
  settle(c.x, rx, x0, x1);
  settle(c.y, ry, y0, y1);

  // Layout: the title, the legend, then the axes with their tick labels and labels.
  float top = min.y;
  if (!c.title.empty()) {  // wrapped to the chart's width
    const float wrap = max.x - min.x;
    dl->AddText(ImGui::GetFont(), fs, ImVec2(min.x, top), fc::kText, c.title.c_str(), nullptr, wrap);
    top += ImGui::CalcTextSize(c.title.c_str(), nullptr, false, wrap).y + gap;
  }
  // The legend under the title, from the chart's left edge; then the axes.
  const std::vector<LegendEntry> entries = legend_of(c);
  const float right = max.x - 0.6f * fs;  // the last x tick label's half
  dl->PushClipRect(min, max, true);  // a label longer than the chart is cut, never over a neighbour
  top += legend(dl, entries, min.x, right, top);
  dl->PopClipRect();
  if (!entries.empty()) top += 0.4f * gap;
  top += 0.5f * line_h;  // the top y tick label's half
  const float bottom = max.y - line_h - tick_len - gap - (c.x.label.empty() ? 0.0f : line_h + gap);
  const float y_label_w = c.y.label.empty() ? 0.0f : line_h + gap;
  const auto y_ticks_for = [&](float height, double lo, double hi) {
    return nice_ticks(lo, hi, std::clamp(int(height / (1.9f * line_h)), 3, 9));
  };
  // The frame with its left edge at `left`, equal aspect applied.
  const auto frame_at = [&](float left) {
    PlotFrame f{ImVec2(left, top), ImVec2(right, bottom), x0, x1, y0, y1};
    if (c.equal_aspect && f.max.x > f.min.x && f.max.y > f.min.y) {
      // The same metres per pixel on both axes: the axis with fewer pixels per metre grows.
      const double sx = (x1 - x0) / double(f.max.x - f.min.x), sy = (y1 - y0) / double(f.max.y - f.min.y);
      if (sx > sy) {
        const double half = 0.5 * sx * double(f.max.y - f.min.y), mid = 0.5 * (y0 + y1);
        f.y0 = mid - half;
        f.y1 = mid + half;
      } else {
        const double half = 0.5 * sy * double(f.max.x - f.min.x), mid = 0.5 * (x0 + x1);
        f.x0 = mid - half;
        f.x1 = mid + half;
      }
    }
    return f;
  };
  // The y tick labels' width decides the left margin, and the margin the ticks (through the
  // aspect): settled in a few passes.
  float left = min.x + y_label_w + 2.0f * fs;
  for (int pass = 0; pass < 3; ++pass) {
    const PlotFrame f = frame_at(left);
    float widest = 0;
    const std::vector<double> yt = y_ticks_for(f.max.y - f.min.y, f.y0, f.y1);
    const double step = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
    if (c.y.ticks.empty())
      for (const double v : yt) widest = std::max(widest, ImGui::CalcTextSize(tick_label(v, step).c_str()).x);
    for (const auto& [v, text] : c.y.ticks) widest = std::max(widest, ImGui::CalcTextSize(text.c_str()).x);
    left = min.x + y_label_w + widest + tick_len + gap;
  }
  const PlotFrame f = frame_at(left);

  // Grid and ticks.
  const std::vector<double> xt =
      nice_ticks(f.x0, f.x1, std::clamp(int((f.max.x - f.min.x) / (5.0f * fs)), 3, 10));
  const std::vector<double> yt = y_ticks_for(f.max.y - f.min.y, f.y0, f.y1);
  const double x_step = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  const double y_step = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  const bool custom_x = !c.x.ticks.empty(), custom_y = !c.y.ticks.empty();
  const auto for_x_ticks = [&](const auto& fn) {
    if (custom_x) {
      for (const auto& [v, text] : c.x.ticks) fn(v, text);
    } else {
      for (const double v : xt) fn(v, tick_label(v, x_step));
    }
  };
  const auto for_y_ticks = [&](const auto& fn) {
    if (custom_y) {
      for (const auto& [v, text] : c.y.ticks) fn(v, text);
    } else {
      for (const double v : yt) fn(v, tick_label(v, y_step));
    }
  };
  for_x_ticks([&](double v, const std::string&) {
    const float x = f.px_x(v);
    if (x >= f.min.x - 0.5f && x <= f.max.x + 0.5f)
      dl->AddLine(ImVec2(x, f.min.y), ImVec2(x, f.max.y), fc::kGrid, line_w);
  });
  for_y_ticks([&](double v, const std::string&) {
    const float y = f.px_y(v);
    if (y >= f.min.y - 0.5f && y <= f.max.y + 0.5f)
      dl->AddLine(ImVec2(f.min.x, y), ImVec2(f.max.x, y), fc::kGrid, line_w);
  });

  // The data, clipped to the axes.
  dl->PushClipRect(f.min, f.max, true);
  for (const PlotBand& b : c.bands)
    dl->AddRectFilled(ImVec2(f.px_x(b.x0), f.min.y), ImVec2(f.px_x(b.x1), f.max.y), b.colour);
  for (const PlotCircle& o : c.circles) {
    const ImVec2 p = f.to_px(o.x, o.y);
    const float r = float(o.r / (f.x1 - f.x0) * double(f.max.x - f.min.x));
    if (o.filled) dl->AddCircleFilled(p, r, fc::with_alpha(o.colour, 40), 48);
    dl->AddCircle(p, r, o.colour, 48, std::max(1.0f, scaled(1.5f)));
  }
  for (const PlotViolin& v : c.violins) {
    if (v.values.empty()) continue;
    const auto [lo_it, hi_it] = std::minmax_element(v.values.begin(), v.values.end());
    const double lo = *lo_it, hi = *hi_it;
    std::vector<double> grid(160);
    for (std::size_t i = 0; i < grid.size(); ++i)
      grid[i] = lo + (hi - lo) * double(i) / double(grid.size() - 1);
    const std::vector<double> d = density(v.values, grid);
    const double peak = std::max(1e-300, *std::max_element(d.begin(), d.end()));
    const float cx = f.px_x(v.x);
    const float px_per_x = float(double(f.max.x - f.min.x) / (f.x1 - f.x0));
    const ImU32 fill = fc::with_alpha(v.colour, 110);
    std::vector<ImVec2> left_edge, right_edge;
    for (std::size_t i = 0; i < grid.size(); ++i) {
      const float w = float(d[i] / peak * v.half_width) * px_per_x;
      const float y = f.px_y(grid[i]);
      left_edge.emplace_back(cx - w, y);
      right_edge.emplace_back(cx + w, y);
    }
    // The body as trapezoids between the grid's rows, without anti-aliased edges: adjacent
    // translucent pieces would show their seams.
    const ImDrawListFlags flags = dl->Flags;
    dl->Flags &= ~ImDrawListFlags_AntiAliasedFill;
    for (std::size_t i = 1; i < grid.size(); ++i)
      dl->AddQuadFilled(left_edge[i - 1], right_edge[i - 1], right_edge[i], left_edge[i], fill);
    dl->Flags = flags;
    const float ow = std::max(1.0f, scaled(1.2f));
    dl->AddPolyline(left_edge.data(), int(left_edge.size()), v.colour, 0, ow);
    dl->AddPolyline(right_edge.data(), int(right_edge.size()), v.colour, 0, ow);
    // The extremes (a thin line) and the mean (a bar across).
    dl->AddLine(ImVec2(cx, f.px_y(lo)), ImVec2(cx, f.px_y(hi)), v.colour, ow);
    const double mean = std::accumulate(v.values.begin(), v.values.end(), 0.0) / double(v.values.size());
    const float bar = 0.45f * float(v.half_width) * px_per_x;
    dl->AddLine(ImVec2(cx - bar, f.px_y(mean)), ImVec2(cx + bar, f.px_y(mean)), fc::kBlack,
                std::max(1.0f, scaled(2.0f)));
  }
  std::vector<ImVec2> pts;
  for (const PlotLine& l : c.lines) {
    const std::size_t n = std::min(l.x.size(), l.y.size());
    pts.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      pts[i] = std::isfinite(l.x[i]) && std::isfinite(l.y[i])
                   ? f.to_px(l.x[i], l.y[i])
                   : ImVec2(std::numeric_limits<float>::quiet_NaN(), 0.0f);
    if (l.width > 0) stroke(dl, pts, l.dash, l.colour, std::max(1.0f, scaled(l.width)));
    if (l.marker != Marker::none) {
      const int every = std::max(1, l.marker_every);
      for (std::size_t i = 0; i < n; ++i) {
        const bool last = l.marker_last && i + 1 == n;
        if ((l.marker_last && every > 1 && !last) || (!last && i % std::size_t(every) != 0)) continue;
        if (std::isfinite(pts[i].x)) draw_marker(dl, pts[i], l.marker, scaled(l.marker_size), l.colour);
      }
    }
  }
  for (const PlotNote& n : c.notes) {
    const ImVec2 p = f.to_px(n.x, n.y);
    const float tw = ImGui::CalcTextSize(n.text.c_str()).x;
    const float w = n.anchor == PlotNote::Anchor::left ? 0.0f : n.anchor == PlotNote::Anchor::centre ? 0.5f * tw : tw;
    dl->AddText(ImVec2(p.x - w, p.y - 0.5f * line_h), n.colour, n.text.c_str());
  }
  dl->PopClipRect();

  // The axes' box, ticks outside it, their labels.
  dl->AddRect(f.min, f.max, fc::kBlack, 0.0f, 0, line_w);
  for_x_ticks([&](double v, const std::string& text) {
    const float x = f.px_x(v);
    if (x < f.min.x - 0.5f || x > f.max.x + 0.5f) return;
    dl->AddLine(ImVec2(x, f.max.y), ImVec2(x, f.max.y + tick_len), fc::kBlack, line_w);
    const float w = ImGui::CalcTextSize(text.c_str()).x;
    dl->AddText(ImVec2(x - 0.5f * w, f.max.y + tick_len + 0.2f * gap), fc::kText, text.c_str());
  });
  for_y_ticks([&](double v, const std::string& text) {
    const float y = f.px_y(v);
    if (y < f.min.y - 0.5f || y > f.max.y + 0.5f) return;
    dl->AddLine(ImVec2(f.min.x - tick_len, y), ImVec2(f.min.x, y), fc::kBlack, line_w);
    const float w = ImGui::CalcTextSize(text.c_str()).x;
    dl->AddText(ImVec2(f.min.x - tick_len - gap - w, y - 0.5f * line_h), fc::kText, text.c_str());
  });
  if (!c.x.label.empty()) {
    const float w = ImGui::CalcTextSize(c.x.label.c_str()).x;
    dl->AddText(ImVec2(0.5f * (f.min.x + f.max.x - w), max.y - line_h), fc::kText, c.x.label.c_str());
  }
  if (!c.y.label.empty())
    add_text_upward(dl, ImVec2(min.x + 0.5f * line_h, 0.5f * (f.min.y + f.max.y)), fc::kText,
                    c.y.label.c_str());
}

void draw_figure(const Figure& fig) {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(size);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  ImGui::Begin("##figure", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoBackground | ImGuiWindowFlags_NoBringToFrontOnFocus);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(ImVec2(0, 0), size, fc::kPage);
  const float fs = ImGui::GetFontSize();
  const float margin = 1.0f * fs;
  float top = 0.6f * fs;
  if (!fig.title.empty()) {
    ImFont* font = heading_font() ? heading_font() : ImGui::GetFont();
    const float hs = font->FontSize, wrap = size.x - 2 * margin;
    // Centred on one line, or wrapped at the margins when it is longer.
    const ImVec2 one = font->CalcTextSizeA(hs, FLT_MAX, 0.0f, fig.title.c_str());
    const ImVec2 ts = font->CalcTextSizeA(hs, FLT_MAX, wrap, fig.title.c_str());
    const float x = one.x <= wrap ? 0.5f * (size.x - one.x) : margin;
    dl->AddText(font, hs, ImVec2(x, top), fc::kText, fig.title.c_str(), nullptr, wrap);
    top += ts.y + 0.6f * fs;
  }
  float bottom = size.y - 0.4f * fs;
  if (!fig.footer.empty()) {
    bottom -= ImGui::GetTextLineHeight();
    dl->AddText(ImVec2(margin, bottom), fc::kGrey, fig.footer.c_str());
    bottom -= 0.4f * fs;
  }
  std::vector<int> rows = fig.rows;
  if (rows.empty())
    for (std::size_t i = 0; i < fig.charts.size(); i += std::size_t(std::max(1, fig.columns)))
      rows.push_back(std::max(1, fig.columns));
  const float hgap = 1.6f * fs, vgap = 1.0f * fs;
  float weights = 0;
  for (std::size_t r = 0; r < rows.size(); ++r)
    weights += r < fig.row_heights.size() ? fig.row_heights[r] : 1.0f;
  const float free = bottom - top - float(rows.empty() ? 0 : rows.size() - 1) * vgap;
  std::size_t i = 0;
  float y = top;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int cols = std::max(1, rows[r]);
    const float cw = (size.x - 2 * margin - float(cols - 1) * hgap) / float(cols);
    const float ch = free * (r < fig.row_heights.size() ? fig.row_heights[r] : 1.0f) / std::max(weights, 1e-6f);
    for (int k = 0; k < cols && i < fig.charts.size(); ++k, ++i) {
      const ImVec2 min(margin + float(k) * (cw + hgap), y);
      draw_chart(fig.charts[i], min, ImVec2(min.x + cw, min.y + ch));
    }
    y += ch + vgap;
  }
  ImGui::End();
  ImGui::PopStyleVar();
}

}  // namespace mixpilot::ui
