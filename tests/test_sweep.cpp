// Sweeps (SPEC §11, docs/sweeps.md), the engine's part: a sweep file expanded into its plan of
// runs (grid order, lists, pilots and seeds, ids), each run's scenario text (the base file with
// the run's values, read back by the scenario loaders), the errors of bad sweep files at their
// line, the plan's hash, the shard rule, the JSON reader and the merged table.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "core/base/json.hpp"
#include "core/base/report_table.hpp"
#include "core/base/shard.hpp"
#include "core/modes/make_mode.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/sweep.hpp"
#include "core/scenario/tracking_scenario.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

const std::string kScenarios = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/";
// A sweep file's text is read as if it were this file: relative scenario paths start here.
const std::string kSweepFile = kScenarios + "sweeps/test.toml";

std::optional<SweepPlan> plan_of(const std::string& text, std::string& error) {
  return parse_sweep(text, kSweepFile, error);
}

// The plan of `text`, which must read.
SweepPlan must_plan(const std::string& text) {
  std::string error;
  auto plan = plan_of(text, error);
  EXPECT_TRUE(plan) << error;
  return plan ? *plan : SweepPlan{};
}

// The error of `text`, which must not read.
std::string must_fail(const std::string& text) {
  std::string error;
  const auto plan = plan_of(text, error);
  EXPECT_FALSE(plan) << "accepted:\n" << text;
  return error;
}

std::vector<std::string> ids(const SweepPlan& p) {
  std::vector<std::string> out;
  for (const SweepRun& r : p.runs) out.push_back(r.id);
  return out;
}

TEST(Sweep, AGridIsEveryCombinationFirstKeySlowest) {
  const SweepPlan p = must_plan(R"(
scenario = "../tracking_smooth_step.toml"
duration = 2.5
[grid]
"plant.rtt" = [0.0, 0.012, 0.03]
"controller.compensation" = [true, false]
)");
  ASSERT_EQ(p.runs.size(), 6u);
  EXPECT_EQ(p.columns, (std::vector<std::string>{"plant.rtt", "controller.compensation"}));
  EXPECT_EQ(ids(p), (std::vector<std::string>{
                        "0000-rtt=0-compensation=true", "0001-rtt=0-compensation=false",
                        "0002-rtt=0.012-compensation=true", "0003-rtt=0.012-compensation=false",
                        "0004-rtt=0.03-compensation=true", "0005-rtt=0.03-compensation=false"}));
  // Each run's text is the base scenario with its values, as the tracking loader reads it.
  const double rtts[] = {0.0, 0.0, 0.012, 0.012, 0.03, 0.03};
  for (std::size_t k = 0; k < p.runs.size(); ++k) {
    const SweepRun& r = p.runs[k];
    EXPECT_EQ(r.index, k);
    ASSERT_TRUE(r.duration);
    EXPECT_EQ(*r.duration, 2.5);
    std::string error;
    const auto sc = parse_tracking_scenario(r.scenario_text, p.scenario_file, error);
    ASSERT_TRUE(sc) << error << "\n" << r.scenario_text;
    EXPECT_EQ(sc->plant.rtt, rtts[k]);
    EXPECT_EQ(sc->controller.compensation, k % 2 == 0);
    // The rest is the file's: its reference (a path relative to the scenario) and its comments.
    EXPECT_EQ(sc->controller.N, 50);
    EXPECT_NE(r.scenario_text.find("# round-trip time tau_r [s]"), std::string::npos);
    EXPECT_TRUE(r.scenario_text.starts_with("# tracking_smooth_step.toml in sweep test, run " + r.id));
  }
  // Names sort in plan order.
  std::vector<std::string> sorted = ids(p);
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, ids(p));
  EXPECT_EQ(p.scenario_file, kScenarios + "tracking_smooth_step.toml");
}

