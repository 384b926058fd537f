// The thesis's figures (app/figures.hpp, `mixpilot figures`, SPEC §11): each figure's data
// (the table its CSV holds, built from flights of the shipped scenarios through the flight
// assembly) against the thesis's behaviour, on the shortened flights that show it (the
// command renders the thesis's lengths); the rendering at print resolution; the command line.
#include <gtest/gtest.h>

#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include "app/figures.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot::cli {
namespace {

namespace fs = std::filesystem;

const std::string kData = MIXPILOT_SOURCE_DIR;  // holds scenarios/, as the data folder does

// The figures `ids` from their shortened flights (those they share flown once).
std::vector<BuiltFigure> build_all(std::vector<const char*> ids) {
  std::vector<const FigureDef*> defs;
  for (const char* id : ids) {
    defs.push_back(find_figure(id));
    EXPECT_NE(defs.back(), nullptr) << id;
  }
  std::vector<BuiltFigure> out;
  std::string error;
  EXPECT_TRUE(build_figures(defs, FigureLength::shortened, 2, kData, out, error)) << error;
  EXPECT_EQ(out.size(), ids.size());
  out.resize(ids.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_EQ(out[i].figure.title.rfind(std::string("Fig. ") + ids[i] + " ", 0), 0u) << out[i].figure.title;
  return out;
}
BuiltFigure build(const char* id) { return build_all({id})[0]; }

// The values of column `name` in the rows where `where` is `is` (all rows for where = "").
std::vector<double> col(const FigureTable& t, const char* name, const char* where = "",
                        const char* is = "") {
  EXPECT_GE(t.column(name), 0) << name;
  return t.numbers(name, where, is);
}

double rms(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x * x;
  return std::sqrt(s / double(std::max<std::size_t>(v.size(), 1)));
}
double mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / double(std::max<std::size_t>(v.size(), 1));
}
double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (const double x : v) m = std::max(m, std::abs(x));
  return m;
}
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

// Fig. 4.4 (thesis ch. 4): the NMPC swings the Pendubot up from down-down, the LQR takes over
// near the top and balances it. Up (both angles within the scenario's 0.05 rad of up-up, for
// good) before 2.5 s, the LQR active from before 2.5 s to the end; the torque within its
// 0.4 N·m bound; the velocities inside their soft bounds up to the thesis's own violations
// (0.1 rad/s and 1 rad/s on the real robot).
TEST(Figure, PendubotIsUpBefore2p5sAndBalanced) {
  const BuiltFigure b = build("4.4");
  const FigureTable& t = b.table;
  const auto time = col(t, "t [s]"), q1 = col(t, "q1 [rad]"), q2 = col(t, "q2 [rad]");
  const auto lqr = col(t, "lqr_active [0/1]"), u = col(t, "u [N m]");
  ASSERT_GT(time.size(), 1500u);  // 4 s at 2 ms
  std::size_t up = time.size();   // from here on within 0.05 rad of up-up
  while (up > 0 && std::hypot(wrap(q1[up - 1]), wrap(q2[up - 1])) <= 0.05) --up;
  ASSERT_LT(up, time.size());
  EXPECT_LT(time[up], 2.5);
  EXPECT_GT(time[up], 0.5);  // it swings: no shortcut
  std::size_t balancing = lqr.size();
  while (balancing > 0 && lqr[balancing - 1] == 1.0) --balancing;
  ASSERT_LT(balancing, lqr.size());
  EXPECT_LT(time[balancing], 2.5);
  EXPECT_LE(max_abs(u), 0.4 + 1e-9);
  EXPECT_GT(max_abs(u), 0.3);  // the swing needs most of the torque
  EXPECT_LE(max_abs(col(t, "dq1 [rad/s]")), 7.8 + 0.1);
  EXPECT_LE(max_abs(col(t, "dq2 [rad/s]")), 5.0 + 1.0);
  // The shaded LQR interval is drawn in every chart.
  ASSERT_EQ(b.figure.charts.size(), 3u);
  for (const ui::Chart& c : b.figure.charts) {
    ASSERT_FALSE(c.bands.empty());
    EXPECT_NEAR(c.bands.back().x0, time[balancing], 1e-9);
  }
}

