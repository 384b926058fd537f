// The thesis's figures (SPEC §11): which flights each is drawn from, and its data and chart
// built from them. The flying, the tables and the rendering are app/figure_flights.cpp's.
#include "app/figures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <span>
#include <string>
#include <tuple>

#include "core/control/delay_margin.hpp"
#include "core/numerics/types.hpp"
#include "core/numerics/version.hpp"

namespace mixpilot::cli {
namespace {

namespace fc = ui::figure_colour;
using ui::Chart;
using ui::Dash;
using ui::Marker;
using ui::PlotLine;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = 180.0 / M_PI;

// ---- Reading flights ---------------------------------------------------------------------

double channel(const Telemetry& s, std::string_view name) {
  for (int i = 0; i < s.num_channels; ++i)
    if (name == s.channels[std::size_t(i)].name) return s.channels[std::size_t(i)].value;
  return kNaN;
}

template <class F>
std::vector<double> each(const FlownFlight& f, const F& value) {
  std::vector<double> v;
  v.reserve(f.steps.size());
  for (const Telemetry& s : f.steps) v.push_back(value(s));
  return v;
}

std::vector<double> times(const FlownFlight& f) {
  return each(f, [](const Telemetry& s) { return s.t; });
}

double min_of(const std::vector<double>& v) {
  double m = std::numeric_limits<double>::infinity();
  for (const double x : v)
    if (std::isfinite(x)) m = std::min(m, x);
  return m;
}
double max_of(const std::vector<double>& v) {
  double m = -std::numeric_limits<double>::infinity();
  for (const double x : v)
    if (std::isfinite(x)) m = std::max(m, x);
  return m;
}

std::vector<double> scaled(std::vector<double> v, double factor) {
  for (double& x : v) x *= factor;
  return v;
}

// ---- Building charts ---------------------------------------------------------------------

PlotLine line(std::string label, ImU32 colour, std::vector<double> x, std::vector<double> y,
              Dash dash = Dash::solid, float width = 1.6f) {
  PlotLine l;
  l.label = std::move(label);
  l.colour = colour;
  l.x = std::move(x);
  l.y = std::move(y);
  l.dash = dash;
  l.width = width;
  return l;
}

// A horizontal line at y over [x0, x1] (a bound, a radius).
PlotLine level(std::string label, ImU32 colour, double y, double x0, double x1,
               Dash dash = Dash::dashed, float width = 1.4f) {
  return line(std::move(label), colour, {x0, x1}, {y, y}, dash, width);
}

// An axis with its label; its range as given (NaN: from the data).
ui::PlotAxis axis(std::string label, double min = kNaN, double max = kNaN) {
  ui::PlotAxis a;
  a.label = std::move(label);
  a.min = min;
  a.max = max;
  return a;
}

// The time axis of a flight of `duration` seconds (533 steps of 15 ms end at 7.995 s: the axis
// ends at 8).
ui::PlotAxis time_axis(double duration) {
  return axis("t [s]", 0.0, std::ceil(duration * 10.0 - 1e-6) / 10.0);
}

// "Fig. 5.6 — title" (the page's heading) and the footer naming what flew.
void heading(ui::Figure& fig, const char* id, const char* title,
             const std::vector<const FlownFlight*>& flights) {
  fig.title = std::string("Fig. ") + id + " \u2014 " + title;
  std::set<std::string> scenarios;
  for (const FlownFlight* f : flights) scenarios.insert("scenarios/" + f->flight.scenario);
  std::string list;
  for (const std::string& s : scenarios) list += (list.empty() ? "" : ", ") + s;
  fig.footer = std::string(version()) + ", flown headless from " + list + " (mixpilot figures)";
}

// A time in milliseconds to 0.1 ms, shortest: "15", "22.5".
std::string ms(double seconds) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", std::round(seconds * 1e4) / 10.0);
  return buf;
}

// The intervals of t where `on` holds, as bands.
std::vector<ui::PlotBand> bands_where(const FlownFlight& f, const std::string& label, ImU32 colour,
                                      bool (*on)(const Telemetry&)) {
  std::vector<ui::PlotBand> out;
  double start = kNaN;
  for (std::size_t i = 0; i < f.steps.size(); ++i) {
    const bool here = on(f.steps[i]);
    if (here && std::isnan(start)) start = f.steps[i].t;
    if (!here && !std::isnan(start)) {
      out.push_back({label, colour, start, f.steps[i].t});
      start = kNaN;
    }
  }
  if (!std::isnan(start)) out.push_back({label, colour, start, f.steps.back().t + f.dt});
  return out;
}

// ---- Fig. 4.4: Pendubot swing-up ---------------------------------------------------------

std::vector<FigureFlight> pendubot_flights(FigureLength length) {
  FigureFlight f;
  f.scenario = "pendubot_swingup.toml";
  if (length == FigureLength::shortened) f.duration = 4.0;  // up before 2.5 s, then held
  return {f};
}

void pendubot_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig,
                    FigureTable& table) {
  const FlownFlight& f = *flights[0];
  heading(fig, "4.4", "Pendubot swing-up and balance: joint angles, velocities and torque", flights);
  table.header = {"t [s]",       "q1 [rad]",    "q2 [rad]",   "q1_reference [rad]",
                  "q2_reference [rad]", "dq1 [rad/s]", "dq2 [rad/s]", "u [N m]",
                  "lqr_active [0/1]"};
  for (const Telemetry& s : f.steps)
    table.add({cell(s.t), cell(s.x(0)), cell(s.x(1)), cell(s.reference(0)), cell(s.reference(1)),
               cell(s.x(2)), cell(s.x(3)), cell(s.u(0)), cell(channel(s, "LQR active"))});
  const std::vector<double> t = times(f);
  const double T = f.duration;
  const auto lqr = bands_where(f, "LQR balancing (else NMPC)", fc::with_alpha(fc::kGrey, 45),
                               [](const Telemetry& s) { return channel(s, "LQR active") > 0.5; });
  const Telemetry& s0 = f.steps.front();
  const double dq1_max = channel(s0, "dq1 bound"), dq2_max = channel(s0, "dq2 bound");
  const double u_max = channel(s0, "torque bound");

  Chart angles;
  angles.title = "(a) joint angles";
  angles.x = time_axis(T);
  angles.y = axis("angle [rad]");
  angles.bands = lqr;
  angles.lines = {
      line("q\u2081", fc::kBlue, t, each(f, [](const Telemetry& s) { return s.x(0); })),
      line("q\u2082", fc::kVermilion, t, each(f, [](const Telemetry& s) { return s.x(1); })),
      line("q\u2081 reference", fc::kBlue, t,
           each(f, [](const Telemetry& s) { return s.reference(0); }), Dash::dashed, 1.2f),
      line("q\u2082 reference", fc::kVermilion, t,
           each(f, [](const Telemetry& s) { return s.reference(1); }), Dash::dashed, 1.2f)};

  Chart velocities;
  velocities.title = "(b) joint velocities and their soft bounds";
  velocities.x = time_axis(T);
  velocities.y = axis("velocity [rad/s]");
  velocities.bands = lqr;
  velocities.lines = {
      line("dq\u2081/dt", fc::kBlue, t, each(f, [](const Telemetry& s) { return s.x(2); })),
      line("dq\u2082/dt", fc::kVermilion, t, each(f, [](const Telemetry& s) { return s.x(3); })),
      level("\u00b1" + cell(dq1_max) + " rad/s (dq\u2081/dt)", fc::kBlue, dq1_max, 0, T),
      level("", fc::kBlue, -dq1_max, 0, T),
      level("\u00b1" + cell(dq2_max) + " rad/s (dq\u2082/dt)", fc::kVermilion, dq2_max, 0, T,
            Dash::dotted, 1.8f),
      level("", fc::kVermilion, -dq2_max, 0, T, Dash::dotted, 1.8f)};

  Chart torque;
  torque.title = "(c) shoulder torque";
  torque.x = time_axis(T);
  torque.y = axis("u [N\u00b7m]");
  torque.bands = lqr;
  torque.lines = {line("u", fc::kGreen, t, each(f, [](const Telemetry& s) { return s.u(0); })),
                  level("\u00b1" + cell(u_max) + " N\u00b7m bound", fc::kBlack, u_max, 0, T),
                  level("", fc::kBlack, -u_max, 0, T)};
  fig.columns = 1;
  fig.charts = {angles, velocities, torque};
}