TEST(Sweep, PilotsAndSeedsAreTheFastestAxesAfterTheGridAndAListMultipliesIt) {
  const SweepPlan p = must_plan(R"(
scenario = "../mi_helix.toml"
pilots = ["novice", "experienced"]
seeds = [3, 4]
[set]
plant.position_noise = 0.01
controller.ph.initial_lambda = 0.25     # the file leaves it at its default: added
[grid]
controller.ph.r = [0.15, 0.2]
[[runs]]
"arena.obstacles[5].radius" = 0.1
[[runs]]
assist = "off"
)");
  ASSERT_EQ(p.runs.size(), 2u * 2 * 2 * 2);
  EXPECT_EQ(p.columns, (std::vector<std::string>{"arena.obstacles[5].radius", "assist",
                                                 "controller.ph.r", "pilot", "plant.seed"}));
  EXPECT_EQ(p.runs[0].id, "0000-radius=0.1-r=0.15-pilot=novice-seed=3");
  EXPECT_EQ(p.runs[1].id, "0001-radius=0.1-r=0.15-pilot=novice-seed=4");
  EXPECT_EQ(p.runs[2].id, "0002-radius=0.1-r=0.15-pilot=experienced-seed=3");
  EXPECT_EQ(p.runs[4].id, "0004-radius=0.1-r=0.2-pilot=novice-seed=3");
  EXPECT_EQ(p.runs[8].id, "0008-assist=off-r=0.15-pilot=novice-seed=3");
  for (const SweepRun& r : p.runs) {
    std::string error;
    const auto sc = parse_scenario(r.scenario_text, p.scenario_file, error);
    ASSERT_TRUE(sc) << error << "\n" << r.scenario_text;
    EXPECT_EQ(sc->plant.position_noise, 0.01);
    EXPECT_EQ(sc->controller.ph.initial_lambda, 0.25);
    EXPECT_EQ(sc->plant.seed, r.index % 2 == 0 ? 3u : 4u);
    EXPECT_EQ(sc->default_pilot, (r.index / 2) % 2 == 0 ? "novice" : "experienced");
    EXPECT_EQ(sc->controller.ph.r, (r.index / 4) % 2 == 0 ? 0.15 : 0.2);
    EXPECT_EQ(sc->arena.obstacles.size(), 8u);
    EXPECT_EQ(sc->arena.obstacles[5].radius, r.index < 8 ? 0.1 : 0.08);
    EXPECT_EQ(r.assist, r.index < 8 ? Assistance::on : Assistance::off);
    EXPECT_FALSE(r.duration);
  }
  EXPECT_TRUE(p.notes.empty());
}

TEST(Sweep, KeysAndTablesTheFileLeavesOutAreAdded) {
  // A scenario of the least it must say: no [plant] at all, [controller] only through its
  // sub-table's header. (The base may be any readable file: the system's temporary folder.)
  const std::string base = "name = \"bare\"\nmode = \"mixed_initiative\"\nmodel = \"mikrokopter\"\n"
                           "pilot = \"reckless\"\n"
                           "[controller.weights]\nr = 70.0\n";
  const std::string file = (test::process_temp_dir() / "sweep_bare_scenario.toml").string();
  std::FILE* f = std::fopen(file.c_str(), "w");
  ASSERT_TRUE(f);
  std::fputs(base.c_str(), f);
  std::fclose(f);
  std::string error;
  const auto p = parse_sweep("scenario = \"" + file + "\"\n[set]\nduration = 5\n"
                             "controller.N = 40\n[grid]\n\"plant.input_delay\" = [0.0, 0.03]\n",
                             kSweepFile, error);
  ASSERT_TRUE(p) << error;
  for (const SweepRun& r : p->runs) {
    const auto sc = parse_scenario(r.scenario_text, p->scenario_file, error);
    ASSERT_TRUE(sc) << error << "\n" << r.scenario_text;
    EXPECT_EQ(sc->duration, 5.0);
    EXPECT_EQ(sc->controller.N, 40);
    EXPECT_EQ(sc->controller.weights.r, 70.0);
    EXPECT_EQ(sc->plant.input_delay, r.index == 0 ? 0.0 : 0.03);
  }
}

