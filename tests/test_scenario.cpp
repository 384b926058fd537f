// Scenario files (core/scenario/scenario_toml.hpp): the shipped mi_helix.toml and its geometry, the
// defaults, and that each kind of error names file, line, column and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include "core/nlp/trajectory_io.hpp"
#include "core/scenario/data_files.hpp"
#include "temp_files.hpp"
#include "core/scenario/obstacle_scenario.hpp"
#include "core/scenario/pendubot_scenario.hpp"
#include "core/scenario/scenario_keys.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/tracking_scenario.hpp"

namespace mixpilot {
namespace {

const std::string kMiHelix = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";

// Header every inline case starts from (4 lines, so the case's own lines are 5, 6, ...).
constexpr const char* kHead =
    "name = \"t\"\n"
    "mode = \"mixed_initiative\"\n"
    "model = \"mikrokopter\"\n"
    "pilot = \"reckless\"\n";

// The error text for kHead + body (empty when it parses).
std::string error_of(const std::string& body) {
  std::string error;
  const auto sc = parse_scenario(std::string(kHead) + body, "t.toml", error);
  EXPECT_EQ(sc.has_value(), error.empty());
  return error;
}

Scenario parse_ok(const std::string& body) {
  std::string error;
  const auto sc = parse_scenario(std::string(kHead) + body, "t.toml", error);
  EXPECT_TRUE(sc) << error;
  return sc ? *sc : Scenario{};
}

// mi_helix_slow (the 60 s headless speed check of the README) is mi_helix at half speed: same
// arena, obstacles and reference curve, so mi_helix's clearance checks below cover it.
TEST(Scenario, ShippedMiHelixSlowIsMiHelixAtHalfSpeed) {
  std::string error;
  const auto fast = load_scenario(kMiHelix, error);
  ASSERT_TRUE(fast) << error;
  const auto slow = load_scenario(MIXPILOT_SOURCE_DIR "/scenarios/mi_helix_slow.toml", error);
  ASSERT_TRUE(slow) << error;
  EXPECT_EQ(slow->duration, 2 * fast->duration);
  ASSERT_EQ(slow->arena.obstacles.size(), fast->arena.obstacles.size());
  for (std::size_t k = 0; k < fast->arena.obstacles.size(); ++k) {
    EXPECT_EQ(slow->arena.obstacles[k].center, fast->arena.obstacles[k].center);
    EXPECT_EQ(slow->arena.obstacles[k].radius, fast->arena.obstacles[k].radius);
  }
  EXPECT_EQ(slow->arena.min, fast->arena.min);
  EXPECT_EQ(slow->arena.max, fast->arena.max);
  for (double t = 0; t <= fast->duration; t += 0.5)  // the rates are rounded to 5 digits
    EXPECT_LE((slow->reference.position(2 * t) - fast->reference.position(t)).norm(), 1e-3) << t;
}

TEST(Scenario, ShippedMiHelixLoads) {
  std::string error;
  const auto sc = load_scenario(kMiHelix, error);
  ASSERT_TRUE(sc) << error;
  EXPECT_EQ(error, "");
  EXPECT_EQ(sc->name, "mi_helix");
  EXPECT_EQ(sc->mode, "mixed_initiative");
  EXPECT_EQ(sc->model, "mikrokopter");
  EXPECT_EQ(sc->duration, 30.0);
  EXPECT_EQ(sc->default_pilot, "novice");
  EXPECT_EQ(sc->source_path, kMiHelix);
  EXPECT_NE(sc->source_text.find("[[arena.obstacles]]"), std::string::npos);
  EXPECT_GE(sc->arena.obstacles.size(), 6u);
  for (const char* p : {"novice", "experienced", "reckless"}) {
    ASSERT_TRUE(sc->pilots.count(p)) << p;
    EXPECT_EQ(sc->pilots.at(p).name, p);
  }
  EXPECT_EQ(sc->pilots.at("experienced").q1, Eigen::Vector3d(400, 400, 600));
  // Table 7.1.
  const MiControllerSettings table71;
  EXPECT_EQ(sc->controller.N, table71.N);
  EXPECT_EQ(sc->controller.dt, table71.dt);
  EXPECT_EQ(sc->controller.weights.q_eta, table71.weights.q_eta);
  EXPECT_EQ(sc->controller.weights.q_e, table71.weights.q_e);
  EXPECT_EQ(sc->controller.weights.q_nu, table71.weights.q_nu);
  EXPECT_EQ(sc->controller.weights.r, table71.weights.r);
  EXPECT_EQ(sc->controller.ph.r, table71.ph.r);
  EXPECT_EQ(sc->controller.ph.N_b, table71.ph.N_b);
  EXPECT_EQ(sc->controller.ph.mu1, table71.ph.mu1);
  EXPECT_EQ(sc->controller.ph.mu2, table71.ph.mu2);
  EXPECT_EQ(sc->controller.ph.theta2, table71.ph.theta2);
  EXPECT_EQ(sc->controller.ph.zeta, table71.ph.zeta);
  EXPECT_EQ(sc->controller.vehicle_radius, 0.3);
}

// SPEC 5.4: every obstacle clear of the reference by more than r + the quadrotor's radius,
// with ~0.1 m to spare (a pilot anywhere inside B keeps clearance), but near enough to matter.
// mi_helix_endurance's five coils are checked the same way.
class ShippedHelix : public testing::TestWithParam<const char*> {};
INSTANTIATE_TEST_SUITE_P(Scenario, ShippedHelix,
                         testing::Values("mi_helix", "mi_helix_endurance"));

TEST_P(ShippedHelix, ObstaclesClearTheReference) {
  std::string error;
  const auto sc = load_scenario(
      std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + GetParam() + ".toml", error);
  ASSERT_TRUE(sc) << error;
  const double required = sc->controller.ph.r + sc->controller.vehicle_radius;
  EXPECT_NEAR(required, 0.475, 1e-12);
  const int kSamples = int(sc->duration * 1e4);  // 0.1 ms: ≤ 11 µm of arc between samples
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < sc->arena.obstacles.size(); ++j) {
    const Obstacle& o = sc->arena.obstacles[j];
    double clearance = std::numeric_limits<double>::infinity();
    double at = 0;
    for (int i = 0; i <= kSamples; ++i) {
      const double t = sc->duration * i / kSamples;
      const double c = (sc->reference.position(t) - o.center).norm() - o.radius;
      if (c < clearance) clearance = c, at = t;
    }
    std::printf("obstacle %zu: clearance %.4f m at t = %.2f s\n", j, clearance, at);
    EXPECT_GT(clearance, required + 0.1) << "obstacle " << j;
    nearest = std::min(nearest, clearance);
  }
  EXPECT_LT(nearest, 0.7);
}

TEST(Scenario, MiHelixStaysInsideTheArenaWithMargin) {
  std::string error;
  const auto sc = load_scenario(kMiHelix, error);
  ASSERT_TRUE(sc) << error;
  double margin = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= 30000; ++i) {
    const Eigen::Vector3d p = sc->reference.position(sc->duration * i / 30000);
    margin = std::min({margin, (p - sc->arena.min).minCoeff(), (sc->arena.max - p).minCoeff()});
  }
  EXPECT_GE(margin, 0.5);
  for (const Obstacle& o : sc->arena.obstacles) {
    EXPECT_TRUE((o.center.array() >= sc->arena.min.array()).all());
    EXPECT_TRUE((o.center.array() <= sc->arena.max.array()).all());
  }
}

