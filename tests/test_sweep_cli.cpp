// `mixpilot sweep` and `mixpilot score DIR` as a user runs them (docs/sweeps.md): a small
// sweep flown twice (the second flies nothing), killed halfway and run again (only the missing
// runs fly, and the table equals an uninterrupted run's but for the timing fields), --jobs 2
// against --jobs 1, shards and the merge naming what is missing, a changed sweep file refused,
// and a folder of recordings scored in shards that cover each recording exactly once.
// The flights are short (4 s of the tracking smooth step, 2 s of mi_helix).
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/base/json.hpp"
#include "core/base/report_table.hpp"
#include "run_mixpilot.hpp"
#include "spawned.hpp"
#include "sweep_table.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

const std::string kScenarios = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/";

// 8 runs of 4 s: four round trips, with and without the predictor (without it, 30 ms and
// 60 ms are beyond the loop's delay margin: the vehicle flies away).
const std::string kTrackingSweep =
    "scenario = \"" + kScenarios + "tracking_smooth_step.toml\"\n"
    "duration = 4\n"
    "[grid]\n"
    "\"plant.rtt\" = [0.0, 0.012, 0.03, 0.06]\n"
    "\"controller.compensation\" = [true, false]\n";
constexpr std::size_t kTrackingRuns = 8;

// A fresh folder of this test process, with the user's folders of run_mixpilot in it.
fs::path home_of(const std::string& name) {
  const fs::path home = test::fresh_path("sweep_cli", name);
  fs::create_directories(home);
  return home;
}

fs::path write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p;
}

std::set<std::string> run_files(const fs::path& dir) {
  std::set<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir / "runs", ec))
    if (e.path().extension() == ".json") out.insert(e.path().filename().string());
  return out;
}

// Lines of `text` matching `re`.
std::size_t count_lines(const std::string& text, const std::string& re) {
  const std::regex r(re);
  std::size_t n = 0;
  std::size_t from = 0;
  while (from < text.size()) {
    std::size_t eol = text.find('\n', from);
    if (eol == std::string::npos) eol = text.size();
    if (std::regex_search(text.substr(from, eol - from), r)) ++n;
    from = eol + 1;
  }
  return n;
}

int sweep(const fs::path& home, const std::string& args, const std::string& out = "out.txt") {
  return test::run_mixpilot(MIXPILOT_BINARY, "sweep " + args, home, out);
}

// The uninterrupted reference: the tracking sweep with --jobs 1.
struct Reference {
  fs::path home, file, dir;
};
const Reference& reference() {
  static const Reference r = [] {
    Reference ref;
    ref.home = home_of("reference");
    ref.file = write(ref.home / "tracking.toml", kTrackingSweep);
    ref.dir = ref.home / "results";
    const int rc = sweep(ref.home, ref.file.string() + " --out " + ref.dir.string() + " --jobs 1");
    EXPECT_EQ(rc, 0) << test::read_file(ref.home / "out.txt");
    return ref;
  }();
  return r;
}