// Fig. 5.3: the smooth step flown with the predictor at 60 ms follows its reference: the
// position ends at the target (1, −1, 1) and the error stays small throughout.
TEST(Figure, SmoothStepFollowsTheReference) {
  const BuiltFigure b = build("5.3");
  const FigureTable& t = b.table;
  const auto err = col(t, "error [m]");
  ASSERT_EQ(err.size(), 533u);  // 8 s at 15 ms
  EXPECT_LT(rms(err), 0.01);
  EXPECT_LT(err.back(), 1e-3);
  EXPECT_NEAR(col(t, "x [m]").back(), 1.0, 0.01);
  EXPECT_NEAR(col(t, "y [m]").back(), -1.0, 0.01);
  EXPECT_NEAR(col(t, "z [m]").back(), 1.0, 0.01);
}

// Fig. 5.4: the helix with the predictor at 60 ms: after the first second's catch-up (the
// reference starts below the hover point at full speed) the error stays within millimetres.
TEST(Figure, HelixFollowsTheReference) {
  const BuiltFigure b = build("5.4");
  const FigureTable& t = b.table;
  const auto time = col(t, "t [s]"), err = col(t, "error [m]");
  double after = 0;
  for (std::size_t k = 0; k < err.size(); ++k)
    if (time[k] >= 1.5) after = std::max(after, err[k]);
  EXPECT_LT(after, 0.002);
  EXPECT_GT(max_abs(err), 10.0 * after);  // the catch-up is the largest error
}

// Fig. 5.5: inside the margin (15 ms) the predictor clearly lowers the error (the step's
// RMS; the helix's once the first second's catch-up is over, where the uncompensated loop
// trails the reference); at 60 ms the uncompensated loop loses the vehicle while the predictor
// flies it exactly as at 15 ms (it restores the delay-free loop on the controller's clock).
TEST(Figure, PredictorOnAndOff) {
  const BuiltFigure b = build("5.5");
  const FigureTable& t = b.table;
  const auto errors = [&](const char* reference, const char* rtt, const char* predictor, double from) {
    std::vector<double> e;
    const auto err = t.numbers("error [m]"), time = t.numbers("t [s]");
    for (std::size_t i = 0; i < t.rows.size(); ++i)
      if (t.rows[i][0] == reference && t.rows[i][1] == rtt && t.rows[i][2] == predictor && time[i] >= from)
        e.push_back(err[i]);
    EXPECT_FALSE(e.empty()) << reference << " " << rtt << " " << predictor;
    return e;
  };
  const auto lost = [&](const char* reference, const char* rtt, const char* predictor) {
    for (const auto& row : t.rows)
      if (row[0] == reference && row[1] == rtt && row[2] == predictor) return row[5] == "1";
    ADD_FAILURE() << "no rows";
    return false;
  };
  EXPECT_LE(rms(errors("step", "15", "on", 0.0)), 0.7 * rms(errors("step", "15", "off", 0.0)));
  EXPECT_LE(rms(errors("helix", "15", "on", 1.5)), 0.2 * rms(errors("helix", "15", "off", 1.5)));
  for (const char* ref : {"step", "helix"}) {
    EXPECT_FALSE(lost(ref, "15", "off")) << ref;
    EXPECT_TRUE(lost(ref, "60", "off")) << ref;
    EXPECT_FALSE(lost(ref, "60", "on")) << ref;
    EXPECT_NEAR(rms(errors(ref, "60", "on", 0.0)), rms(errors(ref, "15", "on", 0.0)), 1e-6) << ref;
  }
}