TEST(Scenario, DefaultsApplyToOmittedKeys) {
  const Scenario sc = parse_ok("duration = 20\n");  // an integer is a fine number
  EXPECT_EQ(sc.duration, 20.0);
  const Scenario def;
  EXPECT_EQ(sc.controller.N, def.controller.N);
  EXPECT_EQ(sc.controller.dt, def.controller.dt);
  EXPECT_EQ(sc.controller.obstacle_form, ObstacleForm::lcl);
  EXPECT_EQ(sc.controller.safety_constraints, true);
  EXPECT_EQ(sc.controller.slack_l1, def.controller.slack_l1);
  EXPECT_EQ(sc.controller.weights.q_e, def.controller.weights.q_e);
  EXPECT_EQ(sc.controller.ph.zeta, def.controller.ph.zeta);
  EXPECT_EQ(sc.controller.ph.initial_lambda, def.controller.ph.initial_lambda);
  EXPECT_EQ(sc.reference.radius, def.reference.radius);
  EXPECT_EQ(sc.reference.angular_rate, def.reference.angular_rate);
  EXPECT_EQ(sc.arena.min, def.arena.min);
  EXPECT_EQ(sc.arena.max, def.arena.max);
  EXPECT_TRUE(sc.arena.obstacles.empty());
  EXPECT_EQ(sc.plant.rate_hz, 1000.0);
  EXPECT_EQ(sc.plant.seed, 1u);
  // "reckless" is always there; nothing else is invented.
  ASSERT_EQ(sc.pilots.size(), 1u);
  EXPECT_EQ(sc.pilots.at("reckless").max_tilt, PilotProfile{}.max_tilt);
  EXPECT_EQ(sc.source_path, "t.toml");

  // Partly given tables keep the defaults of the rest.
  const Scenario p = parse_ok(
      "[controller.ph]\n"
      "r = 0.2\n"
      "[pilots.a]\n"
      "q5 = 3\n");
  EXPECT_EQ(p.controller.ph.r, 0.2);
  EXPECT_EQ(p.controller.ph.N_b, def.controller.ph.N_b);
  EXPECT_EQ(p.pilots.at("a").q5, 3.0);
  EXPECT_EQ(p.pilots.at("a").q1, PilotProfile{}.q1);
  EXPECT_EQ(p.pilots.at("a").name, "a");
}

TEST(Scenario, SyntaxError) {
  EXPECT_EQ(error_of("[controller]\nN = \n"),
            "t.toml:6:5: TOML syntax: error while parsing key-value pair: expected value, saw "
            "'\\n'");
}

TEST(Scenario, WrongType) {
  EXPECT_EQ(error_of("[controller]\ndt = \"fast\"\n"),
            "t.toml:6:6: controller.dt: expected a number, got the string \"fast\"");
  EXPECT_EQ(error_of("[controller]\nN = 50.0\n"),
            "t.toml:6:5: controller.N: expected an integer, got 50.0");
  EXPECT_EQ(error_of("controller = 3\n"), "t.toml:5:14: controller: expected a table, got 3");
  EXPECT_EQ(error_of("[controller.weights]\nq_eta = [1.0, 2.0]\n"),
            "t.toml:6:9: controller.weights.q_eta: expected an array of 3 numbers, got an array "
            "of 2");
  EXPECT_EQ(error_of("[controller.weights]\nq_eta = [1.0, true, 2.0]\n"),
            "t.toml:6:15: controller.weights.q_eta[1]: expected a number, got true");
  EXPECT_EQ(error_of("[arena]\nobstacles = 1\n"),
            "t.toml:6:13: arena.obstacles: expected an array of tables ([[arena.obstacles]]), "
            "got 1");
}