// ---- Tracking under delay (Figs. 5.3 – 5.6) -------------------------------------------------

FigureFlight tracking(const char* scenario, double rtt, bool predictor) {
  FigureFlight f;
  f.scenario = scenario;
  // The shipped scenarios fly RTT 60 ms with the predictor: that flight is the shipped file.
  if (rtt != 0.06) f.keys.push_back({"plant.rtt", cell(rtt)});
  if (!predictor) f.keys.push_back({"controller.compensation", "false"});
  return f;
}

constexpr const char* kStep = "tracking_smooth_step.toml";
constexpr const char* kHelix = "tracking_helix.toml";

double rtt_of(const FlownFlight& f) { return f.metric("rtt_s"); }
bool predictor_of(const FlownFlight& f) { return f.metric("compensation") > 0.5; }

Eigen::Vector3d position(const Telemetry& s) { return s.x.head<3>(); }
double error_of(const Telemetry& s) { return (s.x.head<3>() - s.reference.head<3>()).norm(); }

void tracking_header(FigureTable& table) {
  table.header = {"t [s]", "x [m]", "y [m]", "z [m]", "x_reference [m]", "y_reference [m]",
                  "z_reference [m]", "error [m]"};
}
void tracking_rows(const FlownFlight& f, FigureTable& table) {
  for (const Telemetry& s : f.steps)
    table.add({cell(s.t), cell(s.x(0)), cell(s.x(1)), cell(s.x(2)), cell(s.reference(0)),
               cell(s.reference(1)), cell(s.reference(2)), cell(error_of(s))});
}

// Positions against the reference over time.
Chart positions_chart(const FlownFlight& f, const char* title) {
  const std::vector<double> t = times(f);
  Chart c;
  c.title = title;
  c.x = time_axis(f.duration);
  c.y = axis("position [m]");
  const char* names[3] = {"x", "y", "z"};
  const ImU32 colours[3] = {fc::kBlue, fc::kVermilion, fc::kGreen};
  for (int i = 0; i < 3; ++i)
    c.lines.push_back(line(names[i], colours[i], t, each(f, [i](const Telemetry& s) { return s.x(i); })));
  for (int i = 0; i < 3; ++i)
    c.lines.push_back(line("reference", fc::kBlack, t,
                           each(f, [i](const Telemetry& s) { return s.reference(i); }), Dash::dashed,
                           1.2f));
  return c;
}

std::string delay_words(const FlownFlight& f) {
  return "RTT " + ms(rtt_of(f)) + " ms, predictor " + (predictor_of(f) ? "on" : "off");
}

std::vector<FigureFlight> step_flights(FigureLength) { return {tracking(kStep, 0.06, true)}; }

void step_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  const FlownFlight& f = *flights[0];
  heading(fig, "5.3", ("Smooth step from hover (0, 0, 0.4) to (1, \u22121, 1) m: " + delay_words(f)).c_str(),
          flights);
  tracking_header(table);
  tracking_rows(f, table);
  Chart err;
  err.title = "(b) tracking error \u2016p \u2212 p_ref\u2016";
  err.x = time_axis(f.duration);
  err.y = axis("error [cm]", 0.0);
  err.lines = {line("error", fc::kBlue, times(f), scaled(each(f, error_of), 100.0))};
  fig.columns = 2;
  fig.charts = {positions_chart(f, "(a) position against the Ipopt reference"), err};
}

std::vector<FigureFlight> helix_flights(FigureLength length) {
  FigureFlight f = tracking(kHelix, 0.06, true);
  if (length == FigureLength::shortened) f.duration = 6.0;
  return {f};
}

// Coordinate i of each step's position (or of its reference): a path seen along an axis.
std::vector<double> coordinate(const FlownFlight& f, int i, bool reference = false) {
  return each(f, [i, reference](const Telemetry& s) { return reference ? s.reference(i) : s.x(i); });
}

// A direction positions are seen along on one axis of a view, and the axis's label.
struct Axis3 {
  Eigen::Vector3d dir;
  const char* label;
};
const Axis3 kX{Eigen::Vector3d::UnitX(), "x [m]"};
const Axis3 kY{Eigen::Vector3d::UnitY(), "y [m]"};
const Axis3 kZ{Eigen::Vector3d::UnitZ(), "z [m]"};
// Across the obstacle scenarios' paths (from (0, 0) towards (1, −1)): their side view.
const Axis3 kAlong{Eigen::Vector3d(M_SQRT1_2, -M_SQRT1_2, 0.0), "along (1, \u22121, 0)/\u221a2 [m]"};

std::vector<double> seen(const FlownFlight& f, const Axis3& a, bool reference = false) {
  return each(f, [&a, reference](const Telemetry& s) {
    return a.dir.dot(reference ? Eigen::Vector3d(s.reference.head<3>()) : Eigen::Vector3d(s.x.head<3>()));
  });
}