// Fig. 5.6 as SPEC §5.2 decides: without the predictor the RMS error and the settling time
// grow with the round trip from one control period up to the linearized loop's delay margin
// (18 ms) and a little past it, where the input bounds still hold the loop; further on the
// vehicle is lost. With the predictor neither depends on the round trip.
TEST(Figure, RttStudy) {
  const BuiltFigure b = build("5.6");
  const FigureTable& t = b.table;
  const auto rtt = col(t, "rtt [ms]", "predictor", "off");
  const auto rms_off = col(t, "rms_error [m]", "predictor", "off");
  const auto settle_off = col(t, "settle_time [s]", "predictor", "off");
  const auto lost_off = col(t, "lost [0/1]", "predictor", "off");
  const auto at = [&](double ms) {
    for (std::size_t i = 0; i < rtt.size(); ++i)
      if (rtt[i] == ms) return i;
    ADD_FAILURE() << "no flight at " << ms << " ms";
    return std::size_t(0);
  };
  for (const double ms : {0.0, 6.0, 12.0, 15.0, 18.0, 21.0}) EXPECT_EQ(lost_off[at(ms)], 0.0) << ms;
  const double grid[] = {12.0, 15.0, 18.0, 21.0};
  for (int i = 1; i < 4; ++i) {
    EXPECT_GT(rms_off[at(grid[i])], rms_off[at(grid[i - 1])]) << grid[i];
    EXPECT_GT(settle_off[at(grid[i])], settle_off[at(grid[i - 1])]) << grid[i];
  }
  EXPECT_EQ(lost_off[at(24.0)], 1.0);
  EXPECT_EQ(lost_off[at(30.0)], 1.0);
  // The margin drawn is the linearized loop's, and the losses lie beyond it.
  bool margin_drawn = false;
  for (const ui::PlotLine& l : b.figure.charts[0].lines)
    if (l.label.find("delay margin 18 ms") != std::string::npos) margin_drawn = std::abs(l.x[0] - 18.0) < 1e-9;
  EXPECT_TRUE(margin_drawn);
  const auto rms_on = col(t, "rms_error [m]", "predictor", "on");
  const auto lost_on = col(t, "lost [0/1]", "predictor", "on");
  ASSERT_GE(rms_on.size(), 2u);
  for (std::size_t i = 0; i < rms_on.size(); ++i) {
    EXPECT_EQ(lost_on[i], 0.0);
    EXPECT_NEAR(rms_on[i], rms_on[0], 1e-6);
  }
  EXPECT_LT(rms_on[0], rms_off[at(15.0)]);
}

// Figs. 6.4-6.6 (SPEC §5.3): with either form the Crazyflie keeps the clearance d_C to both
// thrown balls and to every static sphere: at the control instants, where the constraint is
// imposed and the flight sits on it (to 1e-6 m, as the obstacle tests find), and at every 1 kHz
// plant step in between (to the millimetre the mode counts as a violation). The LCL form passes
// closer to d_C than the squared one (Proposition 1: less conservative under RTI); with exact
// ball predictions the difference is below a millimetre, between the control instants. Both
// reach the goal.
TEST(Figure, ObstacleDistancesStayAboveTheClearance) {
  const std::vector<BuiltFigure> figs = build_all({"6.4", "6.5", "6.6"});
  const BuiltFigure& paths = figs[0];
  const BuiltFigure& clutter = figs[1];
  const BuiltFigure& balls = figs[2];
  const FigureTable& t = balls.table;
  const double dc = col(t, "d_C [m]")[0];
  EXPECT_EQ(dc, 0.2);
  double least[2] = {0, 0};
  for (const char* form : {"lcl", "squared"}) {
    const int f = std::string(form) == "lcl" ? 0 : 1;
    double closest = 1e9;
    for (const char* ball : {"distance_ball1 [m]", "distance_ball2 [m]"}) {
      const auto d = col(t, ball, "form", form);
      ASSERT_FALSE(d.empty());
      closest = std::min(closest, *std::min_element(d.begin(), d.end()));
    }
    EXPECT_NEAR(closest, dc, 1e-6) << form << ": the clearance is active and kept";
    least[f] = col(t, "least_distance_1khz [m]", "form", form)[0];
    EXPECT_GE(least[f], dc - 1e-3) << form;
    EXPECT_LE(least[f], closest) << form;
  }
  EXPECT_LT(least[0], least[1]);  // LCL passes closer
  for (const char* form : {"lcl", "squared"}) {
    const auto d = col(clutter.table, "nearest_obstacle [m]", "form", form);
    ASSERT_FALSE(d.empty());
    EXPECT_NEAR(*std::min_element(d.begin(), d.end()), dc, 1e-6) << form;
  }
  for (const char* form : {"lcl", "squared"}) {
    const auto x = col(paths.table, "x [m]", "form", form), xr = col(paths.table, "x_reference [m]", "form", form);
    const auto y = col(paths.table, "y [m]", "form", form), yr = col(paths.table, "y_reference [m]", "form", form);
    const auto z = col(paths.table, "z [m]", "form", form), zr = col(paths.table, "z_reference [m]", "form", form);
    EXPECT_LT(std::hypot(x.back() - xr.back(), y.back() - yr.back(), z.back() - zr.back()), 0.05) << form;
  }
}