// Text from the file reaches a terminal only escaped: a string value, a key or a pilot name
// holding an escape sequence shows as \x1B, never as the sequence itself. Names (which end up
// in summaries and file names) may not hold control characters at all.
TEST(Scenario, ControlCharactersNeverReachTheTerminal) {
  std::string error;
  EXPECT_FALSE(parse_scenario("name = \"a\\u001b[2Jb\"\nmode = \"mixed_initiative\"\n"
                              "model = \"mikrokopter\"\npilot = \"reckless\"\n",
                              "t.toml", error));
  EXPECT_EQ(error, "t.toml:1:8: name: expected a string without control characters, got the "
                   "string \"a\\x1B[2Jb\"");
  EXPECT_EQ(error_of("[controller]\nobstacle_form = \"\\u001b[31mlcl\\u0007\"\n"),
            "t.toml:6:17: controller.obstacle_form: expected one of \"lcl\", \"squared\", "
            "got the string \"\\x1B[31mlcl\\x07\"");
  EXPECT_EQ(error_of("\"\\u009b2J\" = 1\n").rfind("t.toml:5:1: \\xC2\\x9B2J: unknown key", 0), 0u)
      << error_of("\"\\u009b2J\" = 1\n");
  for (const std::string body : {"[pilots.\"\\u001b]0;x\\u0007\"]\nq5 = \"x\"\n",
                                 "x = \"\\u001b\"\n", "[reference]\nradius = \"\\u001b\"\n"}) {
    const std::string e = error_of(body);
    EXPECT_FALSE(e.empty());
    EXPECT_EQ(e.find('\x1b'), std::string::npos) << e;
    EXPECT_EQ(e.find('\x07'), std::string::npos) << e;
  }
}

TEST(Scenario, UnknownKey) {
  EXPECT_EQ(error_of("[controller.ph]\nthetta2 = 50.0\n"),
            "t.toml:6:1: controller.ph.thetta2: unknown key (did you mean \"theta2\"?)");
  EXPECT_EQ(error_of("duraton = 3.0\n"), "t.toml:5:1: duraton: unknown key (did you mean "
                                          "\"duration\"?)");
  // Far from every known key: list them.
  EXPECT_EQ(error_of("[plant]\nwind = 3.0\n"),
            "t.toml:6:1: plant.wind: unknown key; expected one of: rate_hz input_delay "
            "position_noise seed");
  EXPECT_EQ(error_of("[[arena.obstacles]]\ncenter = [0.0, 0.0, 1.0]\nradius = 0.1\nr = 1.0\n"),
            "t.toml:8:1: arena.obstacles[0].r: unknown key (did you mean \"radius\"?)");
  EXPECT_EQ(error_of("[pilots.a]\nq6 = 1.0\n"),
            "t.toml:6:1: pilots.a.q6: unknown key (did you mean \"q1\"?)");
  EXPECT_EQ(error_of("[weather]\n"),
            "t.toml:5:2: weather: unknown key; expected one of: name mode model duration pilot "
            "controller reference arena pilots plant");
}

TEST(Scenario, OutOfRange) {
  EXPECT_EQ(error_of("[controller.ph]\nr = -0.1\n"),
            "t.toml:6:5: controller.ph.r: value outside [1e-06, 1000], got -0.1");
  EXPECT_EQ(error_of("[controller.ph]\nmu1 = 1.0\n"),
            "t.toml:6:7: controller.ph.mu1: value outside (0, 1), got 1.0");
  EXPECT_EQ(error_of("[controller]\nN = 0\n"),
            "t.toml:6:5: controller.N: value outside [1, 200], got 0");
  EXPECT_EQ(error_of("duration = nan\n"),
            "t.toml:5:12: duration: expected a finite number, got nan");
  EXPECT_EQ(error_of("[controller]\nN = 8\n[controller.ph]\nN_b = 10\n"),
            "t.toml:8:7: controller.ph.N_b: expected at most controller.N = 8, got 10");
  // The defaulted N_b (10) against a short horizon points at the [controller.ph] table... or,
  // with no such table, at [controller].
  EXPECT_EQ(error_of("[controller]\nN = 8\n"),
            "t.toml:5:1: controller.ph.N_b: expected at most controller.N = 8, got 10");
  EXPECT_EQ(error_of("[plant]\nrate_hz = 500\n"),
            "t.toml:6:11: plant.rate_hz: value outside [1000, 100000], got 500");
  EXPECT_EQ(error_of("[controller]\ndt = 0.0155\n[plant]\nrate_hz = 1000.0\n"),
            "t.toml:8:11: plant.rate_hz: expected a rate giving a whole number of substeps per "
            "control step, got controller.dt * rate_hz = 15.5");
  EXPECT_EQ(error_of("[arena]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, -1.0, 1.0]\n"),
            "t.toml:7:7: arena.max: expected every component above arena.min = [0.0, 0.0, "
            "0.0], got [1.0, -1.0, 1.0]");
  EXPECT_EQ(error_of("[[arena.obstacles]]\ncenter = [0.0, 0.0, 9.0]\nradius = 0.1\n"),
            "t.toml:6:10: arena.obstacles[0].center: expected a point inside the arena [-3.0, "
            "-3.0, 0.0] .. [3.0, 3.0, 3.0], got [0.0, 0.0, 9.0]");
  EXPECT_EQ(error_of("[[arena.obstacles]]\ncenter = [0.0, 0.0, 1.0]\nradius = 0.0\n"),
            "t.toml:7:10: arena.obstacles[0].radius: value outside (0, 100], got 0.0");
  // The ball B around the reference and the vehicle in it keep clear of the ceiling: r + r_v
  // = 0.175 + 0.3 m below z = 3, which the climb reaches at t = (2.525 − 0.5) / 0.2 s.
  EXPECT_EQ(error_of("[reference]\nclimb_rate = 0.2\n"),
            "t.toml:5:1: reference: expected a helix at least 0.475 m (controller.ph.r + "
            "controller.vehicle_radius) inside the arena over [0, duration], but it comes closer "
            "to the arena's ceiling at t = 10.125 s, at (-0.920, -0.391, 2.525)");
}

TEST(Scenario, MissingRequiredKey) {
  std::string error;
  EXPECT_FALSE(parse_scenario("name = \"t\"\nmode = \"mixed_initiative\"\n", "t.toml", error));
  EXPECT_EQ(error,
            "t.toml:1:1: model: missing required key (expected one of \"mikrokopter\", "
            "\"crazyflie\", \"pendubot\")\n"
            "t.toml:1:1: pilot: expected the name of a profile in [pilots] (\"reckless\"), got "
            "\"novice\" (the default)");
  EXPECT_EQ(error_of("[[arena.obstacles]]\ncenter = [0.0, 0.0, 1.0]\n"),
            "t.toml:5:1: arena.obstacles[0].radius: missing required key (expected a number)");
}