TEST(Sweep, ASweepFliesEveryRunIntoItsFolderAndTheSecondTimeFliesNothing) {
  const Reference& ref = reference();
  const std::string said = test::read_file(ref.home / "out.txt");
  EXPECT_NE(said.find("8 runs in " + ref.dir.string() + ", 0 finished, 8 to fly on 1 job"),
            std::string::npos)
      << said;
  EXPECT_EQ(count_lines(said, "mixpilot sweep: \\[[0-9]+/8\\] "), kTrackingRuns) << said;
  EXPECT_NE(said.find("[8/8]"), std::string::npos) << said;
  ASSERT_EQ(run_files(ref.dir).size(), kTrackingRuns);
  const auto table = test::read_csv_table(ref.dir / "table.csv");
  ASSERT_EQ(table.size(), 1 + kTrackingRuns);
  // The parameters as columns, then the report's fields, the timing ones last.
  const std::vector<std::string>& h = table[0];
  ASSERT_GE(h.size(), 6u);
  EXPECT_EQ(std::vector<std::string>(h.begin(), h.begin() + 4),
            (std::vector<std::string>{"index", "id", "plant.rtt", "controller.compensation"}));
  EXPECT_EQ(h.back(), "wall_s");
  const auto col = [&](const std::string& name) {
    return std::size_t(std::find(h.begin(), h.end(), name) - h.begin());
  };
  ASSERT_LT(col("tracking_rms_m"), h.size());
  EXPECT_LT(col("tracking_rms_m"), col("rti_median_us"));
  EXPECT_EQ(table[1][1], "0000-rtt=0-compensation=true");
  EXPECT_EQ(table[8][1], "0007-rtt=0.06-compensation=false");
  EXPECT_GT(std::stod(table[8][col("tracking_rms_m")]), 1.0);   // beyond the margin, no predictor
  EXPECT_LT(std::stod(table[7][col("tracking_rms_m")]), 0.05);  // the predictor flies 60 ms
  EXPECT_EQ(table[3][col("rtt_s")], "0.012");
  // A run's file: the plan's, its parameters and fly --report's fields.
  std::string error;
  const auto run = parse_json(test::read_file(ref.dir / "runs" / "0003-rtt=0.012-compensation=false.json"), error);
  ASSERT_TRUE(run) << error;
  EXPECT_EQ(run->get("parameters")->number_at("plant.rtt")->number, 0.012);
  EXPECT_FALSE(run->get("parameters")->get("controller.compensation")->boolean);
  EXPECT_EQ(*run->get("report")->string_at("mode"), "crazyflie_tracking");
  EXPECT_EQ(run->get("report")->number_at("rtt_s")->number, 0.012);
  EXPECT_EQ(run->get("report")->number_at("compensation")->number, 0.0);

  // Again: nothing to fly, the run files untouched, the same table.
  std::map<std::string, fs::file_time_type> times;
  for (const std::string& f : run_files(ref.dir)) times[f] = fs::last_write_time(ref.dir / "runs" / f);
  ASSERT_EQ(sweep(ref.home, ref.file.string() + " --out " + ref.dir.string(), "again.txt"), 0)
      << test::read_file(ref.home / "again.txt");
  const std::string again = test::read_file(ref.home / "again.txt");
  EXPECT_NE(again.find("8 finished, 0 to fly"), std::string::npos) << again;
  EXPECT_EQ(count_lines(again, "mixpilot sweep: \\[[0-9]+/8\\] "), 0u) << again;
  for (const auto& [f, t] : times) EXPECT_EQ(fs::last_write_time(ref.dir / "runs" / f), t) << f;
  EXPECT_EQ(test::read_csv_table(ref.dir / "table.csv"), table);
}