void helix_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  const FlownFlight& f = *flights[0];
  heading(fig, "5.4", ("Helix of radius 0.3 m, 2 mm up per 15 ms: " + delay_words(f)).c_str(), flights);
  tracking_header(table);
  tracking_rows(f, table);
  Chart top;
  top.title = "(a) path seen from above";
  top.x = axis("x [m]");
  top.y = axis("y [m]");
  top.equal_aspect = true;
  PlotLine path = line("flown (\u25cf its start)", fc::kBlue, coordinate(f, 0), coordinate(f, 1));
  path.marker = Marker::circle;
  path.marker_every = std::numeric_limits<int>::max();  // the start only
  path.marker_size = 5.0f;
  top.lines = {line("reference", fc::kBlack, coordinate(f, 0, true), coordinate(f, 1, true),
                    Dash::dashed, 1.2f),
               path};
  top.notes = {{"start", fc::kBlue, f.steps.front().x(0) + 0.03, f.steps.front().x(1)}};
  Chart err;
  err.title = "(c) tracking error \u2016p \u2212 p_ref\u2016";
  err.x = time_axis(f.duration);
  err.y = axis("error [cm]", 0.0);
  err.lines = {line("error", fc::kBlue, times(f), scaled(each(f, error_of), 100.0))};
  fig.columns = 3;
  fig.charts = {top, positions_chart(f, "(b) position against the reference"), err};
}

// Fig. 5.5: the predictor on and off, inside the delay margin (15 ms) and at the real setup's
// 60 ms.
std::vector<FigureFlight> predictor_flights(FigureLength length) {
  std::vector<FigureFlight> out;
  for (const char* sc : {kStep, kHelix}) {
    for (const double rtt : {0.015, 0.06}) {
      for (const bool on : {false, true}) {
        FigureFlight f = tracking(sc, rtt, on);
        if (length == FigureLength::shortened && sc == kHelix) f.duration = 6.0;
        out.push_back(f);
      }
    }
  }
  return out;
}

void predictor_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig,
                     FigureTable& table) {
  heading(fig, "5.5", "Tracking with and without the delay predictor", flights);
  table.header = {"reference", "rtt [ms]", "predictor", "t [s]", "error [m]", "lost [0/1]"};
  fig.columns = 1;
  for (int r = 0; r < 2; ++r) {
    Chart c;
    c.title = r == 0 ? "(a) smooth step" : "(b) helix";
    c.y = axis("error \u2016p \u2212 p_ref\u2016 [cm]", 0.0);
    double top = 0, end = 0;
    for (int k = 0; k < 4; ++k) {
      const FlownFlight& f = *flights[std::size_t(4 * r + k)];
      end = std::max(end, f.duration);
      if (!f.lost) top = std::max(top, 100.0 * max_of(each(f, error_of)));
    }
    c.y.max = 1.4 * top;  // room for the note above the curves
    c.x = time_axis(end);
    for (int k = 0; k < 4; ++k) {
      const FlownFlight& f = *flights[std::size_t(4 * r + k)];
      for (const Telemetry& s : f.steps)
        table.add({r == 0 ? "step" : "helix", ms(rtt_of(f)), predictor_of(f) ? "on" : "off",
                   cell(s.t), cell(error_of(s)), f.lost ? "1" : "0"});
      const bool on = predictor_of(f), late = rtt_of(f) > 0.03;
      const ImU32 colour = on ? (late ? fc::kGreen : fc::kBlue) : (late ? fc::kPurple : fc::kVermilion);
      PlotLine l = line(delay_words(f) + (f.lost ? ": vehicle lost" : ""), colour, times(f),
                        scaled(each(f, error_of), 100.0), on && late ? Dash::dashed : Dash::solid,
                        on && late ? 2.2f : 1.6f);
      if (f.lost) {
        char note[96];
        std::snprintf(note, sizeof note,
                      "\u2190 RTT %s ms without the predictor diverges (lost, 100 m away, at %.1f s)",
                      ms(rtt_of(f)).c_str(), f.lost_at);
        // Where the curve leaves the chart.
        double leaves = f.steps.back().t;
        for (const Telemetry& s : f.steps)
          if (100.0 * error_of(s) > c.y.max) {
            leaves = s.t;
            break;
          }
        c.notes.push_back({note, colour, leaves + 0.02 * end, 0.92 * c.y.max});
      }
      c.lines.push_back(std::move(l));
    }
    fig.charts.push_back(std::move(c));
  }
}

// Fig. 5.6 as SPEC §5.2 decides: RMS error and settling time of the smooth step against the
// RTT, the predictor off (from 0 to past the margin) and on.
const double kRttsOff[] = {0.0, 0.003, 0.006, 0.009, 0.012, 0.015, 0.018, 0.021, 0.024, 0.027,
                           0.030, 0.036, 0.045, 0.060};
const double kRttsOn[] = {0.0, 0.015, 0.030, 0.045, 0.060};
const double kRttsOffShort[] = {0.0, 0.006, 0.012, 0.015, 0.018, 0.021, 0.024, 0.030};
const double kRttsOnShort[] = {0.0, 0.030};

std::vector<FigureFlight> rtt_flights(FigureLength length) {
  const bool full = length == FigureLength::thesis;
  std::vector<FigureFlight> out;
  for (const double rtt : full ? std::span<const double>(kRttsOff) : std::span<const double>(kRttsOffShort))
    out.push_back(tracking(kStep, rtt, false));
  for (const double rtt : full ? std::span<const double>(kRttsOn) : std::span<const double>(kRttsOnShort))
    out.push_back(tracking(kStep, rtt, true));
  return out;
}