TEST(Scenario, BadEnumString) {
  EXPECT_EQ(error_of("[controller]\nobstacle_form = \"lcp\"\n"),
            "t.toml:6:17: controller.obstacle_form: expected one of \"lcl\", \"squared\", got "
            "the string \"lcp\"");
  std::string error;
  EXPECT_FALSE(parse_scenario("name = \"t\"\nmode = \"tracking\"\nmodel = \"mikrokopter\"\n"
                              "pilot = \"reckless\"\n",
                              "t.toml", error));
  EXPECT_EQ(error,
            "t.toml:2:8: mode: expected one of \"mixed_initiative\", got the string "
            "\"tracking\"");
  EXPECT_FALSE(parse_scenario("name = \"t\"\nmode = \"mixed_initiative\"\nmodel = \"crazyflie\"\n"
                              "pilot = \"reckless\"\n",
                              "t.toml", error));
  EXPECT_EQ(error,
            "t.toml:3:9: model: expected \"mikrokopter\" for mode \"mixed_initiative\" (SPEC "
            "5.4), got \"crazyflie\"");
}

TEST(Scenario, DefaultPilotMustNameAProfile) {
  std::string error;
  EXPECT_FALSE(parse_scenario("name = \"t\"\nmode = \"mixed_initiative\"\nmodel = \"mikrokopter\"\n"
                              "pilot = \"novce\"\n[pilots.novice]\n",
                              "t.toml", error));
  EXPECT_EQ(error,
            "t.toml:4:9: pilot: expected the name of a profile in [pilots] (\"novice\", "
            "\"reckless\"), got \"novce\"");
}

TEST(Scenario, DuplicateProfile) {
  EXPECT_EQ(error_of("[pilots.a]\nq5 = 1.0\n[pilots.a]\nq5 = 2.0\n"),
            "t.toml:7:1: pilots.a: defined twice (cannot redefine existing table 'pilots.a'); "
            "each key, table and pilot profile may appear once");
}

TEST(Scenario, DuplicateKey) {
  EXPECT_EQ(error_of("[controller.ph]\nr = 0.1\nr = 0.2\n"),
            "t.toml:7:5: controller.ph.r: defined twice (cannot redefine existing floating-point "
            "'r'); each key, table and pilot profile may appear once");
  EXPECT_EQ(error_of("duration = 1.0\nduration = 2.0\n"),
            "t.toml:6:12: duration: defined twice (cannot redefine existing floating-point "
            "'duration'); each key, table and pilot profile may appear once");
}

TEST(Scenario, AllErrorsReportedInFileOrder) {
  const std::string e = error_of("[plant]\nseed = -1\n[controller]\ndt = 0\n");
  EXPECT_EQ(e,
            "t.toml:6:8: plant.seed: value outside [0, 9223372036854775807], got -1\n"
            "t.toml:8:6: controller.dt: value outside [0.001, 1], got 0");
}

TEST(Scenario, MissingFile) {
  std::string error;
  EXPECT_FALSE(load_scenario("no/such/scenario.toml", error));
  EXPECT_EQ(error, "no/such/scenario.toml: cannot open file (No such file or directory)");
}

// Deep nesting, the ways TOML has to nest, about n levels each (key parts and arrays): beyond
// the bound each is refused at its position before the parser sees it (a key of 50 000 parts
// overflowed toml++'s stack: SIGSEGV), through every TOML reader of the engine.
std::vector<std::pair<std::string, std::string>> deep_tomls(int n) {
  std::string dotted = "a", header = "[a", arrays, tables;
  for (int i = 1; i < n; ++i) dotted += ".a", header += ".a";
  for (int i = 0; i < n; ++i) arrays += '[';
  for (int i = 0; i < n; ++i) arrays += ']';
  for (int i = 0; i < n; ++i) tables += "{a = ";
  tables += '1';
  for (int i = 0; i < n; ++i) tables += '}';
  std::string mixed;  // three levels each: the array and two key parts
  for (int i = 0; i < n / 3; ++i) mixed += "[{a.b = ";
  mixed += '1';
  for (int i = 0; i < n / 3; ++i) mixed += "}]";
  return {{"dotted key", dotted + " = 1\n"},
          {"table header", header + "]\nx = 1\n"},
          {"array of tables header", "[" + header + "]]\nx = 1\n"},
          {"arrays", "x = " + arrays + "\n"},
          {"inline tables", "x = " + tables + "\n"},
          {"arrays of inline tables with dotted keys", "x = " + mixed + "\n"}};
}

TEST(Scenario, NestingBeyondTheBoundIsRefusedByEveryReader) {
  const std::string mode = "mode = \"mixed_initiative\"\n";
  for (const int n : {33, 50000}) {
    for (const auto& [shape, body] : deep_tomls(n)) {
      SCOPED_TRACE(shape + " of depth " + std::to_string(n));
      const std::string text = mode + "# nested\n" + body;
      std::string e1, e2, e3, e4, e5;
      EXPECT_FALSE(parse_scenario(text, "d.toml", e1));
      EXPECT_FALSE(scenario_mode(text, "d.toml", e2));
      EXPECT_FALSE(parse_tracking_scenario(text, "d.toml", e3));
      EXPECT_FALSE(parse_pendubot_scenario(text, "d.toml", e4));
      EXPECT_FALSE(parse_obstacle_scenario(text, "d.toml", e5));
      for (const std::string* e : {&e1, &e2, &e3, &e4, &e5})
        EXPECT_TRUE(std::regex_search(*e, std::regex("^d\\.toml:3:[0-9]+: TOML syntax: nested more "
                                                     "than 32 levels deep")))
            << *e;
    }
  }
  // Depth 32 is allowed (the parser then judges the content: here an unknown key).
  for (const auto& [shape, body] : deep_tomls(31)) {
    SCOPED_TRACE(shape);
    std::string e;
    EXPECT_FALSE(parse_scenario(mode + body, "d.toml", e));
    EXPECT_EQ(e.find("nested more than"), std::string::npos) << e;
  }
}