TEST(Sweep, ARunFileThatIsNotThisPlansIsFlownAgainAndForceFliesAgain) {
  const Reference& ref = reference();
  const fs::path home = home_of("replaced");
  const fs::path dir = home / "results";
  fs::copy(ref.dir, dir, fs::copy_options::recursive);
  const fs::path file = write(home / "tracking.toml", kTrackingSweep);
  // One cut short (no writer of mixpilot leaves one: an editor's or a copy's), one of
  // another plan, and the temporary of a run killed while writing.
  write(dir / "runs" / "0002-rtt=0.012-compensation=true.json", "{\"format\": \"mixpilot sw");
  const std::string other = std::regex_replace(
      test::read_file(dir / "runs" / "0005-rtt=0.03-compensation=false.json"),
      std::regex("\"plan_sha256\": \"[0-9a-f]+\""), "\"plan_sha256\": \"0123\"");
  write(dir / "runs" / "0005-rtt=0.03-compensation=false.json", other);
  write(dir / "runs" / "0002-rtt=0.012-compensation=true.json.Ab12Cd.tmp", "{");
  // The merge will not take them.
  EXPECT_EQ(sweep(home, file.string() + " --out " + dir.string() + " --merge", "merge.txt"), 1);
  const std::string merge = test::read_file(home / "merge.txt");
  EXPECT_NE(merge.find("0002-rtt=0.012-compensation=true.json: not a run's JSON"), std::string::npos) << merge;
  EXPECT_NE(merge.find("0005-rtt=0.03-compensation=false.json: a run of another plan (plan_sha256 0123"),
            std::string::npos)
      << merge;
  // The sweep flies them again, and only them.
  ASSERT_EQ(sweep(home, file.string() + " --out " + dir.string()), 0) << test::read_file(home / "out.txt");
  const std::string said = test::read_file(home / "out.txt");
  EXPECT_NE(said.find("6 finished, 2 to fly"), std::string::npos) << said;
  EXPECT_EQ(count_lines(said, "\\] 0002-rtt=0.012-compensation=true: "), 1u) << said;
  EXPECT_EQ(count_lines(said, "\\] 0005-rtt=0.03-compensation=false: "), 1u) << said;
  for (const auto& e : fs::directory_iterator(dir / "runs"))
    EXPECT_EQ(e.path().extension(), ".json") << e.path();
  EXPECT_EQ(test::non_timing(test::read_csv_table(dir / "table.csv")), test::non_timing(test::read_csv_table(ref.dir / "table.csv")));
  // --force flies the selected runs whether finished or not.
  const auto before = fs::last_write_time(dir / "runs" / "0003-rtt=0.012-compensation=false.json");
  ASSERT_EQ(sweep(home, file.string() + " --out " + dir.string() + " --force --shard 4/8", "force.txt"), 0)
      << test::read_file(home / "force.txt");
  EXPECT_NE(test::read_file(home / "force.txt").find("0 finished, 1 to fly"), std::string::npos)
      << test::read_file(home / "force.txt");
  EXPECT_NE(fs::last_write_time(dir / "runs" / "0003-rtt=0.012-compensation=false.json"), before);
}

TEST(Sweep, KilledHalfwayItFliesOnlyTheMissingRunsAndTheTableEqualsAnUninterruptedOne) {
  const Reference& ref = reference();
  const fs::path home = home_of("killed");
  const fs::path file = write(home / "tracking.toml", kTrackingSweep);
  const fs::path dir = home / "results";
  {
    test::Spawned p({MIXPILOT_BINARY, "sweep", file.string(), "--out", dir.string(), "--jobs", "1"},
                    home / "killed.txt",
                    {{"XDG_CONFIG_HOME", (home / "config").string()},
                     {"XDG_DATA_HOME", (home / "data").string()}});
    // About half the runs finished, then SIGKILL: no handler, no clean-up.
    const auto until = std::chrono::steady_clock::now() + std::chrono::minutes(5);
    while (run_files(dir).size() < kTrackingRuns / 2 && p.wait(0) < 0 &&
           std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ::kill(p.pid(), SIGKILL);
    EXPECT_EQ(p.wait(60), 128 + SIGKILL) << test::read_file(home / "killed.txt");
  }
  const std::set<std::string> before = run_files(dir);
  ASSERT_GE(before.size(), kTrackingRuns / 2);
  ASSERT_LT(before.size(), kTrackingRuns) << "the sweep ended before it was killed";
  // Every run file there is whole.
  std::map<std::string, std::string> texts;
  for (const std::string& f : before) {
    std::string error;
    texts[f] = test::read_file(dir / "runs" / f);
    EXPECT_TRUE(parse_json(texts[f], error)) << f << ": " << error;
  }
  EXPECT_FALSE(fs::exists(dir / "table.csv"));

  ASSERT_EQ(sweep(home, file.string() + " --out " + dir.string() + " --jobs 1", "resumed.txt"), 0)
      << test::read_file(home / "resumed.txt");
  const std::string resumed = test::read_file(home / "resumed.txt");
  const std::size_t missing = kTrackingRuns - before.size();
  EXPECT_NE(resumed.find(std::to_string(before.size()) + " finished, " + std::to_string(missing) +
                         " to fly"),
            std::string::npos)
      << resumed;
  EXPECT_EQ(count_lines(resumed, "mixpilot sweep: \\[[0-9]+/8\\] "), missing) << resumed;
  for (const auto& [f, text] : texts) EXPECT_EQ(test::read_file(dir / "runs" / f), text) << f;
  // No temporary of a killed run is left.
  for (const auto& e : fs::directory_iterator(dir / "runs"))
    EXPECT_EQ(e.path().extension(), ".json") << e.path();
  EXPECT_EQ(test::non_timing(test::read_csv_table(dir / "table.csv")), test::non_timing(test::read_csv_table(ref.dir / "table.csv")));
}

TEST(Sweep, TwoJobsGiveTheTableOfOne) {
  const Reference& ref = reference();
  const fs::path home = home_of("jobs2");
  const fs::path file = write(home / "tracking.toml", kTrackingSweep);
  ASSERT_EQ(sweep(home, file.string() + " --out " + (home / "results").string() + " --jobs 2"), 0)
      << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("8 to fly on 2 jobs"), std::string::npos);
  const auto two = test::read_csv_table(home / "results" / "table.csv");
  const auto one = test::read_csv_table(ref.dir / "table.csv");
  ASSERT_EQ(two.size(), one.size());
  EXPECT_EQ(test::non_timing(two), test::non_timing(one));
  // The comparison has something to compare: the measured fields are there and differ by run.
  const auto nt = test::non_timing(one);
  const std::size_t rms = std::size_t(std::find(nt[0].begin(), nt[0].end(), "tracking_rms_m") - nt[0].begin());
  ASSERT_LT(rms, nt[0].size());
  EXPECT_NE(nt[1][rms], nt[4][rms]);  // 0 ms against 12 ms without the predictor
}