TEST(Sweep, ErrorsNameTheLineAndWhatWasExpected) {
  const std::string head = "scenario = \"../tracking_smooth_step.toml\"\n";
  const std::string mi = "scenario = \"../mi_helix.toml\"\n";
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {head + "sedes = [1]\n[grid]\n\"plant.rtt\" = [0.0]\n", "test.toml:2:1: sedes: unknown key"},
      {"[grid]\n\"plant.rtt\" = [0.0]\n", "test.toml:1:1: scenario: missing required key"},
      {head + "[grid]\n", "test.toml:2:1: grid: an empty grid"},
      {head + "[grid]\n\"plant.rtt\" = []\n", "test.toml:3:15: grid.plant.rtt: an empty list"},
      {head + "[grid]\n\"plant.rtt\" = 0.01\n",
       "test.toml:3:15: grid.plant.rtt: expected an array of the values to try, got 0.01 (a "
       "value for every run goes in [set])"},
      {head + "[grid]\n\"controller.N\" = [10, 20.5]\n",
       "test.toml:3:23: grid.controller.N[1]: expected an integer like the scenario's value 50, "
       "got 20.5"},
      {head + "[grid]\n\"controller.compensation\" = [\"yes\"]\n",
       "test.toml:3:30: grid.controller.compensation[0]: expected true or false"},
      {head + "[grid]\n\"plant.rtt.x\" = [1]\n",
       "test.toml:3:18: grid.plant.rtt.x[0]: plant.rtt is 0.06 in the scenario, not a table"},
      {head + "[grid]\n\"plant\" = [1]\n", "grid.plant[0]: a table in the scenario: expected the key of a value inside it"},
      {head + "[grid]\n\"plant.start[3]\" = [1.0]\n", "has 3 elements: index 3 is out of range"},
      {head + "[grid]\n\"plant..rtt\" = [1.0]\n", "expected a key path of the scenario"},
      {head + "[grid]\n\"plant.rtt\" = [0.0, 0.0]\n", "the value 0.0 is given twice"},
      {head + "[set]\n\"plant.rtt\" = 0.0\n[grid]\n\"plant.rtt\" = [0.01]\n",
       "test.toml:5:16: plant.rtt: given in [set] and again in [grid]"},
      {head + "[set]\n\"plant.start\" = [0.0, 0.0, 0.5]\n[grid]\n\"plant.start[2]\" = [0.4]\n",
       "plant.start[2]: overlaps plant.start"},
      {head + "duration = 3\n[grid]\nduration = [1, 2]\n",
       "duration: given in the top-level duration and again in [grid]"},
      {head + "seeds = [1, 2]\n", "test.toml:2:9: seeds: seeds set plant.seed"},
      {head + "pilots = [\"novice\"]\n", "pilot profiles fly mixed_initiative scenarios"},
      {head + "[grid]\nassist = [\"off\"]\n", "assist (fly --assist) is for mixed_initiative"},
      {mi + "[grid]\nassist = [\"maybe\"]\n", "expected \"on\" or \"off\", got \"maybe\""},
      {mi + "[grid]\nfloor = [1.5]\n", "expected a number from 0 to 1"},
      {mi + "[set]\nfloor = 0.6\nceiling = 0.4\n[grid]\n\"plant.seed\" = [1]\n",
       "floor 0.6 above ceiling 0.4"},
      {mi + "pilots = [\"novice\", 3]\n", "pilots[1]: expected a pilot profile's name"},
      {head, "nothing to sweep"},
      {head + "[grid]\n\"plant.rtt\" = [0.0\n", "test.toml:3:"},
      {"scenario = \"../no_such_scenario.toml\"\n[grid]\nx = [1]\n",
       "test.toml:1:12: scenario: cannot be read"},
      {"scenario = \"no_such_shipped_scenario\"\n[grid]\nx = [1]\n",
       "expected a shipped scenario's name"},
      {"scenario = \"../../x/../etc\"\n[grid]\nx = [1]\n", "or a path ending in .toml"},
      {head + "[[runs]]\n[[runs]]\n\"plant.rtt\" = 0.01\n", "runs[0]: an empty run"},
      {head + "runs = 3\n", "runs: expected [[runs]] tables"},
      {head + "[grid]\nx = [{a = 1}]\n", "expected a number, a boolean, a string or an array"},
  };
  for (const Case& c : cases) {
    const std::string error = must_fail(c.text);
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "sweep file:\n" << c.text << "\nerror:\n" << error << "\nexpected: " << c.expected;
  }
}

TEST(Sweep, TooManyRunsAreRefusedBeforeExpanding) {
  std::string values;
  for (int i = 0; i < 101; ++i) values += (i ? ", " : "") + std::to_string(i * 1e-4);
  const std::string error = must_fail("scenario = \"../tracking_smooth_step.toml\"\n[grid]\n"
                                      "\"plant.rtt\" = [" + values + "]\n\"plant.measurement_fraction\" = [" +
                                      values + "]\n");
  EXPECT_NE(error.find("expands to more than 10000 runs"), std::string::npos) << error;
}