// Nesting is counted in keys and containers, never in strings, comments or values.
TEST(Scenario, NestingCountsNeitherStringsNorCommentsNorNumbers) {
  const std::string dots(200, '.');
  std::string e;
  EXPECT_TRUE(parse_scenario(std::string(kHead) + "# " + dots + "\n[controller]\ndt = 0.015 # " +
                                 dots + "\n",
                             "t.toml", e))
      << e;
  // A quoted key with many dots is one part; brackets in strings are not arrays.
  for (const std::string& body :
       {"\"" + dots + "\" = 1\n", "x = \"" + std::string(100, '[') + "\"\n",
        "x = '" + std::string(100, '{') + "'\n",
        "x = \"\"\"\n" + std::string(100, '{') + "\\\"\"\"\n\"\"\"\n",
        "x = [" + std::string(50, '1') + ".5, 2.5e3, 1979-05-27T07:32:00Z]\n"}) {
    const std::string err = error_of(body);
    EXPECT_FALSE(err.empty());  // unknown keys all, but never for their depth
    EXPECT_EQ(err.find("nested"), std::string::npos) << err;
  }
}

// What editors write: a UTF-8 byte-order mark and CR-only or CR LF line ends read as LF.
TEST(Scenario, ByteOrderMarkAndLineEndsOfAnyEditor) {
  std::string error;
  const std::string text = std::string(kHead) + "[controller]\ndt = 0.02\n";
  for (const std::string& variant :
       {"\xEF\xBB\xBF" + text, std::regex_replace(text, std::regex("\n"), "\r"),
        std::regex_replace(text, std::regex("\n"), "\r\n")}) {
    const auto sc = parse_scenario(variant, "t.toml", error);
    ASSERT_TRUE(sc) << error;
    EXPECT_EQ(sc->controller.dt, 0.02);
  }
}

// --- Ranges (docs/scenario-format.md, "Ranges"): each value below was accepted by the loaders
// before they had ranges, and then crashed, hung or gave nonsense in flight.

struct Edit {
  std::string table, key, value;
};

// A shipped scenario with each edit's `key = value` in its [table] (replacing the key's line,
// else added under the table's header), parsed under its own path so its reference CSV resolves.
template <class Parse>
std::string shipped_error(const std::string& file, const std::vector<Edit>& edits, Parse parse) {
  const std::string path = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + file;
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::vector<std::string> lines;
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  const std::regex header(R"(^\s*\[+\s*([^\]]+?)\s*\]+.*)");
  for (const Edit& e : edits) {
    const std::regex assignment("^\\s*" + e.key + "\\s*=.*");
    std::string current;
    std::size_t insert_at = e.table.empty() ? 0 : lines.size() + 1;
    bool done = false;
    std::smatch m;
    for (std::size_t i = 0; i < lines.size() && !done; ++i) {
      if (std::regex_match(lines[i], m, header)) {
        current = m[1];
        if (current == e.table && insert_at > lines.size()) insert_at = i + 1;
      } else if (current == e.table && std::regex_match(lines[i], assignment)) {
        lines[i] = e.key + " = " + e.value;
        done = true;
      }
    }
    EXPECT_TRUE(done || insert_at <= lines.size()) << e.table << " not in " << file;
    if (!done && insert_at <= lines.size()) {
      lines.insert(lines.begin() + std::ptrdiff_t(insert_at), e.key + " = " + e.value);
    }
  }
  std::string out;
  for (const std::string& l : lines) out += l + '\n';
  std::string error;
  const auto sc = parse(out, path, error);
  EXPECT_EQ(sc.has_value(), error.empty());
  return error;
}

std::string mi_error(const std::vector<Edit>& edits) {
  return shipped_error("mi_helix.toml", edits,
                       [](const std::string& t, const std::string& p, std::string& e) {
                         return parse_scenario(t, p, e);
                       });
}
std::string pendubot_error(const std::vector<Edit>& edits) {
  return shipped_error("pendubot_swingup.toml", edits,
                       [](const std::string& t, const std::string& p, std::string& e) {
                         return parse_pendubot_scenario(t, p, e);
                       });
}
std::string tracking_error(const std::vector<Edit>& edits) {
  return shipped_error("tracking_helix.toml", edits,
                       [](const std::string& t, const std::string& p, std::string& e) {
                         return parse_tracking_scenario(t, p, e);
                       });
}
std::string obstacle_error(const std::vector<Edit>& edits) {
  return shipped_error("obstacles_thrown_balls.toml", edits,
                       [](const std::string& t, const std::string& p, std::string& e) {
                         return parse_obstacle_scenario(t, p, e);
                       });
}

// `key: value outside <range>` at the key's own line and column.
::testing::AssertionResult outside(const std::string& error, const std::string& key,
                                   const std::string& range) {
  const std::string want = ": " + key + ": value outside " + range;
  if (error.find(want) != std::string::npos &&
      std::regex_search(error, std::regex(R"(\.toml:\d+:\d+: )"))) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "expected \"" << want << "\" in \"" << error << '"';
}

TEST(ScenarioRanges, ShippedScenariosAreInsideTheRanges) {
  EXPECT_EQ(mi_error({{"controller", "N", "50"}}), "");
  EXPECT_EQ(pendubot_error({{"controller", "N", "10"}}), "");
  EXPECT_EQ(tracking_error({{"controller", "N", "50"}}), "");
  EXPECT_EQ(obstacle_error({{"controller", "clearance", "0.2"}}), "");
}