void rtt_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "5.6", "Smooth step against the round-trip time: the predictor off, and on", flights);
  table.header = {"rtt [ms]", "predictor", "rms_error [m]", "settle_time [s]", "overshoot [m]",
                  "lost [0/1]", "lost_at [s]"};
  for (const FlownFlight* f : flights)
    table.add({ms(rtt_of(*f)), predictor_of(*f) ? "on" : "off", cell(f->metric("tracking_rms_m")),
               f->lost ? "nan" : cell(f->metric("settle_time_s")), cell(f->metric("overshoot_m")),
               f->lost ? "1" : "0", f->lost ? cell(f->lost_at) : "nan"});
  const double margin = linearized_delay_margin();
  double rtt_end = 0, first_lost = kNaN;
  for (const FlownFlight* f : flights) {
    rtt_end = std::max(rtt_end, 1e3 * rtt_of(*f));
    if (f->lost && !predictor_of(*f) && !(1e3 * rtt_of(*f) >= first_lost))
      first_lost = 1e3 * rtt_of(*f);
  }
  const auto chart = [&](const std::string& title, const char* ylabel, const char* metric, double factor,
                         bool log) {
    Chart c;
    c.title = title;
    c.x = axis("round-trip time [ms]", -1.0, rtt_end + 2.0);
    c.y = axis(ylabel, log ? kNaN : 0.0);
    c.y.log = log;
    double top = 0, bottom = std::numeric_limits<double>::infinity();
    for (const FlownFlight* f : flights) {
      if (f->lost) continue;
      top = std::max(top, factor * f->metric(metric));
      bottom = std::min(bottom, factor * f->metric(metric));
    }
    // Room above the curves for the losses' crosses.
    c.y.max = log ? 3.0 * top : 1.3 * top;
    if (log) c.y.min = 0.6 * bottom;
    const double lost_y = log ? 1.9 * top : 1.2 * top;
    for (const bool on : {false, true}) {
      PlotLine flew = line(on ? "predictor on" : "predictor off", on ? fc::kBlue : fc::kVermilion, {}, {});
      flew.marker = on ? Marker::square : Marker::circle;
      PlotLine lost = line("predictor off: vehicle lost", fc::kVermilion, {}, {});
      lost.width = 0;
      lost.marker = Marker::cross;
      lost.marker_size = 6.0f;
      for (const FlownFlight* f : flights) {
        if (predictor_of(*f) != on) continue;
        if (f->lost) {
          lost.x.push_back(1e3 * rtt_of(*f));
          lost.y.push_back(lost_y);
        } else {
          flew.x.push_back(1e3 * rtt_of(*f));
          flew.y.push_back(factor * f->metric(metric));
        }
      }
      c.lines.push_back(std::move(flew));
      if (!lost.x.empty()) c.lines.push_back(std::move(lost));
    }
    if (!std::isnan(first_lost))
      c.bands.push_back({"", fc::with_alpha(fc::kVermilion, 28), first_lost - 1.5, rtt_end + 2.0});
    c.lines.push_back(line("linearized delay margin " + ms(margin) + " ms (predictor off)",
                           fc::kBlack, {1e3 * margin, 1e3 * margin}, {log ? c.y.min : 0.0, c.y.max}, Dash::dashed,
                           1.4f));
    return c;
  };
  fig.columns = 2;
  fig.charts = {chart("(a) RMS tracking error (logarithmic)", "RMS error [cm]", "tracking_rms_m", 100.0, true),
                chart("(b) settling time (within " + cell(100.0 * tracking_defaults::kSettleRadius) +
                          " cm of the target for good)",
                      "settling time [s]", "settle_time_s", 1.0, false)};
}

// ---- Obstacle avoidance (Figs. 6.4 – 6.6) --------------------------------------------------

constexpr const char* kBalls = "obstacles_thrown_balls.toml";
constexpr const char* kCluttered = "obstacles_cluttered.toml";

std::vector<FigureFlight> obstacle_pair(const char* scenario) {
  FigureFlight lcl, squared;
  lcl.scenario = squared.scenario = scenario;
  squared.keys.push_back({"controller.constraint_form", "\"squared\""});
  return {lcl, squared};
}
std::vector<FigureFlight> balls_flights(FigureLength) { return obstacle_pair(kBalls); }
std::vector<FigureFlight> cluttered_flights(FigureLength) { return obstacle_pair(kCluttered); }

const char* form_of(const FlownFlight& f) { return f.metric("form") > 0.5 ? "squared" : "lcl"; }
const char* form_words(const FlownFlight& f) {
  return f.metric("form") > 0.5 ? "squared: \u2016p \u2212 o\u2016\u00b2 \u2265 d_C\u00b2"
                                : "LCL: \u2016p \u2212 o\u2016 \u2265 d_C";
}
ImU32 form_colour(const FlownFlight& f) { return f.metric("form") > 0.5 ? fc::kBlue : fc::kOrange; }

// The balls' centres at every step of `f` (ball j at step k: out[j][k]).
std::vector<std::vector<Eigen::Vector3d>> balls_of(const FlownFlight& f) {
  std::vector<std::vector<Eigen::Vector3d>> out;
  if (!f.view.moving) return out;
  std::vector<Eigen::Vector3d> c;
  for (const Telemetry& s : f.steps) {
    f.view.moving(s.t, c);
    if (out.empty()) out.resize(c.size());
    for (std::size_t j = 0; j < c.size() && j < out.size(); ++j) out[j].push_back(c[j]);
  }
  return out;
}

// The paths of both forms and the reference seen along the axes (a, b); the view frames them
// and the circles later added within `frame` (what flies past, the balls, may leave it).
Chart obstacle_view(const std::vector<const FlownFlight*>& flights, const Axis3& a, const Axis3& b,
                    const char* title) {
  const FlownFlight& first = *flights[0];
  Chart c;
  c.title = title;
  c.x = axis(a.label);
  c.y = axis(b.label);
  c.equal_aspect = true;
  for (const FlownFlight* f : flights)
    c.lines.push_back(line(form_words(*f), form_colour(*f), seen(*f, a), seen(*f, b), Dash::solid, 1.8f));
  c.lines.push_back(line("reference", fc::kBlack, seen(first, a, true), seen(first, b, true), Dash::dashed, 1.2f));
  const Eigen::Vector3d goal_at = first.steps.back().reference.head<3>(), start_at = first.steps.front().x.head<3>();
  PlotLine start = line("start", fc::kBlack, {a.dir.dot(start_at)}, {b.dir.dot(start_at)});
  start.width = 0;
  start.marker = Marker::circle;
  PlotLine goal = line("goal", fc::kBlack, {a.dir.dot(goal_at)}, {b.dir.dot(goal_at)});
  goal.width = 0;
  goal.marker = Marker::star;
  goal.marker_size = 7.0f;
  c.lines.push_back(start);
  c.lines.push_back(goal);
  return c;
}

// Frames `c` around its paths (every line but those `before` the first path) and its circles,
// `margin` metres beyond them.
void frame_paths(Chart& c, std::size_t first_path, double margin) {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (std::size_t i = first_path; i < c.lines.size(); ++i)
    for (std::size_t k = 0; k < c.lines[i].x.size(); ++k) {
      x0 = std::min(x0, c.lines[i].x[k]);
      x1 = std::max(x1, c.lines[i].x[k]);
      y0 = std::min(y0, c.lines[i].y[k]);
      y1 = std::max(y1, c.lines[i].y[k]);
    }
  for (const ui::PlotCircle& o : c.circles) {
    x0 = std::min(x0, o.x - o.r);
    x1 = std::max(x1, o.x + o.r);
    y0 = std::min(y0, o.y - o.r);
    y1 = std::max(y1, o.y + o.r);
  }
  c.x.min = x0 - margin;
  c.x.max = x1 + margin;
  c.y.min = y0 - margin;
  c.y.max = y1 + margin;
}