TEST(Sweep, TheScenarioLoadersComplaintIsSaidAtTheSweepsLine) {
  // The sweep reads (every key exists or may be added); the scenario refuses some runs.
  const SweepPlan p = must_plan(R"(
scenario = "../tracking_smooth_step.toml"
[grid]
"plant.rtt" = [0.03, 2.0]
"controller.thetta" = [1.0]
"reference.nowhere.x" = [1]
)");
  ASSERT_EQ(p.runs.size(), 2u);
  std::string error;
  EXPECT_FALSE(make_mode(p.runs[1].scenario_text, p.scenario_file, {}, error));
  std::string said;
  for (const std::string& line : explain_run_error(p, p.runs[1], error)) said += line + "\n";
  // The value out of range at its line in the sweep file, the unknown keys at their own: the
  // scenario's words, in `file:line:col: key: what`.
  EXPECT_NE(said.find(kSweepFile + ":4:22: plant.rtt: value outside [0, 1], got 2.0\n"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find(kSweepFile + ":5:24: controller.thetta: unknown key"), std::string::npos)
      << said;
  EXPECT_NE(said.find(kSweepFile + ":6:26: reference.nowhere: unknown key"), std::string::npos)
      << said;
  // A complaint about a key no setting names is the scenario's, with the run's settings.
  const std::vector<std::string> other = explain_run_error(
      p, p.runs[0], p.scenario_file + ":30:3: reference.file: cannot open file (gone)");
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0], kSweepFile + ":2:12: scenario: " + p.scenario_file +
                          " with plant.rtt = 0.03, controller.thetta = 1.0, "
                          "reference.nowhere.x = 1: reference.file: cannot open file (gone)");
}

TEST(Sweep, SeedsWithoutNoiseAreNoted) {
  const SweepPlan p = must_plan("scenario = \"../mi_helix.toml\"\nseeds = [1, 2]\n");
  ASSERT_EQ(p.notes.size(), 1u);
  EXPECT_NE(p.notes[0].find("plant.position_noise is 0"), std::string::npos);
}

TEST(Sweep, AShippedScenariosNameIsFoundInTheDataFolder) {
  // The test executable's data folder is the build tree's share/mixpilot (the install layout).
  std::string error;
  const auto p = parse_sweep("scenario = \"tracking_helix\"\n[grid]\n\"controller.N\" = [10, 20]\n",
                             testing::TempDir() + "anywhere.toml", error);
  ASSERT_TRUE(p) << error;
  EXPECT_TRUE(p->scenario_file.ends_with("/scenarios/tracking_helix.toml")) << p->scenario_file;
  EXPECT_EQ(p->name, "anywhere");
}

TEST(Sweep, ThePlansHashChangesWithWhatIsFlownOnly) {
  const std::string text = "scenario = \"../tracking_smooth_step.toml\"\n[grid]\n"
                           "\"plant.rtt\" = [0.0, 0.012]\n";
  const SweepPlan a = must_plan(text);
  const SweepPlan same = must_plan("# a comment\n" + text);
  std::string error;
  const auto renamed = parse_sweep(text, kScenarios + "sweeps/renamed.toml", error);
  ASSERT_TRUE(renamed) << error;
  EXPECT_EQ(a.sha256, renamed->sha256);
  const SweepPlan other_value = must_plan("scenario = \"../tracking_smooth_step.toml\"\n[grid]\n"
                                          "\"plant.rtt\" = [0.0, 0.015]\n");
  const SweepPlan shorter = must_plan(text + "[set]\n\"controller.N\" = 40\n");
  const SweepPlan longer = must_plan("duration = 3\n" + text);
  EXPECT_EQ(a.sha256.size(), 64u);
  EXPECT_EQ(a.sha256, same.sha256);
  EXPECT_NE(a.sha256, other_value.sha256);
  EXPECT_NE(a.sha256, shorter.sha256);
  EXPECT_NE(a.sha256, longer.sha256);
  // plan.json carries it, and every run's id and parameters.
  const auto j = parse_json(sweep_plan_json(a, "mixpilot test"), error);
  ASSERT_TRUE(j) << error;
  ASSERT_TRUE(j->string_at("plan_sha256"));
  EXPECT_EQ(*j->string_at("plan_sha256"), a.sha256);
  ASSERT_TRUE(j->get("runs"));
  ASSERT_EQ(j->get("runs")->items.size(), 2u);
  EXPECT_EQ(*j->get("runs")->items[1].string_at("id"), "0001-rtt=0.012");
  EXPECT_EQ(j->get("runs")->items[1].get("parameters")->number_at("plant.rtt")->number, 0.012);
}

