#pragma once
// The app's plotter (SPEC §8 "Plots", §11 figures). Its pieces draw into an ImGui draw list:
// the mapping of a plot's data onto its pixels, polylines thinned to each pixel column's
// extremes (thousands of samples cost a few hundred points, and no spike is lost) and dashed
// lines. The window's rolling plots (ui/widgets.cpp) and the Progress panel's chart draw their
// curves with them; a Chart adds what a printed figure needs: axes with ticks and labels, a
// title, a legend above the curves (it never hides data), reference lines, shaded intervals,
// circles in data units, markers and violins. The thesis's figures (`mixpilot figures`) are
// Figures: a title and a grid of Charts, drawn on a white page.
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <imgui.h>

namespace mixpilot::ui {

// Where a plot's data [x0, x1] × [y0, y1] lies on screen: the rectangle [min, max).
struct PlotFrame {
  ImVec2 min, max;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;

  float px_x(double x) const { return float(min.x + (x - x0) / (x1 - x0) * (max.x - min.x)); }
  float px_y(double y) const { return float(max.y - (y - y0) / (y1 - y0) * (max.y - min.y)); }
  ImVec2 to_px(double x, double y) const { return ImVec2(px_x(x), px_y(y)); }
};

// One polyline through the points point(0) .. point(n − 1) (screen positions, x ascending
// within a run; a non-finite point breaks the line), thinned to the extremes of each pixel
// column in the order they occur.
template <class Point>
void stroke_thinned(ImDrawList* dl, std::size_t n, const Point& point, ImU32 colour, float width) {
  int column = -1;
  float y_lo = 0, y_hi = 0;
  bool lo_first = true;
  const auto flush = [&] {
    if (column < 0) return;
    const float a = lo_first ? y_lo : y_hi, b = lo_first ? y_hi : y_lo;
    dl->PathLineTo(ImVec2(float(column), a));
    if (b != a) dl->PathLineTo(ImVec2(float(column), b));
  };
  for (std::size_t i = 0; i < n; ++i) {
    const ImVec2 p = point(i);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      flush();
      column = -1;
      dl->PathStroke(colour, 0, width);
      continue;
    }
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
  dl->PathStroke(colour, 0, width);
}

// A dashed polyline through `points` (`on` pixels drawn, `off` left out, the pattern carried
// from one segment to the next); a non-finite point breaks it.
void stroke_dashed(ImDrawList* dl, std::span<const ImVec2> points, ImU32 colour, float width,
                   float on, float off);

// ---- Charts: printed figures ---------------------------------------------------------------

enum class Dash { solid, dashed, dotted };
enum class Marker { none, circle, square, diamond, triangle, cross, star };

// One series: a curve through (x[i], y[i]) (NaN: a gap), markers at its points, or both.
struct PlotLine {
  std::string label;  // in the legend; "" for none
  ImU32 colour = IM_COL32(0, 0, 0, 255);
  std::vector<double> x, y;
  Dash dash = Dash::solid;
  float width = 1.5f;      // [px at 100 %]; 0: no line, markers only
  Marker marker = Marker::none;
  float marker_size = 4.0f;  // half width [px at 100 %]
  // Points with a marker: every `marker_every`-th (1: all); the last point always has one when
  // `marker_last` (where a curve ends: a lost flight).
  int marker_every = 1;
  bool marker_last = false;
};

// A shaded interval of x (e.g. while a controller is active).
struct PlotBand {
  std::string label;
  ImU32 colour = IM_COL32(0, 0, 0, 40);
  double x0 = 0, x1 = 0;
};

// A circle of radius r in data units (the chart keeps equal aspect where it draws them): an
// obstacle seen from above.
struct PlotCircle {
  std::string label;  // in the legend (once per label)
  ImU32 colour = IM_COL32(0, 0, 0, 255);
  double x = 0, y = 0, r = 0;
  bool filled = true;  // tinted inside, outlined
};

// The distribution of `values` at x: a violin (a Gaussian kernel density estimate, mirrored,
// `half_width` wide at its mode) with a bar at the mean.
struct PlotViolin {
  std::string label;     // in the legend (once per label)
  std::string tick;      // under the x axis at x ("" for none)
  ImU32 colour = IM_COL32(0, 0, 0, 255);
  double x = 0;
  double half_width = 0.35;  // [x units]
  std::vector<double> values;
};

// Text at a data point: its left edge, centre or right edge at x, its middle at y.
struct PlotNote {
  enum class Anchor { left, centre, right };
  std::string text;
  ImU32 colour = IM_COL32(0, 0, 0, 255);
  double x = 0, y = 0;
  Anchor anchor = Anchor::left;
};

struct PlotAxis {
  std::string label;  // with its unit: "t [s]"
  // The range; NaN: from the data, padded.
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
  // Ticks at these values with these labels instead of evenly spaced numbers.
  std::vector<std::pair<double, std::string>> ticks;
  // A logarithmic axis (the y axis only): values ≤ 0 are left out, ticks at 1, 2 and 5 × 10^k.
  bool log = false;
};

struct Chart {
  std::string title;  // the panel's ("(a) step response"), "" for none
  PlotAxis x, y;
  std::vector<PlotBand> bands;
  std::vector<PlotCircle> circles;
  std::vector<PlotViolin> violins;
  std::vector<PlotLine> lines;  // drawn in order, over the bands, circles and violins
  std::vector<PlotNote> notes;
  bool equal_aspect = false;  // one metre is as long on both axes (paths seen from above)
};

struct Figure {
  std::string title;  // "Fig. 5.6 — ...", the page's heading
  std::string footer;  // small print under the charts ("" for none)
  int columns = 1;
  // Charts per row, top to bottom, where rows differ ({2, 1}: two side by side, one across
  // under them); empty: `columns` in every row.
  std::vector<int> rows;
  std::vector<float> row_heights;  // the rows' relative heights ({}: equal)
  std::vector<Chart> charts;       // row by row
};

// The page's colours: a figure is printed, so it is dark on white.
namespace figure_colour {
inline constexpr ImU32 rgb(unsigned r, unsigned g, unsigned b, unsigned a = 255) {
  return IM_COL32(r, g, b, a);
}
// Okabe–Ito (UI.md §9) on white; the app's roles keep their hues (pilot sky blue, MPC green,
// planner orange).
inline constexpr ImU32 kBlack = rgb(0, 0, 0);
inline constexpr ImU32 kBlue = rgb(0x00, 0x72, 0xB2);
inline constexpr ImU32 kOrange = rgb(0xE6, 0x9F, 0x00);
inline constexpr ImU32 kVermilion = rgb(0xD5, 0x5E, 0x00);
inline constexpr ImU32 kGreen = rgb(0x00, 0x9E, 0x73);
inline constexpr ImU32 kSky = rgb(0x56, 0xB4, 0xE9);
inline constexpr ImU32 kPurple = rgb(0xCC, 0x79, 0xA7);
inline constexpr ImU32 kGrey = rgb(0x77, 0x77, 0x77);
inline constexpr ImU32 kPage = rgb(0xFF, 0xFF, 0xFF);
inline constexpr ImU32 kText = rgb(0x11, 0x11, 0x11);
inline constexpr ImU32 kGrid = rgb(0xDD, 0xDD, 0xDD);
// `c` with alpha `a` (tints of a colour: bands, circles, violins).
inline constexpr ImU32 with_alpha(ImU32 c, unsigned a) {
  return (c & ~IM_COL32_A_MASK) | (ImU32(a) << IM_COL32_A_SHIFT);
}
}  // namespace figure_colour

// "Nice" tick positions (1, 2 or 5 × 10^k apart) inside [lo, hi], about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target);
// A tick's label with as many decimals as the spacing `step` needs ("0.25", "-1", "1e-05").
std::string tick_label(double value, double step);

// Draws `chart` into [min, max) of the current window (its axes, labels, legend and data).
void draw_chart(const Chart& chart, ImVec2 min, ImVec2 max);
// Draws `figure` as a full page over [0, display size): the heading (heading_font() where one
// is loaded), the charts in their grid, the footer.
void draw_figure(const Figure& figure);

// `text` drawn turned a quarter left (reading upwards), centred at `centre`: a y axis's label.
void add_text_upward(ImDrawList* dl, ImVec2 centre, ImU32 colour, const char* text);

}  // namespace mixpilot::ui