TEST(Sweep, ShardsFlyTheirRunsOnlyAndTheMergeNamesWhatIsMissing) {
  const Reference& ref = reference();
  const fs::path home = home_of("shards");
  const fs::path file = write(home / "tracking.toml", kTrackingSweep);
  const std::string dir = (home / "results").string();
  ASSERT_EQ(sweep(home, file.string() + " --out " + dir + " --shard 2/3", "s2.txt"), 0)
      << test::read_file(home / "s2.txt");
  EXPECT_EQ(run_files(dir), (std::set<std::string>{"0001-rtt=0-compensation=false.json",
                                                   "0004-rtt=0.03-compensation=true.json",
                                                   "0007-rtt=0.06-compensation=false.json"}));
  EXPECT_FALSE(fs::exists(fs::path(dir) / "table.csv"));  // a shard does not merge
  EXPECT_EQ(sweep(home, file.string() + " --out " + dir + " --merge", "m1.txt"), 1);
  const std::string m1 = test::read_file(home / "m1.txt");
  EXPECT_NE(m1.find("5 of 8 runs are missing, no table written: 0000-rtt=0-compensation=true, "
                    "0002-rtt=0.012-compensation=true, 0003-rtt=0.012-compensation=false, "
                    "0005-rtt=0.03-compensation=false, 0006-rtt=0.06-compensation=true"),
            std::string::npos)
      << m1;
  EXPECT_FALSE(fs::exists(fs::path(dir) / "table.csv"));
  for (const char* s : {"1/3", "3/3"})
    ASSERT_EQ(sweep(home, file.string() + " --out " + dir + " --shard " + s + " --jobs 2", "s.txt"), 0)
        << test::read_file(home / "s.txt");
  EXPECT_EQ(run_files(dir).size(), kTrackingRuns);
  ASSERT_EQ(sweep(home, file.string() + " --out " + dir + " --merge", "m2.txt"), 0)
      << test::read_file(home / "m2.txt");
  EXPECT_EQ(test::non_timing(test::read_csv_table(fs::path(dir) / "table.csv")),
            test::non_timing(test::read_csv_table(ref.dir / "table.csv")));
}