TEST(Sweep, ShardsPartitionThePlan) {
  for (std::int64_t n = 1; n <= 9; ++n) {
    for (std::size_t total : {0u, 1u, 5u, 40u, 41u, 97u}) {
      std::vector<int> owners(total, 0);
      std::vector<std::size_t> sizes;
      for (std::int64_t i = 1; i <= n; ++i) {
        std::size_t size = 0;
        for (std::size_t k = 0; k < total; ++k)
          if (in_shard(k, Shard{i, n})) ++owners[k], ++size;
        sizes.push_back(size);
      }
      for (std::size_t k = 0; k < total; ++k) EXPECT_EQ(owners[k], 1) << k << " of " << total << ", n " << n;
      // Even to within one run.
      EXPECT_LE(*std::max_element(sizes.begin(), sizes.end()) -
                    *std::min_element(sizes.begin(), sizes.end()),
                1u);
    }
  }
  EXPECT_TRUE(in_shard(0, Shard{1, 4}));
  EXPECT_TRUE(in_shard(5, Shard{2, 4}));
  for (const char* bad : {"", "1", "0/3", "4/3", "1/0", "-1/3", "1/3/4", "a/b", "1 /3", "1/1000001",
                          "99999999999/99999999999"})
    EXPECT_FALSE(parse_shard(bad)) << bad;
  const auto s = parse_shard("3/7");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->index, 3);
  EXPECT_EQ(s->count, 7);
}

TEST(Sweep, TheJsonReaderReadsWhatTheReportsWrite) {
  std::string error;
  const auto j = parse_json(
      R"({"a": "x\"\\\n\u00e9\ud83d\ude00", "n": -1.25e-3, "z": 0, "t": true, "f": false,
          "nil": null, "arr": [1, [2, {}], []], "o": {"k": 17.000000000000004}})",
      error);
  ASSERT_TRUE(j) << error;
  EXPECT_EQ(*j->string_at("a"), "x\"\\\n\xc3\xa9\xf0\x9f\x98\x80");
  EXPECT_EQ(j->number_at("n")->number, -1.25e-3);
  EXPECT_EQ(j->number_at("n")->text, "-1.25e-3");
  EXPECT_TRUE(j->get("t")->boolean);
  EXPECT_TRUE(j->get("nil")->is(JsonValue::Type::null));
  EXPECT_EQ(j->get("arr")->items.size(), 3u);
  EXPECT_EQ(j->get("o")->number_at("k")->text, "17.000000000000004");
  for (const char* bad : {"", "{", "{\"a\" 1}", "[1,]", "01", "1.", "-", "\"\\x\"", "\"a",
                          "{\"a\": 1} x", "\"\\ud800\"", "nul", "\"\x01\""})
    EXPECT_FALSE(parse_json(bad, error)) << bad;
  EXPECT_FALSE(parse_json(std::string(100, '['), error));
  EXPECT_NE(error.find("nested more than 64"), std::string::npos) << error;
  EXPECT_FALSE(parse_json("{\n  \"a\": x}", error));
  EXPECT_EQ(error, "line 2, column 8: expected a JSON value");
  EXPECT_EQ(json_quote("a\"b\\c\n"), "\"a\\\"b\\\\c\\u000a\"");
}

TEST(Sweep, TheTableHasTheKeysThenTheLabelsThenTheValuesThenTheTimingFields) {
  std::string error;
  const auto a = parse_json(
      R"({"mode": "m", "rti_median_us": 7.5, "skill": 0.10000000000000001, "note": "a,b"})", error);
  const auto b = parse_json(R"({"mode": "m", "skill": 1e-3, "lost": null, "wall_s": 2})", error);
  ASSERT_TRUE(a && b);
  const std::vector<ReportRow> rows = {
      {{{"index", "0"}, {"id", "0000-x=1"}, {"x", "1"}}, &*a},
      {{{"index", "1"}, {"id", "0001-x=\"q\""}, {"x", "\"q\""}}, &*b},
  };
  EXPECT_EQ(report_table_csv(rows),
            "index,id,x,mode,note,skill,lost,rti_median_us,wall_s\n"
            "0,0000-x=1,1,m,\"a,b\",0.1,,7.5,\n"
            "1,\"0001-x=\"\"q\"\"\",\"\"\"q\"\"\",m,,0.001,,,2\n");
  for (const char* t : {"rti_median_us", "rti_p99_us", "lqr_median_us", "predictor_median_us",
                        "rti_max_us", "deadline_misses", "wall_s"})
    EXPECT_TRUE(is_timing_field(t)) << t;
  for (const char* t : {"skill", "fallbacks", "tracking_rms_m", "steps", "settle_time_s"})
    EXPECT_FALSE(is_timing_field(t)) << t;
}

}  // namespace
}  // namespace mixpilot