// controller.N = 2147483647 overflowed an int in the QP dimensions (std::length_error, abort);
// N = 100000 hung. The horizon is at most 200 stages in every mode.
TEST(ScenarioRanges, HorizonIsBounded) {
  for (const char* n : {"2147483647", "100000", "201"}) {
    EXPECT_TRUE(outside(mi_error({{"controller", "N", n}}), "controller.N", "[1, 200]")) << n;
    EXPECT_TRUE(outside(pendubot_error({{"controller", "N", n}}), "controller.N", "[1, 200]")) << n;
    EXPECT_TRUE(outside(tracking_error({{"controller", "N", n}}), "controller.N", "[1, 200]")) << n;
    EXPECT_TRUE(outside(obstacle_error({{"controller", "N", n}}), "controller.N", "[1, 200]")) << n;
  }
  EXPECT_TRUE(
      outside(mi_error({{"pilots.novice", "N", "2147483647"}}), "pilots.novice.N", "[1, 200]"));
  EXPECT_TRUE(
      outside(mi_error({{"controller.ph", "N_b", "2147483647"}}), "controller.ph.N_b", "[1, 200]"));
}

// A huge reference.angular_rate hung the loader's arena check (its sample count overflowed).
TEST(ScenarioRanges, HelixAngularRateIsBounded) {
  for (const char* w : {"1e300", "1e9", "-11"}) {
    EXPECT_TRUE(outside(mi_error({{"reference", "angular_rate", w}}), "reference.angular_rate",
                        "[-10, 10]"))
        << w;
    EXPECT_TRUE(outside(tracking_error({{"reference", "angular_rate", w}}),
                        "reference.angular_rate", "[-10, 10]"))
        << w;
  }
}

// A delay of 1e300 behaved like 0 (its step count overflowed).
TEST(ScenarioRanges, DelaysAreBounded) {
  EXPECT_TRUE(outside(mi_error({{"pilots.novice", "reaction_delay", "1e300"}}),
                      "pilots.novice.reaction_delay", "[0, 10]"));
  EXPECT_TRUE(
      outside(mi_error({{"plant", "input_delay", "1e300"}}), "plant.input_delay", "[0, 10]"));
  EXPECT_TRUE(outside(tracking_error({{"plant", "rtt", "1e300"}}), "plant.rtt", "[0, 1]"));
}

// A huge obstacle radius made the skill score inf (and a bare `inf` in the JSON report).
TEST(ScenarioRanges, ObstacleRadiusFitsTheArena) {
  EXPECT_TRUE(outside(mi_error({{"arena.obstacles", "radius", "1e300"}}),
                      "arena.obstacles[0].radius", "(0, 100]"));
  // mi_helix's arena is 5 x 5 x 2.5 m: half its diagonal is 3.75 m.
  EXPECT_TRUE(outside(mi_error({{"arena.obstacles", "radius", "3.75"}}),
                      "arena.obstacles[0].radius", "(0, 3.75)"));
  EXPECT_EQ(mi_error({{"arena.obstacles", "radius", "3.7"}}), "");
}

// A huge duration reserved gigabytes of per-step buffers; a tiny one flew no step at all.
TEST(ScenarioRanges, RunSizeIsBounded) {
  EXPECT_TRUE(outside(mi_error({{"", "duration", "1e9"}}), "duration", "(0, 3600]"));
  EXPECT_TRUE(outside(pendubot_error({{"", "duration", "1e300"}}), "duration", "(0, 3600]"));
  EXPECT_TRUE(outside(tracking_error({{"", "duration", "3601"}}), "duration", "(0, 3600]"));
  EXPECT_TRUE(outside(obstacle_error({{"", "duration", "1e9"}}), "duration", "(0, 3600]"));
  // 3600 s at dt = 1 ms: 3.6e6 control steps, above the 2e6 bound.
  const std::string e = mi_error({{"", "duration", "3600.0"}, {"controller", "dt", "0.001"}});
  EXPECT_NE(e.find("duration: duration / controller.dt (control steps) = 3600000, outside [1, "
                   "2000000]"),
            std::string::npos)
      << e;
  // Shorter than one control step: nothing would be flown.
  const std::string tiny = pendubot_error({{"", "duration", "1e-9"}});
  EXPECT_NE(tiny.find("duration / controller.dt (control steps) = 5e-07, outside [1, 2000000]"),
            std::string::npos)
      << tiny;
  // 3600 s at 1e5 Hz: 3.6e8 plant substeps, above the 4e7 bound.
  const std::string sub =
      pendubot_error({{"plant", "rate_hz", "100000.0"}, {"", "duration", "3600.0"}});
  EXPECT_NE(sub.find("plant substeps) = 360000000, outside [0, 40000000]"), std::string::npos)
      << sub;
}

// Non-finite numbers are refused everywhere, whatever the key's range.
TEST(ScenarioRanges, NonFiniteNumbersAreRefused) {
  for (const char* v : {"nan", "inf", "-inf"}) {
    EXPECT_NE(
        mi_error({{"reference", "phase", v}}).find("reference.phase: expected a finite number"),
        std::string::npos);
    EXPECT_NE(pendubot_error({{"lqr", "r", v}}).find("lqr.r: expected a finite number"),
              std::string::npos);
    EXPECT_NE(obstacle_error({{"balls", "throw_time", v}}).find("expected a finite number"),
              std::string::npos);
  }
}

// Counts that size per-step work: obstacles (64), encoder resolutions (2^24 counts per turn).
TEST(ScenarioRanges, CountsAreBounded) {
  std::string many = "[arena]\nmin = [-3.0, -3.0, 0.0]\nmax = [3.0, 3.0, 3.0]\n";
  for (int i = 0; i < 65; ++i)
    many += "[[arena.obstacles]]\ncenter = [0.0, 0.0, 1.0]\nradius = 0.1\n";
  EXPECT_NE(error_of(many).find("arena.obstacles: the number of obstacles = 65, outside [0, 64]"),
            std::string::npos);
  EXPECT_TRUE(outside(pendubot_error({{"sensor", "counts_q1", "2147483647"}}), "sensor.counts_q1",
                      "[4, 16777216]"));
  EXPECT_TRUE(outside(mi_error({{"controller", "max_constrained_obstacles", "2147483647"}}),
                      "controller.max_constrained_obstacles", "[0, 64]"));
}