TEST(Sweep, AChangedSweepFileIsRefusedOnTheFolderOfAnother) {
  const Reference& ref = reference();
  const fs::path home = home_of("changed");
  const fs::path file = write(home / "tracking.toml",
                              std::regex_replace(kTrackingSweep, std::regex("0\\.03,"), "0.024,"));
  EXPECT_EQ(sweep(home, file.string() + " --out " + ref.dir.string()), 1);
  const std::string said = test::read_file(home / "out.txt");
  EXPECT_NE(said.find(ref.dir.string() + " holds the results of another plan"), std::string::npos)
      << said;
  EXPECT_NE(said.find("its run 4 is 0004-rtt=0.03-compensation=true, this plan's "
                      "0004-rtt=0.024-compensation=true"),
            std::string::npos)
      << said;
  EXPECT_EQ(sweep(home, file.string() + " --out " + ref.dir.string() + " --merge", "m.txt"), 1);
  // A folder that is not a sweep's.
  fs::create_directories(home / "other");
  write(home / "other" / "notes.txt", "mine");
  EXPECT_EQ(sweep(home, file.string() + " --out " + (home / "other").string(), "o.txt"), 1);
  EXPECT_NE(test::read_file(home / "o.txt").find("is not empty and holds no plan.json"),
            std::string::npos);
}