void obstacle_path_rows(const FlownFlight& f, FigureTable& table,
                        const std::vector<std::vector<Eigen::Vector3d>>& balls) {
  for (std::size_t k = 0; k < f.steps.size(); ++k) {
    const Telemetry& s = f.steps[k];
    std::vector<std::string> row = {form_of(f), cell(s.t), cell(s.x(0)), cell(s.x(1)), cell(s.x(2)),
                                    cell(s.reference(0)), cell(s.reference(1)), cell(s.reference(2))};
    for (const auto& ball : balls)
      for (int i = 0; i < 3; ++i) row.push_back(cell(ball[k](i)));
    table.add(std::move(row));
  }
}

void balls_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "6.4", "Two balls thrown at the Crazyflie: LCL against the squared constraint", flights);
  const double dc = flights[0]->metric("clearance_m");
  const auto balls = balls_of(*flights[0]);
  table.header = {"form", "t [s]", "x [m]", "y [m]", "z [m]", "x_reference [m]", "y_reference [m]",
                  "z_reference [m]"};
  for (std::size_t j = 0; j < balls.size(); ++j)
    for (const char* axis_name : {"x", "y", "z"})
      table.header.push_back("ball" + std::to_string(j + 1) + "_" + axis_name + " [m]");
  for (const FlownFlight* f : flights) obstacle_path_rows(*f, table, balls);
  fig.columns = 2;
  const struct {
    Axis3 a, b;
    const char* title;
  } views[] = {{kX, kY, "(a) seen from above"}, {kAlong, kZ, "(b) seen from the side, across the path"}};
  for (const auto& v : views) {
    Chart c = obstacle_view(flights, v.a, v.b, v.title);
    // Each ball's flight (dotted), and the ball where it comes closest to the LCL path, with
    // its clearance sphere d_C.
    std::vector<PlotLine> flights_of_balls;
    for (std::size_t j = 0; j < balls.size(); ++j) {
      std::vector<double> bx, by;
      std::size_t closest = 0;
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < balls[j].size(); ++k) {
        bx.push_back(v.a.dir.dot(balls[j][k]));
        by.push_back(v.b.dir.dot(balls[j][k]));
        const double d = (position(flights[0]->steps[k]) - balls[j][k]).norm();
        if (d < best) {
          best = d;
          closest = k;
        }
      }
      flights_of_balls.push_back(line("a ball's flight", fc::kVermilion, bx, by, Dash::dotted, 1.8f));
      const double cx = v.a.dir.dot(balls[j][closest]), cy = v.b.dir.dot(balls[j][closest]);
      c.circles.push_back({"a ball at its closest, its d_C = " + cell(dc) + " m sphere", fc::kVermilion, cx,
                           cy, dc, true});
      char label[32];
      std::snprintf(label, sizeof label, "b%zu at %.2f s", j + 1, flights[0]->steps[closest].t);
      // Above the first ball, below the second: their spheres may nearly touch.
      c.notes.push_back({label, fc::kVermilion, cx, j % 2 == 0 ? cy + dc + 0.06 : cy - dc - 0.06,
                         ui::PlotNote::Anchor::centre});
    }
    frame_paths(c, 0, 0.16);
    c.lines.insert(c.lines.end(), flights_of_balls.begin(), flights_of_balls.end());
    fig.charts.push_back(std::move(c));
  }
}

void cluttered_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig,
                     FigureTable& table) {
  heading(fig, "6.5", "A cluttered arena of static spheres: LCL against the squared constraint", flights);
  const double dc = flights[0]->metric("clearance_m");
  const std::vector<ViewSphere>& spheres = flights[0]->view.spheres;
  const auto nearest = [&](const Telemetry& s) {
    double d = std::numeric_limits<double>::infinity();
    for (const ViewSphere& o : spheres) d = std::min(d, (position(s) - o.center).norm());
    return d;
  };
  table.header = {"form", "t [s]", "x [m]", "y [m]", "z [m]", "x_reference [m]", "y_reference [m]",
                  "z_reference [m]", "nearest_obstacle [m]", "d_C [m]"};
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps)
      table.add({form_of(*f), cell(s.t), cell(s.x(0)), cell(s.x(1)), cell(s.x(2)), cell(s.reference(0)),
                 cell(s.reference(1)), cell(s.reference(2)), cell(nearest(s)), cell(dc)});
  fig.rows = {2, 1};
  fig.row_heights = {1.6f, 1.0f};
  const struct {
    Axis3 a, b;
    const char* title;
  } views[] = {{kX, kY, "(a) seen from above"}, {kAlong, kZ, "(b) seen from the side, across the path"}};
  for (const auto& v : views) {
    Chart c = obstacle_view(flights, v.a, v.b, v.title);
    for (const ViewSphere& o : spheres)
      c.circles.push_back({"obstacle: its d_C sphere, projected", fc::kVermilion,
                           v.a.dir.dot(o.center), v.b.dir.dot(o.center), dc, true});
    frame_paths(c, 0, 0.05);
    fig.charts.push_back(std::move(c));
  }
  Chart d;
  d.title = "(c) distance to the nearest obstacle (d_C = " + cell(dc) + " m)";
  d.x = time_axis(flights[0]->duration);
  double least = dc;
  for (const FlownFlight* f : flights) least = std::min(least, min_of(each(*f, nearest)));
  d.y = axis("distance [m]", least - 0.01);
  for (const FlownFlight* f : flights)
    d.lines.push_back(line(form_of(*f) == std::string("lcl") ? "LCL" : "squared", form_colour(*f), times(*f),
                           each(*f, nearest), Dash::solid, 1.8f));
  d.lines.push_back(level("d_C = " + cell(dc) + " m", fc::kBlack, dc, 0.0, flights[0]->duration));
  fig.charts.push_back(std::move(d));
}