// Reference CSVs: bounded cell values, columns and an increasing equidistant time.
std::string csv_error(const std::string& text) {
  const std::string path = ::testing::TempDir() + "mixpilot_ranges.csv";
  {
    std::ofstream out(path, std::ios::trunc);
    out << text;
  }
  std::string error;
  const auto f = read_trajectory_csv(path, error);
  EXPECT_EQ(f.has_value(), error.empty());
  std::remove(path.c_str());
  return error.empty() ? "" : error.substr(path.size());
}

TEST(ScenarioRanges, ReferenceCsvIsBounded) {
  EXPECT_EQ(csv_error("t,x0,u0\n0,1,2\n0.1,1,2\n0.2,1,\n"), "");
  // 1e300 in a state once made the tracking RMS inf.
  EXPECT_EQ(csv_error("t,x0,u0\n0,1e300,2\n0.1,1,2\n0.2,1,\n"),
            ":2: column 2 (x0): expected a number in [-1e6, 1e6], found \"1e300\"");
  EXPECT_EQ(csv_error("t,x0,u0\n0,1,2\n0.1,1,2\n0.1,1,\n"),
            ":4: expected t = 0.200000 (equidistant grid of dt = 0.100000)");
  EXPECT_EQ(csv_error("t,x0,u0\n0.1,1,2\n0,1,2\n-0.1,1,\n"), ":3: expected t to increase");
  std::string wide = "t";
  for (int i = 0; i < 65; ++i) wide += ",x" + std::to_string(i);
  EXPECT_EQ(csv_error(wide + ",u0\n"),
            ":1: expected at most 64 x and 64 u columns, found 65 and 1");
}


// The shipped data is found beside the executable (<exe>/../share/mixpilot: the install prefix,
// and the build tree's links), or where MIXPILOT_DATA_DIR says; a wrong override is reported,
// never silently replaced.
TEST(DataFiles, FoundBesideTheExecutableOrWhereTheOverrideSays) {
  namespace fs = std::filesystem;
  unsetenv("MIXPILOT_DATA_DIR");
  const std::string dir = data_dir();
  ASSERT_FALSE(dir.empty());
  EXPECT_TRUE(fs::exists(fs::path(dir) / "scenarios" / "mi_helix.toml")) << dir;
  EXPECT_TRUE(fs::exists(data_file("assets/dds-loopback.xml")));
  EXPECT_EQ(fs::path(dir).filename(), "mixpilot");
  EXPECT_EQ(fs::path(dir).parent_path().filename(), "share");

  const fs::path mine = test::fresh_path("data_files", "override");
  fs::create_directories(mine / "scenarios");
  setenv("MIXPILOT_DATA_DIR", mine.c_str(), 1);
  EXPECT_EQ(data_dir(), mine.lexically_normal().string());
  EXPECT_EQ(data_file("scenarios/x.toml"), (mine / "scenarios" / "x.toml").string());

  setenv("MIXPILOT_DATA_DIR", "/nonexistent/mixpilot", 1);
  std::string why;
  EXPECT_EQ(data_dir(&why), "");
  EXPECT_NE(why.find("MIXPILOT_DATA_DIR=/nonexistent/mixpilot holds no scenarios/"),
            std::string::npos) << why;
  EXPECT_EQ(data_file("scenarios/mi_helix.toml"), "");
  unsetenv("MIXPILOT_DATA_DIR");
}


// ---- Scenario keys set to other values (core/scenario/scenario_keys.hpp) -----------------

namespace keys_test {

std::string set(const std::string& text, std::vector<ScenarioKey> keys, std::string& error) {
  const auto out = set_scenario_keys(text, "t.toml", keys, error);
  return out ? *out : std::string();
}

}  // namespace keys_test

// A key the file gives changes where it stands: every other byte (comments, order, other
// keys) is kept, and the loader reads the new value.
TEST(ScenarioKeys, AValueIsReplacedWhereItStands) {
  const std::string path = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/tracking_smooth_step.toml";
  std::string text, error;
  ASSERT_TRUE(read_text_file(path, text, error)) << error;
  const std::string edited = keys_test::set(text, {{"plant.rtt", "0.012"}, {"controller.compensation", "false"}}, error);
  ASSERT_FALSE(edited.empty()) << error;
  std::string expected = text;
  expected.replace(expected.find("rtt = 0.06 "), 10, "rtt = 0.012");
  expected.replace(expected.find("compensation = true"), 19, "compensation = false");
  EXPECT_EQ(edited, expected);
  const auto sc = parse_tracking_scenario(edited, path, error);
  ASSERT_TRUE(sc) << error;
  EXPECT_EQ(sc->plant.rtt, 0.012);
  EXPECT_FALSE(sc->controller.compensation);
  // Code points before the value on its line (toml++ counts columns in code points), arrays,
  // strings; the later setting of a key wins.
  const std::string t = "a = \"\u00e9\u2192\"  # \u00fc\n[b]\nc = [\"\u00e9\u00e9\", 5]  # \u2192\n";
  EXPECT_EQ(keys_test::set(t, {{"a", "\"x\""}, {"b.c", "[1, 2]"}, {"b.c", "[3]"}}, error),
            "a = \"x\"  # \u00fc\n[b]\nc = [3]  # \u2192\n") << error;
}