TEST(Sweep, TheCommandLineSaysWhatItExpects) {
  const fs::path home = home_of("usage");
  const fs::path file = write(home / "tracking.toml", kTrackingSweep);
  const std::string f = file.string();
  struct Case {
    std::string args;
    int status;
    std::string said;
  };
  const std::vector<Case> cases = {
      {"", 2, "which sweep file?"},
      {f + " --shard 0/3", 2, "--shard expects i/n with whole numbers 1 <= i <= n"},
      {f + " --shard 4/3", 2, "--shard expects i/n"},
      {f + " --jobs 0", 2, "--jobs expects a whole number from 1 to 256"},
      {f + " --merge --shard 1/2", 2, "--merge only gathers"},
      {f + " --merge --jobs 2", 2, "--merge only gathers"},
      {f + " --check --force", 2, "--check only reads the sweep file"},
      {f + " --out", 2, "--out needs a value"},
      {f + " " + f, 2, "one sweep file at a time"},
      {f + " --frobnicate", 2, "unknown option '--frobnicate'"},
      {(home / "missing.toml").string(), 1, "missing.toml: cannot open file"},
      {home.string(), 1, "expected a regular file"},
      {f + " --merge --out " + (home / "nothing").string(), 1, "no such folder"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(sweep(home, c.args), c.status) << c.args << "\n" << test::read_file(home / "out.txt");
    EXPECT_NE(test::read_file(home / "out.txt").find(c.said), std::string::npos)
        << c.args << "\n" << test::read_file(home / "out.txt");
  }
  // --check prints the plan and writes nothing.
  ASSERT_EQ(sweep(home, f + " --check"), 0) << test::read_file(home / "out.txt");
  const std::string plan = test::read_file(home / "out.txt");
  EXPECT_NE(plan.find("8 runs of " + kScenarios + "tracking_smooth_step.toml, 4 s each"),
            std::string::npos)
      << plan;
  EXPECT_NE(plan.find("  0007-rtt=0.06-compensation=false\n"), std::string::npos) << plan;
  EXPECT_FALSE(fs::exists(home / "tracking"));
  // A run the scenario refuses: said at the sweep file's line, before anything flies.
  const fs::path bad = write(home / "bad.toml", "scenario = \"" + kScenarios +
                                                    "tracking_smooth_step.toml\"\n[grid]\n"
                                                    "\"plant.rtt\" = [0.0, 1.5]\n");
  EXPECT_EQ(sweep(home, bad.string() + " --out " + (home / "bad").string()), 1);
  EXPECT_NE(test::read_file(home / "out.txt")
                .find(bad.string() + ":3:21: plant.rtt: value outside [0, 1], got 1.5 (run "
                                     "0001-rtt=1.5)"),
            std::string::npos)
      << test::read_file(home / "out.txt");
  EXPECT_FALSE(fs::exists(home / "bad"));
}

TEST(Sweep, AFolderOfRecordingsIsScoredInShardsThatCoverEachRecordingOnce) {
  // Four recorded flights of mi_helix (a sweep with record = true), scored in three shards.
  const fs::path home = home_of("score");
  const fs::path file = write(home / "pilots.toml",
                              "scenario = \"" + kScenarios + "mi_helix.toml\"\n"
                              "duration = 2\nrecord = true\n"
                              "pilots = [\"novice\", \"experienced\"]\n"
                              "[grid]\n\"controller.ph.r\" = [0.15, 0.175]\n");
  const fs::path flown = home / "flown";
  ASSERT_EQ(sweep(home, file.string() + " --out " + flown.string()), 0)
      << test::read_file(home / "out.txt");
  const fs::path recordings = flown / "recordings";
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(recordings)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names.size(), 4u);
  EXPECT_EQ(names[0], "0000-r=0.15-pilot=novice.mcap");

  const fs::path scores = home / "scores";
  std::set<std::string> seen;
  std::map<int, std::set<std::string>> by_shard;
  for (int i = 1; i <= 3; ++i) {
    const std::string out = "shard" + std::to_string(i) + ".txt";
    ASSERT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                                 "score " + recordings.string() + " --out " + scores.string() +
                                     " --shard " + std::to_string(i) + "/3",
                                 home, out),
              0)
        << test::read_file(home / out);
    const std::set<std::string> now = run_files(scores);
    for (const std::string& f : now)
      if (!seen.count(f)) by_shard[i].insert(f);
    seen = now;
    EXPECT_FALSE(fs::exists(scores / "table.csv"));
  }
  // Shard i scored the recordings of index k with k mod 3 = i − 1, and nothing else.
  EXPECT_EQ(by_shard[1], (std::set<std::string>{"0000-0000-r=0.15-pilot=novice.json",
                                                "0003-0003-r=0.175-pilot=experienced.json"}));
  EXPECT_EQ(by_shard[2], (std::set<std::string>{"0001-0001-r=0.15-pilot=experienced.json"}));
  EXPECT_EQ(by_shard[3], (std::set<std::string>{"0002-0002-r=0.175-pilot=novice.json"}));
  // Run again, nothing is scored twice.
  ASSERT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                               "score " + recordings.string() + " --out " + scores.string() +
                                   " --shard 2/3",
                               home, "again.txt"),
            0);
  EXPECT_NE(test::read_file(home / "again.txt").find("1 scored, 0 to score"), std::string::npos)
      << test::read_file(home / "again.txt");
  ASSERT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                               "score " + recordings.string() + " --out " + scores.string() +
                                   " --merge",
                               home, "merge.txt"),
            0)
      << test::read_file(home / "merge.txt");
  // One row per recording, its replay exact, its score the live flight's.
  const auto table = test::read_csv_table(scores / "table.csv");
  const auto flights = test::read_csv_table(flown / "table.csv");
  ASSERT_EQ(table.size(), 5u);
  ASSERT_EQ(flights.size(), 5u);
  const auto col = [](const std::vector<std::string>& h, const std::string& n) {
    return std::size_t(std::find(h.begin(), h.end(), n) - h.begin());
  };
  for (std::size_t r = 1; r < table.size(); ++r) {
    EXPECT_EQ(table[r][col(table[0], "replay")], "exact");
    EXPECT_EQ(table[r][col(table[0], "file")], (recordings / names[r - 1]).string());
    for (const char* field : {"skill", "mean_lambda", "max_deviation_m", "collisions"})
      EXPECT_EQ(table[r][col(table[0], field)], flights[r][col(flights[0], field)]) << field;
  }
  // A recording added since: another plan, refused.
  fs::copy_file(recordings / names[0], recordings / "zz-added.mcap");
  EXPECT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                               "score " + recordings.string() + " --out " + scores.string(), home,
                               "added.txt"),
            1);
  EXPECT_NE(test::read_file(home / "added.txt").find("it has 4 runs, this plan 5"), std::string::npos)
      << test::read_file(home / "added.txt");
  // Folder options without a folder, and --json with one.
  EXPECT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                               "score " + (recordings / names[0]).string() + " --shard 1/2", home,
                               "u1.txt"),
            2);
  EXPECT_NE(test::read_file(home / "u1.txt").find("--shard goes with a folder of recordings"),
            std::string::npos);
  EXPECT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                               "score " + recordings.string() + " --json x.json", home, "u2.txt"),
            2);
}

}  // namespace
}  // namespace mixpilot