void distances_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig,
                     FigureTable& table) {
  heading(fig, "6.6", "Distance between the Crazyflie and the thrown balls b\u2081, b\u2082", flights);
  const double dc = flights[0]->metric("clearance_m");
  // The mode's least distance over the flight at every 1 kHz plant step (between the control
  // instants too), per form: where the forms differ (below a millimetre).
  table.header = {"form", "t [s]", "distance_ball1 [m]", "distance_ball2 [m]", "d_C [m]",
                  "least_distance_1khz [m]"};
  struct Dist {
    const FlownFlight* f;
    std::vector<double> d[2];
  };
  std::vector<Dist> all;
  for (const FlownFlight* f : flights) {
    const auto balls = balls_of(*f);
    Dist dist{f, {}};
    for (std::size_t k = 0; k < f->steps.size(); ++k) {
      std::vector<std::string> row = {form_of(*f), cell(f->steps[k].t)};
      for (std::size_t j = 0; j < 2; ++j) {
        const double d = j < balls.size() ? (position(f->steps[k]) - balls[j][k]).norm() : kNaN;
        dist.d[j].push_back(d);
        row.push_back(cell(d));
      }
      row.push_back(cell(dc));
      row.push_back(cell(f->metric("min_distance_m")));
      table.add(std::move(row));
    }
    all.push_back(std::move(dist));
  }
  const double T = flights[0]->duration;
  const auto lines_into = [&](Chart& c, double x0, double x1, int only) {
    for (const Dist& d : all)
      for (int j = 0; j < 2; ++j)
        if (only < 0 || only == j)
          c.lines.push_back(line((form_of(*d.f) == std::string("lcl") ? "LCL, " : "squared, ") +
                                     std::string(j == 0 ? "b\u2081" : "b\u2082"),
                                 form_colour(*d.f), times(*d.f), d.d[j], j == 0 ? Dash::solid : Dash::dashed,
                                 1.8f));
    c.lines.push_back(level("d_C = " + cell(dc) + " m", fc::kBlack, dc, x0, x1, Dash::dotted, 2.0f));
  };
  Chart whole;
  whole.title = "(a) the flight (a ball, once past, falls away)";
  whole.x = time_axis(T);
  whole.y = axis("distance [m]", 0.0, 2.0);
  lines_into(whole, 0.0, T, -1);
  {
    char note[160];
    std::snprintf(note, sizeof note,
                  "least distance at the 1 kHz plant steps: LCL %.5f m, squared %.5f m",
                  flights[0]->metric("min_distance_m"), flights[1]->metric("min_distance_m"));
    whole.notes.push_back({note, fc::kText, 0.98 * T, 1.85, ui::PlotNote::Anchor::right});
  }
  fig.rows = {1, 2};
  fig.charts = {whole};
  // Each ball's closest approach, zoomed (the thesis's inset): ±0.15 s around the least
  // distance of either form.
  for (int j = 0; j < 2; ++j) {
    double t_min = 0, d_min = std::numeric_limits<double>::infinity();
    for (const Dist& d : all)
      for (std::size_t k = 0; k < d.d[j].size(); ++k)
        if (d.d[j][k] < d_min) {
          d_min = d.d[j][k];
          t_min = d.f->steps[k].t;
        }
    Chart zoom;
    zoom.title = std::string(j == 0 ? "(b) b\u2081" : "(c) b\u2082") + "'s closest approach";
    zoom.x = axis("t [s]", t_min - 0.15, t_min + 0.15);
    zoom.y = axis("distance [m]", std::min(dc, d_min) - 0.01, dc + 0.1);
    lines_into(zoom, t_min - 0.15, t_min + 0.15, j);
    fig.charts.push_back(std::move(zoom));
  }
}

// ---- Mixed initiative (Figs. 7.5 – 7.9) ---------------------------------------------------

constexpr const char* kHelixMi = "mi_helix.toml";

FigureFlight mi(const char* pilot, int n_b, FigureLength length) {
  FigureFlight f;
  f.scenario = kHelixMi;
  f.pilot = pilot;
  if (n_b != 10) f.keys.push_back({"controller.ph.N_b", std::to_string(n_b)});
  if (length == FigureLength::shortened) f.duration = 12.0;
  f.timed = true;  // Fig. 7.9's RTI times come from these flights too
  return f;
}

std::vector<FigureFlight> pilots_flights(FigureLength length) {
  return {mi("novice", 10, length), mi("experienced", 10, length)};
}

ImU32 pilot_colour(const FlownFlight& f) { return f.flight.pilot == "novice" ? fc::kBlue : fc::kVermilion; }

void paths_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "7.5", "Mixed-initiative flights among obstacles: a novice and an experienced pilot", flights);
  table.header = {"pilot", "t [s]", "x [m]", "y [m]", "z [m]", "x_reference [m]", "y_reference [m]",
                  "z_reference [m]"};
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps)
      table.add({f->flight.pilot, cell(s.t), cell(s.x(0)), cell(s.x(1)), cell(s.x(2)), cell(s.reference(0)),
                 cell(s.reference(1)), cell(s.reference(2))});
  fig.columns = 2;
  for (const auto& [a, b, title] : {std::tuple{0, 1, "(a) seen from above"}, std::tuple{0, 2, "(b) seen from the side"}}) {
    const char* names[3] = {"x [m]", "y [m]", "z [m]"};
    Chart c;
    c.title = title;
    c.x = axis(names[a]);
    c.y = axis(names[b]);
    c.equal_aspect = true;
    for (const ViewSphere& o : flights[0]->view.spheres)
      c.circles.push_back({"obstacle", fc::kPurple, o.center(a), o.center(b), o.radius, true});
    c.lines.push_back(line("reference", fc::kBlack, coordinate(*flights[0], a, true),
                           coordinate(*flights[0], b, true), Dash::dashed, 1.2f));
    for (const FlownFlight* f : flights)
      c.lines.push_back(line(f->flight.pilot + " pilot", pilot_colour(*f), coordinate(*f, a), coordinate(*f, b),
                             Dash::solid, 1.6f));
    const Telemetry& last = flights[0]->steps.back();
    PlotLine start = line("start", fc::kBlack, {flights[0]->steps.front().x(a)}, {flights[0]->steps.front().x(b)});
    start.width = 0;
    start.marker = Marker::circle;
    PlotLine goal = line("goal", fc::kBlack, {last.reference(a)}, {last.reference(b)});
    goal.width = 0;
    goal.marker = Marker::star;
    goal.marker_size = 7.0f;
    c.lines.push_back(start);
    c.lines.push_back(goal);
    fig.charts.push_back(std::move(c));
  }
}