// Figs. 7.5-7.8 (SPEC §5.4): both emulated pilots stay inside the ball B and within the rotor
// bound; the novice leans more on the planner (lower λ, larger deviation), and the MPC
// overlays the experienced pilot's inputs more closely than the novice's.
TEST(Figure, NoviceLeansOnThePlanner) {
  const std::vector<BuiltFigure> figs = build_all({"7.5", "7.6", "7.7", "7.8"});
  const BuiltFigure& paths = figs[0];
  const BuiltFigure& attitude = figs[1];
  const BuiltFigure& authority = figs[2];
  const BuiltFigure& rotors = figs[3];
  const FigureTable& t = authority.table;
  const double r = col(t, "r [m]")[0];
  EXPECT_EQ(r, 0.175);
  const auto lam_n = col(t, "lambda [-]", "pilot", "novice");
  const auto lam_e = col(t, "lambda [-]", "pilot", "experienced");
  const auto dev_n = col(t, "deviation [m]", "pilot", "novice");
  const auto dev_e = col(t, "deviation [m]", "pilot", "experienced");
  ASSERT_EQ(lam_n.size(), 800u);  // 12 s at 15 ms
  EXPECT_LT(mean(lam_n), mean(lam_e) - 0.1);
  EXPECT_LT(*std::min_element(lam_n.begin(), lam_n.end()), *std::min_element(lam_e.begin(), lam_e.end()));
  EXPECT_GT(mean(lam_e), 0.8);
  EXPECT_GT(mean(dev_n), mean(dev_e));
  EXPECT_LE(max_abs(dev_n), r);
  EXPECT_LE(max_abs(dev_e), r);

  const auto override_of = [&](const char* pilot) {
    const FigureTable& a = attitude.table;
    const auto rp = col(a, "roll_pilot [deg]", "pilot", pilot), rm = col(a, "roll_mpc [deg]", "pilot", pilot);
    const auto pp = col(a, "pitch_pilot [deg]", "pilot", pilot), pm = col(a, "pitch_mpc [deg]", "pilot", pilot);
    std::vector<double> d;
    for (std::size_t k = 0; k < rp.size(); ++k) d.push_back(std::hypot(rp[k] - rm[k], pp[k] - pm[k]));
    return rms(d);
  };
  EXPECT_LT(override_of("experienced"), override_of("novice"));

  const double bound = col(rotors.table, "omega_max [1e3 rad/s]")[0];
  EXPECT_EQ(bound, 0.09);
  for (const char* w : {"omega1 [1e3 rad/s]", "omega2 [1e3 rad/s]", "omega3 [1e3 rad/s]", "omega4 [1e3 rad/s]"}) {
    const auto o = col(rotors.table, w);
    EXPECT_LE(*std::max_element(o.begin(), o.end()), bound + 1e-9) << w;
    EXPECT_GE(*std::min_element(o.begin(), o.end()), -1e-9) << w;
  }

  EXPECT_EQ(col(paths.table, "x [m]", "pilot", "novice").size(), 800u);
}

// Fig. 7.9: the mixed-initiative NMPC's RTI time stays within its 15 ms period: at the median
// of every flight (both pilots, N_b 5 and 50), and the mean too.
TEST(Figure, RtiTimeWithinThePeriod) {
  const BuiltFigure b = build("7.9");
  const FigureTable& t = b.table;
  for (const char* pilot : {"novice", "experienced"}) {
    for (const char* n_b : {"5", "50"}) {
      std::vector<double> ms;
      const auto all = t.numbers("rti_time [ms]");
      for (std::size_t i = 0; i < t.rows.size(); ++i)
        if (t.rows[i][0] == pilot && t.rows[i][1] == n_b) ms.push_back(all[i]);
      ASSERT_EQ(ms.size(), 400u) << pilot << " " << n_b;  // 6 s at 15 ms
      EXPECT_LT(median(ms), 15.0) << pilot << " " << n_b;
      EXPECT_LT(mean(ms), 15.0) << pilot << " " << n_b;
      EXPECT_GT(median(ms), 0.0) << pilot << " " << n_b;
    }
  }
}