// A key the file leaves to its default is added under its table's header (the root's at the
// top); then the loader checks it as any key.
TEST(ScenarioKeys, AMissingKeyIsAddedUnderItsTable) {
  std::string error;
  const std::string t = "# c\nname = \"n\"\n\n[controller]  # the NMPC\nN = 50\n\n[plant]\nrtt = 0.06";
  EXPECT_EQ(keys_test::set(t, {{"controller.kind", "\"lqr\""}, {"plant.seed", "3"}, {"duration", "2.0"}}, error),
            "duration = 2.0\n# c\nname = \"n\"\n\n[controller]  # the NMPC\nkind = \"lqr\"\nN = 50\n\n"
            "[plant]\nseed = 3\nrtt = 0.06")
      << error;
  const std::string path = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/tracking_smooth_step.toml";
  std::string text;
  ASSERT_TRUE(read_text_file(path, text, error)) << error;
  const std::string edited = keys_test::set(text, {{"plant.typo", "1.0"}}, error);
  ASSERT_FALSE(edited.empty()) << error;
  EXPECT_FALSE(parse_tracking_scenario(edited, path, error));
  EXPECT_NE(error.find("plant.typo"), std::string::npos) << error;
}

// An element of an array is a key too: a value of an array of tables' element, an element of
// a value array, a key an element leaves out (under its [[header]]); a table the file lacks, or
// has no header of its own, is appended with its header; an inline table takes a key inside its
// braces.
TEST(ScenarioKeys, ArrayElementsInlineAndMissingTables) {
  std::string error;
  const std::string t = "[a]\nv = [1.0, 2.0]  # x\nin = { p = 1 }\n[[e]]\nf = 3\n[[e]]\nf = 4\n[g.h]\ni = 4\n";
  EXPECT_EQ(keys_test::set(t, {{"e[1].f", "5"}, {"a.v[1]", "-0.5"}, {"e[0].k", "true"},
                               {"a.in.q", "\"s\""}, {"g.z", "1"}, {"x.y.w", "[1, 2]"}},
                           error),
            "[a]\nv = [1.0, -0.5]  # x\nin = { p = 1 , q = \"s\" }\n[[e]]\nk = true\nf = 3\n[[e]]\n"
            "f = 5\n[g.h]\ni = 4\n\n[g]\nz = 1\n\n[x.y]\nw = [1, 2]\n")
      << error;
  // A shipped scenario's obstacle: the loader reads the new radius, every other byte is kept.
  const std::string path = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";
  std::string text;
  ASSERT_TRUE(read_text_file(path, text, error)) << error;
  const auto before = parse_scenario(text, path, error);
  ASSERT_TRUE(before) << error;
  const std::string edited = keys_test::set(text, {{"arena.obstacles[1].radius", "0.125"}}, error);
  ASSERT_FALSE(edited.empty()) << error;
  const auto after = parse_scenario(edited, path, error);
  ASSERT_TRUE(after) << error;
  ASSERT_GT(before->arena.obstacles.size(), 2u);
  EXPECT_NE(before->arena.obstacles[1].radius, 0.125);
  EXPECT_EQ(after->arena.obstacles[1].radius, 0.125);
  EXPECT_EQ(after->arena.obstacles[0].radius, before->arena.obstacles[0].radius);
  EXPECT_EQ(after->arena.obstacles[2].radius, before->arena.obstacles[2].radius);
  // Only that value changed: the second obstacle's "radius = 0.2" line.
  const std::size_t second = text.find("[[arena.obstacles]]", text.find("[[arena.obstacles]]") + 1);
  const std::size_t at = text.find("radius = 0.2\n", second);
  ASSERT_NE(at, std::string::npos);
  std::string expected = text;
  expected.replace(at, 12, "radius = 0.125");
  EXPECT_EQ(edited, expected);
}

// What cannot be set is refused with the setting and the file named.
TEST(ScenarioKeys, RefusalsNameTheSetting) {
  const std::string t = "name = \"n\"\n[a]\nb = 1\nv = [1.0, 2.0]\n[a.c]\nd = 2\n[[e]]\nf = 3\n";
  const struct {
    ScenarioKey key;
    const char* says;
  } cases[] = {
      {{"a", "1"}, "a table in the scenario: expected the key of a value inside it"},
      {{"e", "1"}, "an array of tables in the scenario: expected the key of a value inside it"},
      {{"e.f", "1"}, "e is an array of tables in the scenario: expected an element of it, e[index].f"},
      {{"e[1].f", "1"}, "has 1 elements: index 1 is out of range"},
      {{"a.v[2]", "1.0"}, "has 2 elements: index 2 is out of range"},
      {{"a.b[0]", "1"}, "b is 1 in the scenario, not an array"},
      {{"x[0].y", "1"}, "the scenario has no x"},
      {{"a.b.z", "1"}, "a.b is 1 in the scenario, not a table"},
      {{"a.b", "\"s\""}, "expected an integer like the scenario's value 1, got \"s\""},
      {{"a.v", "1.0"}, "expected an array"},
      {{"name", "true"}, "expected a string"},
      {{"a.b", "lcl"}, "not one TOML value"},
      {{"a.b", "1\nc = 2"}, "on one line"},
      {{"a..b", "1"}, "expected a key path of the scenario"},
      {{"a.\"b\"", "1"}, "expected a key path of the scenario"},
      {{"a.v[x]", "1"}, "expected [index] with a whole number after \"v\""},
  };
  for (const auto& c : cases) {
    std::string error;
    EXPECT_FALSE(set_scenario_keys(t, "t.toml", {c.key}, error)) << c.key.key;
    EXPECT_NE(error.find(c.says), std::string::npos) << error;
    EXPECT_NE(error.find("setting " + c.key.key + " = "), std::string::npos) << error;
    EXPECT_NE(error.find("t.toml"), std::string::npos) << error;
  }
  std::string error;
  EXPECT_FALSE(set_scenario_keys("a = [", "t.toml", {{"a", "1"}}, error));
  EXPECT_NE(error.find("not TOML"), std::string::npos) << error;
  const auto k = parse_scenario_key(" plant.rtt = 0.012 ", error);
  ASSERT_TRUE(k);
  EXPECT_EQ(k->key, "plant.rtt");
  EXPECT_EQ(k->value, "0.012");
  EXPECT_FALSE(parse_scenario_key("plant.rtt", error));
  EXPECT_FALSE(parse_scenario_key("=1", error));
}

}  // namespace
}  // namespace mixpilot