void attitude_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "7.6", "Pilot inputs and the mixed-initiative NMPC's commands (stage 1)", flights);
  table.header = {"pilot", "t [s]", "roll_pilot [deg]", "roll_mpc [deg]", "pitch_pilot [deg]",
                  "pitch_mpc [deg]"};
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps)
      table.add({f->flight.pilot, cell(s.t), cell(kDeg * s.pilot.roll), cell(kDeg * s.applied.roll),
                 cell(kDeg * s.pilot.pitch), cell(kDeg * s.applied.pitch)});
  fig.columns = 2;
  char letter = 'a';
  for (const FlownFlight* f : flights) {
    for (const bool roll : {true, false}) {
      Chart c;
      c.title = std::string("(") + letter++ + ") " + f->flight.pilot + " pilot: " + (roll ? "roll \u03c6" : "pitch \u03b8");
      c.x = time_axis(f->duration);
      c.y = axis(roll ? "\u03c6 [deg]" : "\u03b8 [deg]");
      c.lines = {line(roll ? "pilot \u03c6_h" : "pilot \u03b8_h", fc::kSky, times(*f),
                      each(*f, [roll](const Telemetry& s) { return kDeg * (roll ? s.pilot.roll : s.pilot.pitch); }),
                      Dash::solid, 2.4f),
                 line(roll ? "MPC \u03c6*\u2081" : "MPC \u03b8*\u2081", fc::kGreen, times(*f),
                      each(*f, [roll](const Telemetry& s) { return kDeg * (roll ? s.applied.roll : s.applied.pitch); }),
                      Dash::solid, 1.4f)};
      fig.charts.push_back(std::move(c));
    }
  }
  // What the MPC changed: the pilot's command minus the MPC's, on one scale for both pilots.
  double span = 0;
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps)
      span = std::max({span, std::abs(kDeg * (s.pilot.roll - s.applied.roll)),
                       std::abs(kDeg * (s.pilot.pitch - s.applied.pitch))});
  for (const FlownFlight* f : flights) {
    Chart c;
    c.title = std::string("(") + letter++ + ") " + f->flight.pilot + " pilot: the MPC's correction";
    c.x = time_axis(f->duration);
    c.y = axis("pilot \u2212 MPC [deg]", -1.08 * span, 1.08 * span);
    c.lines = {line("roll \u03c6_h \u2212 \u03c6*\u2081", fc::kBlue, times(*f),
                    each(*f, [](const Telemetry& s) { return kDeg * (s.pilot.roll - s.applied.roll); })),
               line("pitch \u03b8_h \u2212 \u03b8*\u2081", fc::kVermilion, times(*f),
                    each(*f, [](const Telemetry& s) { return kDeg * (s.pilot.pitch - s.applied.pitch); }))};
    fig.charts.push_back(std::move(c));
  }
}

double deviation_of(const Telemetry& s) { return channel(s, "deviation"); }

void authority_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "7.7", "Deviation from the reference against r, and the PH index \u03bb", flights);
  table.header = {"pilot", "t [s]", "deviation [m]", "r [m]", "lambda [-]"};
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps)
      table.add({f->flight.pilot, cell(s.t), cell(deviation_of(s)), cell(channel(s, "ball radius r")),
                 cell(s.lambda)});
  const double T = flights[0]->duration, r = channel(flights[0]->steps.front(), "ball radius r");
  Chart dev;
  dev.title = "(a) distance to the reference \u2016p \u2212 \u03b7^r\u2016";
  dev.x = time_axis(T);
  dev.y = axis("distance [m]", 0.0);
  Chart lam;
  lam.title = "(b) predicted healthiness index \u03bb";
  lam.x = time_axis(T);
  lam.y = axis("\u03bb (0 planner \u2026 1 pilot)", 0.0, 1.02);
  for (const FlownFlight* f : flights) {
    dev.lines.push_back(line(f->flight.pilot + " pilot", pilot_colour(*f), times(*f), each(*f, deviation_of)));
    lam.lines.push_back(line(f->flight.pilot + " pilot", pilot_colour(*f), times(*f),
                             each(*f, [](const Telemetry& s) { return s.lambda; })));
  }
  dev.lines.push_back(level("r = " + cell(r) + " m", fc::kBlack, r, 0.0, T));
  fig.columns = 2;
  fig.charts = {dev, lam};
}

void rotors_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "7.8", "Rotor speeds of the MikroKopter against their bound", flights);
  table.header = {"pilot", "t [s]", "omega1 [1e3 rad/s]", "omega2 [1e3 rad/s]", "omega3 [1e3 rad/s]",
                  "omega4 [1e3 rad/s]", "omega_max [1e3 rad/s]"};
  const double bound = channel(flights[0]->steps.front(), "rotor speed bound");
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps)
      table.add({f->flight.pilot, cell(s.t), cell(s.x(12)), cell(s.x(13)), cell(s.x(14)), cell(s.x(15)),
                 cell(bound)});
  fig.columns = 2;
  double lo = std::numeric_limits<double>::infinity();
  for (const FlownFlight* f : flights)
    for (int j = 0; j < 4; ++j) lo = std::min(lo, min_of(each(*f, [j](const Telemetry& s) { return s.x(12 + j); })));
  char letter = 'a';
  for (const FlownFlight* f : flights) {
    Chart c;
    c.title = std::string("(") + letter++ + ") " + f->flight.pilot + " pilot";
    c.x = time_axis(f->duration);
    c.y = axis("\u03a9 [10\u00b3 rad/s]", lo - 0.05 * (bound - lo), bound + 0.08 * (bound - lo));
    const ImU32 colours[4] = {fc::kBlue, fc::kOrange, fc::kGreen, fc::kPurple};
    const char* sub[4] = {"\u2081", "\u2082", "\u2083", "\u2084"};
    for (int j = 0; j < 4; ++j)
      c.lines.push_back(line(std::string("\u03a9") + sub[j], colours[j], times(*f),
                             each(*f, [j](const Telemetry& s) { return s.x(12 + j); }), Dash::solid, 1.2f));
    c.lines.push_back(level("upper bound \u03a9_max = " + cell(bound), fc::kBlack, bound, 0.0, f->duration,
                            Dash::dashed, 1.6f));
    fig.charts.push_back(std::move(c));
  }
}

const int kVirtualHorizons[] = {5, 10, 25, 50};
const int kVirtualHorizonsShort[] = {5, 50};

std::vector<FigureFlight> rti_flights(FigureLength length) {
  std::vector<FigureFlight> out;
  const auto horizons = length == FigureLength::thesis ? std::span<const int>(kVirtualHorizons)
                                                       : std::span<const int>(kVirtualHorizonsShort);
  for (const char* pilot : {"novice", "experienced"}) {
    for (const int n_b : horizons) {
      FigureFlight f = mi(pilot, n_b, length);
      if (length == FigureLength::shortened) f.duration = 6.0;
      out.push_back(f);
    }
  }
  return out;
}

int virtual_horizon(const FlownFlight& f) {
  for (const ScenarioKey& k : f.flight.keys)
    if (k.key == "controller.ph.N_b") return std::stoi(k.value);
  return 10;
}