// The command as a user runs it: one figure (the Pendubot's, the quickest to fly) rendered at
// print resolution, with its data and index; the image is neither blank nor unlabelled (the
// heading's text and the axis labels are dark pixels on the white page); nothing is replaced
// without --force; unknown ids are refused with the list of valid ones.
TEST(Figure, CommandRendersPngCsvAndIndex) {
  const fs::path home = test::fresh_path("figures", "home");
  fs::create_directories(home);
  const fs::path out = home / "figs";
  const std::string bin = MIXPILOT_BINARY;
  ASSERT_EQ(test::run_mixpilot(bin, "figures --out '" + out.string() + "' --only 4.4", home), 0)
      << test::read_file(home / "out.txt");
  const std::string log = test::read_file(home / "out.txt");
  EXPECT_NE(log.find("flying pendubot_swingup"), std::string::npos) << log;
  const std::string png = test::read_file(out / "fig_4_4.png");
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png.data()),
                                            int(png.size()), &w, &h, &n, 4);
  ASSERT_NE(px, nullptr) << "not a PNG";
  EXPECT_EQ(w, 1800);
  EXPECT_EQ(h, 1500);
  const auto dark_in = [&](int x0, int y0, int x1, int y1) {
    int dark = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const unsigned char* p = px + 4 * (std::size_t(y) * std::size_t(w) + std::size_t(x));
        dark += p[0] < 100 && p[1] < 100 && p[2] < 100;
      }
    return dark;
  };
  const auto white_in = [&](int x0, int y0, int x1, int y1) {
    int white = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const unsigned char* p = px + 4 * (std::size_t(y) * std::size_t(w) + std::size_t(x));
        white += p[0] > 245 && p[1] > 245 && p[2] > 245;
      }
    return white;
  };
  // The page is white, and not only white.
  EXPECT_GT(white_in(0, 0, w, h), w * h / 2);
  EXPECT_GT(dark_in(0, 0, w, h), w * h / 200);
  // The heading: text across the middle of the top band, nothing at its far ends.
  EXPECT_GT(dark_in(w / 4, 0, 3 * w / 4, 60), 500);
  EXPECT_EQ(dark_in(0, 0, 40, 60), 0);
  // The y axis labels (turned upwards) along the left edge of each panel.
  EXPECT_GT(dark_in(20, 100, 60, h - 100), 300);
  // Coloured curves (the joint angles in blue).
  int blue = 0;
  for (int i = 0; i < w * h; ++i) blue += px[4 * i] < 40 && px[4 * i + 1] > 90 && px[4 * i + 1] < 140 && px[4 * i + 2] > 150;
  EXPECT_GT(blue, 1000);
  stbi_image_free(px);
  const std::string csv = test::read_file(out / "fig_4_4.csv");
  EXPECT_EQ(csv.rfind("t [s],q1 [rad],q2 [rad],", 0), 0u) << csv.substr(0, 200);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4001);  // the header and 8 s at 2 ms
  const std::string index = test::read_file(out / "index.md");
  EXPECT_NE(index.find("## Fig. 4.4"), std::string::npos) << index;
  EXPECT_NE(index.find("](fig_4_4.png)"), std::string::npos) << index;
  EXPECT_NE(index.find("](fig_4_4.csv)"), std::string::npos) << index;
  EXPECT_EQ(index.find("Fig. 5.3"), std::string::npos) << index;

  // Again without --force: refused before anything flies, the files untouched.
  EXPECT_EQ(test::run_mixpilot(bin, "figures --out '" + out.string() + "' --only 4.4", home), 1);
  const std::string again = test::read_file(home / "out.txt");
  EXPECT_NE(again.find("--force"), std::string::npos) << again;
  EXPECT_EQ(again.find("flying"), std::string::npos) << again;
  EXPECT_EQ(test::read_file(out / "fig_4_4.png"), png);
  // Unknown ids, with the valid ones listed; no --out.
  EXPECT_EQ(test::run_mixpilot(bin, "figures --out '" + out.string() + "' --only 4.4,5.7", home), 2);
  const std::string unknown = test::read_file(home / "out.txt");
  EXPECT_NE(unknown.find("no figure '5.7'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("4.4, 5.3, 5.4, 5.5, 5.6, 6.4, 6.5, 6.6, 7.5, 7.6, 7.7, 7.8, 7.9"), std::string::npos)
      << unknown;
  EXPECT_EQ(test::run_mixpilot(bin, "figures --only 4.4", home), 2);
  EXPECT_EQ(test::run_mixpilot(bin, "figures --out '" + out.string() + "' --width 100", home), 2);
  // Another size: the same figure in proportion.
  ASSERT_EQ(test::run_mixpilot(bin, "figures --out '" + out.string() + "' --only 4.4 --width 600 --force",
                               home), 0)
      << test::read_file(home / "out.txt");
  const std::string small = test::read_file(out / "fig_4_4.png");
  ASSERT_TRUE(stbi_info_from_memory(reinterpret_cast<const unsigned char*>(small.data()), int(small.size()),
                                    &w, &h, &n));
  EXPECT_EQ(w, 600);
  EXPECT_EQ(h, 500);
  EXPECT_EQ(test::run_mixpilot(bin, "figures --help", home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("7.9   RTI time"), std::string::npos);
}

}  // namespace
}  // namespace mixpilot::cli