void rti_build(const std::vector<const FlownFlight*>& flights, ui::Figure& fig, FigureTable& table) {
  heading(fig, "7.9", "RTI time per step of the mixed-initiative NMPC for virtual horizons N_b", flights);
  table.header = {"pilot", "N_b", "t [s]", "rti_time [ms]", "fallback [0/1]"};
  double top = 0;
  for (const FlownFlight* f : flights)
    for (const Telemetry& s : f->steps) {
      table.add({f->flight.pilot, std::to_string(virtual_horizon(*f)), cell(s.t), cell(1e-3 * s.stats.total_us),
                 (s.events & (kEventFallback | kEventOverrun)) ? "1" : "0"});
      top = std::max(top, 1e-3 * s.stats.total_us);
    }
  const double dt_ms = 1e3 * flights[0]->dt;
  fig.columns = 2;
  char letter = 'a';
  for (const char* pilot : {"novice", "experienced"}) {
    Chart c;
    c.title = std::string("(") + letter++ + ") " + pilot + " pilot";
    c.y = axis("RTI time (prepare + feedback) [ms]", kNaN, std::max(top, dt_ms) * 1.5);
    c.y.log = true;
    double x = 0;
    for (const FlownFlight* f : flights) {
      if (f->flight.pilot != pilot) continue;
      ui::PlotViolin v;
      v.label = "distribution over the flight's steps, bar at the mean";
      v.colour = pilot_colour(*f);
      v.x = x;
      v.values = each(*f, [](const Telemetry& s) { return 1e-3 * s.stats.total_us; });
      c.violins.push_back(std::move(v));
      c.x.ticks.emplace_back(x, "N_b = " + std::to_string(virtual_horizon(*f)));
      x += 1.0;
    }
    c.x.label = "virtual horizon of the PH index";
    c.x.min = -0.6;
    c.x.max = x - 0.4;
    c.lines.push_back(level("sampling period \u0394t = " + cell(dt_ms) + " ms", fc::kBlack, dt_ms, c.x.min,
                            c.x.max));
    fig.charts.push_back(std::move(c));
  }
}

}  // namespace

const std::vector<FigureDef>& figure_defs() {
  static const std::vector<FigureDef> defs = {
      {"4.4", "fig_4_4", "Pendubot swing-up",
       "The Pendubot swung up from down-down to up-up by the NMPC tracking the offline swing-up "
       "reference, then balanced by the LQR (shaded while it is active): joint angles against the "
       "reference, joint velocities against their soft bounds, and the shoulder torque against "
       "its bound.",
       1800, 1500, pendubot_flights, pendubot_build},
      {"5.3", "fig_5_3", "Smooth step under a 60 ms round trip",
       "The Crazyflie's position against the Ipopt smooth-step reference, flown with the ERK4 "
       "delay predictor at the real setup's 60 ms round trip, and its tracking error.",
       1800, 900, step_flights, step_build},
      {"5.4", "fig_5_4", "Helix under a 60 ms round trip",
       "The helix reference flown with the predictor at 60 ms: the path seen from above and the "
       "position against the reference over time (the helix starts 2 cm below the hover point "
       "at full speed, so the first second is a catch-up).",
       1800, 900, helix_flights, helix_build},
      {"5.5", "fig_5_5", "Tracking with and without the delay predictor",
       "The tracking error of the smooth step and of the helix with the predictor on and off, at "
       "15 ms (inside the uncompensated loop's delay margin) and 60 ms (beyond it: without the "
       "predictor the vehicle is lost). With the predictor the error does not depend on the "
       "round trip (the curves at 15 and 60 ms coincide).",
       1800, 1300, predictor_flights, predictor_build},
      {"5.6", "fig_5_6", "Smooth step against the round-trip time",
       "SPEC 5.2's Fig. 5.6: the smooth step's RMS tracking error and settling time against the "
       "round-trip time, without the predictor from 0 ms to past the linearized loop's delay "
       "margin (where the vehicle is lost), and with it (flat).",
       1800, 900, rtt_flights, rtt_build},
      {"6.4", "fig_6_4", "Two thrown balls: LCL against the squared constraint",
       "The paths flown past two balls thrown at the Crazyflie with the LCL constraint and with "
       "the squared one, against the obstacle-free reference, seen from above and from the side; "
       "each ball's flight and its clearance sphere where it comes closest.",
       1800, 1000, balls_flights, balls_build},
      {"6.5", "fig_6_5", "A cluttered arena: LCL against the squared constraint",
       "The paths flown through a cluttered arena of static spheres with both constraint forms, "
       "seen from above and from the side (each obstacle drawn as its clearance sphere d_C), and "
       "the distance to the nearest obstacle against d_C.",
       1800, 1500, cluttered_flights, cluttered_build},
      {"6.6", "fig_6_6", "Distances to the thrown balls",
       "The distance between the Crazyflie and each thrown ball with both constraint forms "
       "against the clearance d_C, over the flight and around the closest approach: the LCL "
       "form passes closer to d_C without crossing it.",
       1800, 1300, balls_flights, distances_build},
      {"7.5", "fig_7_5", "Mixed-initiative paths of a novice and an experienced pilot",
       "The emulated novice's and experienced pilot's flights of the mixed-initiative helix among "
       "the obstacles, seen from above and from the side, against the planner's reference.",
       1800, 1000, pilots_flights, paths_build},
      {"7.6", "fig_7_6", "Pilot inputs and the NMPC's commands",
       "Each pilot's roll and pitch commands against the mixed-initiative NMPC's stage-1 "
       "attitude, and below them the MPC's correction (the pilot's command minus the MPC's) on "
       "one scale for both: the MPC overlays the experienced pilot's inputs and trims the "
       "novice's oscillations.",
       1800, 1650, pilots_flights, attitude_build},
      {"7.7", "fig_7_7", "Deviation against r, and the PH index",
       "The distance to the planner's reference against the ball radius r, and the PH index "
       "lambda (the pilot's authority) of both pilots: the novice's lambda drops, the "
       "experienced pilot keeps it high.",
       1800, 900, pilots_flights, authority_build},
      {"7.8", "fig_7_8", "Rotor speeds",
       "The four rotor speeds of each pilot's flight against their upper bound.",
       1800, 900, pilots_flights, rotors_build},
      {"7.9", "fig_7_9", "RTI time",
       "The distribution of the mixed-initiative NMPC's time per RTI step (prepare + feedback) "
       "over each flight, for virtual horizons N_b of 5, 10, 25 and 50, for both pilots, against "
       "the 15 ms sampling period (logarithmic). Wall-clock times of the machine that rendered "
       "the figure, each flight flown alone: on a busy machine the tail holds the time the "
       "process waited for a core.",
       1800, 900, rti_flights, rti_build},
  };
  return defs;
}

const FigureDef* find_figure(std::string_view id) {
  for (const FigureDef& d : figure_defs())
    if (id == d.id) return &d;
  return nullptr;
}

std::string figure_ids() {
  std::string out;
  for (const FigureDef& d : figure_defs()) out += (out.empty() ? "" : ", ") + std::string(d.id);
  return out;
}

}  // namespace mixpilot::cli
