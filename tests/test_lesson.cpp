// Lessons (SPEC §10, docs/lesson-format.md): the reader (the shipped course, errors that point
// into the file, hostile input), the verdict, the progress in the history (SQLite; the
// PostgreSQL backend in test_postgres.cpp), the schema's forward migration, `mixpilot lesson`
// (its help, --list, --check, --status, --reset, the attempts limit), the beginner course flown
// by the emulated pilots (LessonCourse.*: where each stops, the history, the ceiling rising in
// the recordings and the recorded λ under it), and the window's lesson picker.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "app/lesson.hpp"
#include "app/trainer.hpp"
#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"
#include "core/history/schema.hpp"
#include "core/history/sqlite_history.hpp"
#include "core/recording/recording.hpp"
#include "core/scenario/lesson.hpp"
#include "core/scenario/scenario_toml.hpp"

#include "app_window_test.hpp"
#include "history_test.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
using test::attempt;
using test::flight;
using test::progress_of;

const std::string kSource = MIXPILOT_SOURCE_DIR;
const std::string kBeginner = kSource + "/scenarios/lessons/beginner.toml";

// A lesson's text, parsed as if it were the file `name` in the test's folder.
std::optional<Lesson> parse(const std::string& text, std::string& error,
                            const std::string& name = "x.toml") {
  return parse_lesson(text, (test::fresh_path("lesson_text", name)).string(), error);
}

// The shipped beginner course: five steps from a hover to the helix alone, the ceiling never
// falling, every scenario shipped and a mixed-initiative one.
TEST(Lesson, TheBeginnerCourseReads) {
  std::string error;
  const auto l = load_lesson(kBeginner, error);
  ASSERT_TRUE(l) << error;
  EXPECT_EQ(l->name, "beginner");
  EXPECT_FALSE(l->description.empty());
  ASSERT_EQ(l->steps.size(), 5u);
  EXPECT_EQ(l->hash, sha256_hex(l->source_text));
  const std::vector<std::string> scenarios = {"lesson_hover", "lesson_climb",
                                              "lesson_helix_slow", "mi_helix", "mi_helix"};
  double previous = 0.0;
  for (std::size_t i = 0; i < l->steps.size(); ++i) {
    const LessonStep& s = l->steps[i];
    EXPECT_EQ(s.scenario_name, scenarios[i]) << i;
    EXPECT_EQ(fs::canonical(s.scenario_path),
              fs::canonical(kSource + "/scenarios/" + scenarios[i] + ".toml"))
        << i;
    EXPECT_GT(s.flown_ceiling(), previous) << "step " << i << ": the assistance fades";
    previous = s.flown_ceiling();
    // Each step passable: min_skill below the bound 60 + 40 c a ceiling leaves the skill.
    ASSERT_TRUE(s.pass.min_skill) << i;
    EXPECT_LT(*s.pass.min_skill, 60.0 + 40.0 * s.flown_ceiling()) << i;
    EXPECT_EQ(s.pass.max_collisions, 0) << i;
  }
  EXPECT_FALSE(l->steps[3].probe);
  EXPECT_TRUE(l->steps[4].probe);
  EXPECT_EQ(l->steps[4].flown_ceiling(), 1.0);
  EXPECT_EQ(l->steps[0].ceiling, 0.3);
  EXPECT_EQ(criteria_text(l->steps[0].pass),
            "skill at least 65, no collision, in the ball at least 90 % of the time");
  // Shipped lessons are found by name.
  EXPECT_EQ(fs::path(lesson_path("beginner")).filename(), "beginner.toml");
  EXPECT_EQ(lesson_path("./mine.toml"), "./mine.toml");
}

// One line per problem, each `file:line:col: key path: what was expected`, in file order.
TEST(Lesson, ReaderErrorsPointIntoTheFile) {
  const std::string text =
      "name = \"x\"\n"                                  // 1
      "description = \"y\"\n"                           // 2
      "colour = 3\n"                                    // 3
      "\n"                                              // 4
      "[[steps]]\n"                                     // 5
      "title = \"a\"\n"                                 // 6
      "scenario = \"no_such\"\n"                        // 7
      "ceiling = 0.5\n"                                 // 8
      "[steps.pass]\n"                                  // 9
      "min_skil = 3\n"                                  // 10
      "\n"                                              // 11
      "[[steps]]\n"                                     // 12
      "title = \"b\"\n"                                 // 13
      "scenario = \"" + kSource + "/scenarios/pendubot_swingup.toml\"\n"  // 14
      "ceiling = 0.4\n"                                 // 15
      "[steps.pass]\n"                                  // 16
      "\n"                                              // 17
      "[[steps]]\n"                                     // 18
      "title = \"c\"\n"                                 // 19
      "scenario = \"mi_helix\"\n"                       // 20
      "ceiling = 0.3\n"                                 // 21
      "probe = true\n"                                  // 22
      "attempts = 0\n"                                  // 23
      "[steps.pass]\n"                                  // 24
      "min_skill = 200\n"                               // 25
      "max_collisions = 1.5\n"                          // 26
      "\n"                                              // 27
      "[[steps]]\n"                                     // 28
      "scenario = \"../x/y\"\n"                         // 29
      "ceiling = 0.2\n"                                 // 30
      "pass = 3\n";                                     // 31
  std::string error;
  EXPECT_FALSE(parse(text, error, "errors.toml"));
  const std::string f = test::fresh_path("lesson_text", "errors.toml").string();
  const std::vector<std::string> expected = {
      f + ":3:1: colour: unknown key; expected one of: name description steps",
      f + ":7:12: steps[0].scenario: expected a shipped scenario's name",
      f + ":10:1: steps[0].pass.min_skil: unknown key (did you mean \"min_skill\"?)",
      f + ":14:12: steps[1].scenario: expected a mixed_initiative scenario (a pilot shares the "
          "authority λ there), got \"pendubot_swingup\"",
      f + ":15:11: steps[1].ceiling: expected at least steps[0]'s ceiling 0.5 (passing a step "
          "never lowers the ceiling: the planner's share only fades), got 0.4",
      f + ":16:1: steps[1].pass: expected at least one criterion",
      f + ":21:11: steps[2].ceiling: a probe flies unassisted (λ pinned to 1): expected 1 or no "
          "ceiling, got 0.3",
      f + ":23:12: steps[2].attempts: value outside [1, 1000], got 0",
      f + ":25:13: steps[2].pass.min_skill: value outside [0, 100], got 200",
      f + ":26:18: steps[2].pass.max_collisions: expected an integer, got 1.5",
      f + ":28:1: steps[3].title: missing required key (expected a string)",
      f + ":29:12: steps[3].scenario: expected a shipped scenario's name (letters, digits, _ - .) "
          "or a path ending in .toml, got \"../x/y\"",
      f + ":30:11: steps[3].ceiling: expected at least steps[0]'s ceiling 0.5",
      f + ":31:8: steps[3].pass: expected a table, got 3",
  };
  std::size_t at = 0;
  for (const std::string& e : expected) {
    const std::size_t found = error.find(e, at);
    EXPECT_NE(found, std::string::npos) << "missing (in order): " << e << "\n" << error;
    if (found != std::string::npos) at = found;
  }
  EXPECT_EQ(std::count(error.begin(), error.end(), '\n') + 1, std::ptrdiff_t(expected.size()))
      << error;

  // The whole file's problems: no steps, the wrong types, no TOML at all.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"name = \"x\"\ndescription = \"y\"\n", ":1:1: steps: missing required key"},
      {"name = \"x\"\ndescription = \"y\"\nsteps = []\n",
       ":3:9: steps: expected an array of tables ([[steps]]), at least one, got an array of 0"},
      {"name = 1\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"mi_helix\"\n"
       "ceiling = 1\n[steps.pass]\nmin_skill = 1\n",
       ":1:8: name: expected a non-empty string, got 1"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"mi_helix\"\n"
       "ceiling = 1\n",
       ":3:1: steps[0].pass: missing required table"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"mi_helix\"\n"
       "ceiling = nan\n[steps.pass]\nmin_skill = 1\n",
       ":6:11: steps[0].ceiling: expected a finite number, got nan"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"mi_helix\"\n"
       "ceiling = 0\n[steps.pass]\nmin_skill = 1\n",
       ":6:11: steps[0].ceiling: value outside (0, 1], got 0"},
      {"name = \"x\"\n[[steps]\n", ":2:9: TOML syntax: "},
  };
  for (const auto& [bad, want] : cases) {
    error.clear();
    EXPECT_FALSE(parse(bad, error)) << bad;
    EXPECT_NE(error.find(want), std::string::npos) << "want " << want << "\ngot " << error;
  }
}

// Nothing a file holds crashes or hangs the reader: each is refused with a located reason.
TEST(Lesson, ReaderSurvivesHostileInput) {
  std::string many = "name = \"x\"\ndescription = \"y\"\n";
  for (int i = 0; i < 65; ++i)
    many += "[[steps]]\ntitle = \"a\"\nscenario = \"mi_helix\"\nceiling = 1\n[steps.pass]\n"
            "min_skill = 1\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "name: missing required key"},
      {std::string("\0\x01\xff\xfe", 4), "TOML syntax"},
      {"a" + std::string(100000, '.') + "b = 1\n", "nested more than 32 levels"},
      {"x = " + std::string(5000, '[') + "\n", "nested more than 32 levels"},
      {many, "the number of steps = 65, outside [1, 64]"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"\\u001b[2J\"\n",
       "expected a string without control characters"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"" +
           std::string(5000, 'a') + "\"\nceiling = 1\n[steps.pass]\nmin_skill = 1\n",
       "steps[0].scenario: expected a shipped scenario's name"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"/dev/zero.toml\"\n"
       "ceiling = 1\n[steps.pass]\nmin_skill = 1\n",
       "steps[0].scenario: cannot be read: /dev/zero.toml: cannot open file"},
      {"name = \"x\"\ndescription = \"y\"\n[[steps]]\ntitle = \"a\"\nscenario = \"" + kSource +
           "/scenarios/lessons/beginner.toml\"\nceiling = 1\n[steps.pass]\nmin_skill = 1\n",
       "steps[0].scenario: is not a scenario that loads"},
  };
  for (const auto& [text, want] : cases) {
    std::string error;
    EXPECT_FALSE(parse(text, error)) << want;
    EXPECT_NE(error.find(want), std::string::npos) << "want " << want << "\ngot " << error;
    EXPECT_TRUE(std::regex_search(error, std::regex(R"(x\.toml:\d+:\d+: )"))) << error;
  }
  std::string error;
  EXPECT_FALSE(load_lesson(kSource + "/scenarios", error));
  EXPECT_NE(error.find("expected a regular file, got a directory"), std::string::npos) << error;
  EXPECT_FALSE(load_lesson(kSource + "/no/such.toml", error));
  EXPECT_NE(error.find("cannot open file"), std::string::npos) << error;
}

// Every criterion judged; the first that failed names the verdict; an unfinished flight fails.
TEST(Lesson, TheVerdictNamesTheFirstFailedCriterion) {
  LessonStep step;
  step.pass.min_skill = 70;
  step.pass.max_collisions = 0;
  step.pass.min_time_in_ball = 0.9;
  LessonScore s{80.0, 0.95, 0.0, true};
  LessonVerdict v = judge(step, s);
  EXPECT_TRUE(v.passed);
  EXPECT_EQ(v.failed, "");
  ASSERT_EQ(v.results.size(), 4u);
  EXPECT_EQ(v.results[0].text, "skill 80.0 (at least 70)");
  EXPECT_EQ(v.results[2].text, "in the ball 95.0 % of the time (at least 90 %)");
  s.skill = 70.0;  // the bound itself passes
  EXPECT_TRUE(judge(step, s).passed);
  s.skill = 69.99;
  s.collisions = 1;
  v = judge(step, s);
  EXPECT_FALSE(v.passed);
  EXPECT_EQ(v.failed, "min_skill");
  EXPECT_EQ(v.detail, "skill 70.0 (at least 70)");
  EXPECT_FALSE(v.results[1].passed);
  EXPECT_EQ(v.results[1].text, "1 collision (at most 0)");
  s = {90.0, 0.5, 0.0, true};
  EXPECT_EQ(judge(step, s).failed, "min_time_in_ball");
  s = {90.0, 1.0, 0.0, false};
  v = judge(step, s);
  EXPECT_EQ(v.failed, "completed");
  EXPECT_EQ(v.detail, "not flown to its end");
}

// ---- The history --------------------------------------------------------------------------

TEST(Lesson, ProgressLivesInTheHistory) {
  const fs::path p = test::fresh_path("lesson", "progress.sqlite");
  std::string error;
  auto store = history::open_sqlite(p.string(), error);
  ASSERT_TRUE(store) << error;
  test::progress_round_trip(*store);
}

std::int64_t sql_int(const fs::path& p, const char* sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(p.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &s, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  std::int64_t v = -1;
  if (sqlite3_step(s) == SQLITE_ROW) v = sqlite3_column_int64(s, 0);
  sqlite3_finalize(s);
  sqlite3_close(db);
  return v;
}

// A history of schema 3 (before lessons) is brought to 4 on open; its flights stay and take
// lesson attempts from then on.
TEST(Lesson, TheSchemaMigratesForwardFromVersion3) {
  const fs::path p = test::fresh_path("lesson", "migrate.sqlite");
  std::string error;
  auto store = history::open_sqlite(p.string(), error);
  ASSERT_TRUE(store) << error;
  ASSERT_EQ(store->add(flight("Ada", 1000, 60.0, "old"), error),
            history::HistoryStore::Added::added);
  store.reset();
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(p.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "DROP TABLE lesson_attempts; DROP TABLE lesson_progress; "
                             "ALTER TABLE flights DROP COLUMN ended_by; "
                             "DELETE FROM schema_version WHERE version > 3",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  ASSERT_EQ(sql_int(p, "SELECT max(version) FROM schema_version"), 3);
  store = history::open_sqlite(p.string(), error);
  ASSERT_TRUE(store) << error;
  EXPECT_EQ(sql_int(p, "SELECT max(version) FROM schema_version"), history::kSchemaVersion);
  EXPECT_EQ(history::kSchemaVersion, 5);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM sqlite_master WHERE name = 'lesson_attempts_by_lesson'"),
            1);
  std::vector<history::StoredFlight> rows;
  ASSERT_TRUE(store->query({}, rows, error)) << error;
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].recording_hash, "old");
  EXPECT_EQ(rows[0].lesson_step, -1);
  ASSERT_EQ(store->add_attempt(flight("Ada", 2000, 80.0), attempt(0, true), error),
            history::HistoryStore::Added::added)
      << error;
  EXPECT_EQ(progress_of(*store, "Ada").step, 1);
}

// ---- The command ---------------------------------------------------------------------------

const std::string kBinary = MIXPILOT_BINARY;

// A scenario like lesson_hover, `seconds` long, written as `name` beside the test's lessons.
fs::path short_hover(const fs::path& dir, const std::string& name, double seconds) {
  std::string text = test::read_file(kSource + "/scenarios/lesson_hover.toml");
  text = std::regex_replace(text, std::regex("duration = 10.0"),
                            "duration = " + std::to_string(seconds));
  text = std::regex_replace(text, std::regex("name = \"lesson_hover\""),
                            "name = \"" + name + "\"");
  fs::create_directories(dir);
  std::ofstream(dir / (name + ".toml")) << text;
  return dir / (name + ".toml");
}

// --help tells the truth about the options; --list and --check read the shipped course; usage
// errors exit 2 and a bad lesson 1 with its located reason.
TEST(Lesson, TheCommandLine) {
  const fs::path home = test::fresh_path("lesson_cli", "home");
  fs::create_directories(home);
  ASSERT_EQ(test::run_mixpilot(kBinary, "lesson --help", home), 0);
  const std::string help = test::read_file(home / "out.txt");
  for (const char* option : {"--trainee", "--headless", "--pilot", "--until-done", "--record-dir",
                             "--no-record", "--history", "--status", "--reset", "--check",
                             "--list", "4 the step was flown and did not pass"})
    EXPECT_NE(help.find(option), std::string::npos) << option;
  ASSERT_EQ(test::run_mixpilot(kBinary, "--help", home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("lesson "), std::string::npos);

  ASSERT_EQ(test::run_mixpilot(kBinary, "lesson --list", home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("beginner       5 steps  From a hover"), std::string::npos)
      << test::read_file(home / "out.txt");
  ASSERT_EQ(test::run_mixpilot(kBinary, "lesson beginner --check", home), 0);
  const std::string check = test::read_file(home / "out.txt");
  EXPECT_NE(check.find("1. Hover at a point"), std::string::npos) << check;
  EXPECT_NE(check.find("5. The helix alone"), std::string::npos) << check;
  EXPECT_NE(check.find("a probe: you fly alone"), std::string::npos) << check;

  const std::vector<std::pair<std::string, std::string>> usage = {
      {"lesson", "which lesson?"},
      {"lesson beginner --headless", "whose lesson?"},
      {"lesson beginner --trainee A --status --reset", "one of --status, --reset, --check"},
      {"lesson beginner --trainee A --history off", "--history off: a lesson's progress"},
      {"lesson beginner --trainee A --until-done", "--until-done is for --headless flights"},
      {"lesson beginner --trainee A --headless --pilot keyboard", "a person flies in the window"},
      {"lesson beginner --trainee A --status --headless", "fly nothing"},
      {"lesson beginner --trainee A --frobnicate", "unknown option '--frobnicate'"},
      {"lesson beginner other --trainee A", "one lesson at a time"},
      {"lesson beginner --trainee ''", "--trainee needs a value"},
  };
  for (const auto& [args, want] : usage) {
    EXPECT_EQ(test::run_mixpilot(kBinary, args, home), 2) << args;
    EXPECT_NE(test::read_file(home / "out.txt").find(want), std::string::npos)
        << args << ": " << test::read_file(home / "out.txt");
  }
  std::ofstream(home / "bad.toml") << "name = \"x\"\ndescription = \"y\"\nsteps = 1\n";
  EXPECT_EQ(test::run_mixpilot(kBinary, "lesson " + (home / "bad.toml").string() + " --check",
                               home),
            1);
  EXPECT_NE(test::read_file(home / "out.txt").find("bad.toml:3:9: steps: expected an array"),
            std::string::npos)
      << test::read_file(home / "out.txt");
  EXPECT_EQ(test::run_mixpilot(kBinary, "lesson no_such_lesson --check", home), 1);
  EXPECT_NE(test::read_file(home / "out.txt").find("no shipped lesson 'no_such_lesson'"),
            std::string::npos)
      << test::read_file(home / "out.txt");
}

// A step's attempts: a failure is exit 4 and counts; the last allowed one closes the step
// (nothing flies: exit 1, said); --status shows it; --reset opens the lesson again.
TEST(Lesson, AttemptsLimitStatusAndReset) {
  const fs::path home = test::fresh_path("lesson_cli", "attempts");
  const fs::path dir = home / "lessons";
  short_hover(dir, "hover_2s", 2.0);
  // Under a ceiling of 0.3 the skill is at most 72: 99 cannot be reached.
  std::ofstream(dir / "hard.toml")
      << "name = \"hard\"\ndescription = \"an unpassable step\"\n"
         "[[steps]]\ntitle = \"Hover perfectly\"\nscenario = \"hover_2s.toml\"\nceiling = 0.3\n"
         "attempts = 2\n[steps.pass]\nmin_skill = 99\n";
  const std::string lesson = (dir / "hard.toml").string();
  const std::string fly = "lesson " + lesson + " --trainee Ada --headless --no-record";
  ASSERT_EQ(test::run_mixpilot(kBinary, fly, home), 4) << test::read_file(home / "out.txt");
  std::string out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("NOT PASSED: skill"), std::string::npos) << out;
  EXPECT_NE(out.find("(at least 99)"), std::string::npos) << out;
  EXPECT_NE(out.find("attempts: 1 failed, 1 of 2 left"), std::string::npos) << out;
  ASSERT_EQ(test::run_mixpilot(kBinary, fly, home), 4) << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("step 1 is closed (2 attempts failed)"),
            std::string::npos)
      << test::read_file(home / "out.txt");
  ASSERT_EQ(test::run_mixpilot(kBinary, fly, home), 1);
  EXPECT_NE(test::read_file(home / "out.txt").find("step 1 is closed: its 2 attempts failed"),
            std::string::npos)
      << test::read_file(home / "out.txt");
  ASSERT_EQ(test::run_mixpilot(kBinary, "lesson " + lesson + " --trainee Ada --status", home), 0);
  out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("2 attempts"), std::string::npos) << out;
  EXPECT_NE(out.find("step 1: failed"), std::string::npos) << out;
  ASSERT_EQ(test::run_mixpilot(kBinary, "lesson " + lesson + " --trainee Ada --reset", home), 0);
  ASSERT_EQ(test::run_mixpilot(kBinary, fly, home), 4) << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("attempts: 1 failed, 1 of 2 left"),
            std::string::npos);
  // The history lists the three attempts as the lesson's, and where Ada is.
  ASSERT_EQ(test::run_mixpilot(kBinary, "history --trainee Ada", home), 0);
  out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("hard 1 \u2717"), std::string::npos) << out;
  EXPECT_NE(out.find("lessons:"), std::string::npos) << out;
  EXPECT_NE(out.find("on step 1 of 1, 1 failed attempt at it"), std::string::npos) << out;
}

// ---- The beginner course flown by the emulated pilots -------------------------------------

struct Course {
  fs::path home;
  int status = -1;
  std::string out;
  std::vector<RecordingContents> recordings;  // by the step they flew (lesson_step)
};

// `pilot` through the beginner course with --until-done, recorded, in a history of its own.
Course fly_course(const std::string& pilot) {
  Course c;
  c.home = test::fresh_path("lesson_course", pilot);
  fs::create_directories(c.home);
  c.status = test::run_mixpilot(kBinary,
                                "lesson beginner --trainee " + pilot + " --headless --pilot " +
                                    pilot + " --until-done --record-dir '" +
                                    (c.home / "rec").string() + "'",
                                c.home);
  c.out = test::read_file(c.home / "out.txt");
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(c.home / "rec")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    std::string error;
    auto rec = read_recording(f.string(), error);
    EXPECT_TRUE(rec) << error;
    if (rec) c.recordings.push_back(std::move(*rec));
  }
  std::sort(c.recordings.begin(), c.recordings.end(), [](const auto& a, const auto& b) {
    return std::stoi(a.metadata.at("lesson_step")) < std::stoi(b.metadata.at("lesson_step"));
  });
  return c;
}

// The scores the course printed, per step: "pass skill 99.3 (at least 60)".
std::vector<double> printed_skills(const std::string& out) {
  std::vector<double> v;
  const std::regex re(R"((?:pass|FAIL) skill ([0-9.]+) \(at least)");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), re); it != std::sregex_iterator();
       ++it)
    v.push_back(std::stod((*it)[1]));
  return v;
}

// Each recording: its lesson and step in the metadata, the ceiling rising step after step as
// authority_ceiling (none for the probe, which flies with assist=off), every recorded λ at or
// under the ceiling, and the ceiling reached (the planner's share is what the ceiling keeps).
void expect_the_ceiling_rises(const Course& c, std::size_t steps) {
  ASSERT_EQ(c.recordings.size(), steps) << c.out;
  const double ceilings[] = {0.3, 0.5, 0.65, 0.9, 1.0};
  double previous = 0.0;
  for (std::size_t i = 0; i < steps; ++i) {
    const RecordingContents& r = c.recordings[i];
    EXPECT_EQ(r.metadata.at("lesson"), "beginner");
    EXPECT_EQ(r.metadata.at("lesson_step"), std::to_string(i + 1));
    EXPECT_EQ(r.metadata.at("lesson_steps"), "5");
    EXPECT_EQ(r.metadata.at("lesson_hash").size(), 64u);
    const bool probe = i == 4;
    EXPECT_EQ(r.metadata.at("assist"), probe ? "off" : "on") << i;
    const double ceiling = probe ? 1.0 : std::stod(r.metadata.at("authority_ceiling"));
    EXPECT_EQ(ceiling, ceilings[i]) << i;
    EXPECT_EQ(r.metadata.count("authority_ceiling"), probe ? 0u : 1u) << i;
    EXPECT_GT(ceiling, previous) << "the ceiling rises at step " << i + 1;
    previous = ceiling;
    ASSERT_FALSE(r.lambda.empty()) << i;
    double highest = 0.0;
    for (const LambdaSample& s : r.lambda) {
      ASSERT_LE(s.lambda, ceiling) << "step " << i + 1 << " at " << s.step;
      highest = std::max(highest, s.lambda);
    }
    // The ceiling held λ down at some step (the pilots' own λ goes above each ceiling).
    EXPECT_EQ(highest, ceiling) << "step " << i + 1;
  }
}

// The novice passes the hover, the climb and the slow third of the helix, and stops at the
// helix under a ceiling of 0.9, where its skill is not enough (exit 4); the history holds the
// four attempts and the novice on step 4 with one failed attempt.
TEST(LessonCourse, TheNoviceStopsWhereItsSkillIsNotEnough) {
  const Course c = fly_course("novice");
  EXPECT_EQ(c.status, 4) << c.out;
  const std::vector<double> skills = printed_skills(c.out);
  ASSERT_EQ(skills.size(), 4u) << c.out;
  const double thresholds[] = {65, 72, 77, 85};
  for (std::size_t i = 0; i < skills.size(); ++i) {
    std::printf("novice step %zu: skill %.1f (threshold %.0f)\n", i + 1, skills[i], thresholds[i]);
    if (i < 3) EXPECT_GE(skills[i], thresholds[i] + 3.0) << "step " << i + 1 << " margin";
    else EXPECT_LE(skills[i], thresholds[i] - 3.0) << "step " << i + 1 << " margin";
  }
  EXPECT_NE(c.out.find("NOT PASSED: skill"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("next: step 4 of 5: The helix, the planner at your side"),
            std::string::npos)
      << c.out;
  expect_the_ceiling_rises(c, 4);
  // The progress and the attempts, as the history says them.
  std::string error;
  auto store = history::open_sqlite((c.home / "data/mixpilot/history.sqlite").string(), error);
  ASSERT_TRUE(store) << error;
  std::vector<history::LessonProgress> progress;
  ASSERT_TRUE(store->lesson_progress("novice", progress, error)) << error;
  ASSERT_EQ(progress.size(), 1u);
  EXPECT_EQ(progress[0].step, 3);
  EXPECT_EQ(progress[0].failed_attempts, 1);
  EXPECT_EQ(progress[0].steps, 5);
  std::vector<history::StoredAttempt> attempts;
  ASSERT_TRUE(store->lesson_attempts("novice", "beginner", progress[0].lesson_hash, attempts,
                                     error))
      << error;
  ASSERT_EQ(attempts.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(attempts[std::size_t(i)].step, i);
    EXPECT_EQ(attempts[std::size_t(i)].passed, i < 3);
    EXPECT_EQ(attempts[std::size_t(i)].skill, skills[std::size_t(i)] == 0 ? 0 : attempts[std::size_t(i)].skill);
    EXPECT_NEAR(attempts[std::size_t(i)].skill, skills[std::size_t(i)], 0.051);
  }
  EXPECT_EQ(attempts[3].failed_criterion, "min_skill");
  // `history --json`: each attempt's lesson, step (1-based) and verdict.
  ASSERT_EQ(test::run_mixpilot(kBinary, "history --json", c.home, "history.json"), 0);
  const std::string json = test::read_file(c.home / "history.json");
  EXPECT_NE(json.find("\"lesson\": \"beginner\", \"lesson_step\": 4, \"lesson_passed\": false, "
                      "\"lesson_failed\": \"min_skill\""),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"lesson\": \"beginner\", \"lesson_step\": 1, \"lesson_passed\": true, "
                      "\"lesson_failed\": null"),
            std::string::npos)
      << json;
  // Again: the novice flies step 4 (a failed step is not skipped), and fails it again.
  ASSERT_EQ(test::run_mixpilot(kBinary, "lesson beginner --trainee novice --status", c.home), 0);
  EXPECT_NE(test::read_file(c.home / "out.txt").find("next: step 4 of 5"), std::string::npos);
}

// The experienced pilot completes the course: five passes, the probe last; the history says
// every step passed.
TEST(LessonCourse, TheExperiencedPilotCompletesIt) {
  const Course c = fly_course("experienced");
  EXPECT_EQ(c.status, 0) << c.out;
  const std::vector<double> skills = printed_skills(c.out);
  ASSERT_EQ(skills.size(), 5u) << c.out;
  const double thresholds[] = {65, 72, 77, 85, 4};
  for (std::size_t i = 0; i < skills.size(); ++i) {
    std::printf("experienced step %zu: skill %.1f (threshold %.0f)\n", i + 1, skills[i],
                thresholds[i]);
    // Margins: 3 points, or (the probe's low bar) half the threshold.
    EXPECT_GE(skills[i], thresholds[i] + (i == 4 ? 2.0 : 3.0)) << "step " << i + 1 << " margin";
  }
  EXPECT_NE(c.out.find("next: nothing; every step of beginner is passed"), std::string::npos)
      << c.out;
  expect_the_ceiling_rises(c, 5);
  std::string error;
  auto store =
      history::open_sqlite((c.home / "data/mixpilot/history.sqlite").string(), error);
  ASSERT_TRUE(store) << error;
  std::vector<history::LessonProgress> progress;
  ASSERT_TRUE(store->lesson_progress("experienced", progress, error)) << error;
  ASSERT_EQ(progress.size(), 1u);
  EXPECT_TRUE(progress[0].completed());
  ASSERT_EQ(test::run_mixpilot(kBinary, "history", c.home), 0);
  EXPECT_NE(test::read_file(c.home / "out.txt").find("beginner (" + progress[0].lesson_hash.substr(0, 12) +
                                                     ")  every step passed (5)"),
            std::string::npos)
      << test::read_file(c.home / "out.txt");
  // Done: nothing more to fly.
  ASSERT_EQ(test::run_mixpilot(kBinary,
                               "lesson beginner --trainee experienced --headless --no-record",
                               c.home),
            0);
  EXPECT_NE(test::read_file(c.home / "out.txt").find("has passed every step"), std::string::npos);
}

// ---- The window's lesson picker -------------------------------------------------------------

class LessonPicker : public test::AppWindowTest, public testing::WithParamInterface<float> {
 protected:
  void SetUp() override {
    home_ = test::fresh_path("lesson_picker",
                             "scale" + std::to_string(int(std::lround(GetParam() * 100))));
    fs::create_directories(home_);
    setenv("XDG_CONFIG_HOME", (home_ / "config").c_str(), 1);
    setenv("XDG_DATA_HOME", (home_ / "data").c_str(), 1);
    std::string error;
    if (!screen_.open(1280, 720, error, GetParam())) GTEST_SKIP() << "no EGL device: " << error;
  }
  // Frames until `done`, at most 20 s.
  template <class Done>
  bool frames_until(cli::Trainer& app, Done done) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!done() && std::chrono::steady_clock::now() < deadline) {
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return done();
  }
  void save_shot(const std::string& name) {
    const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
    if (!dir || !*dir) return;
    std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen_.png();
  }
  fs::path home_;
};

// The beginner course for a trainee two steps in, with a failed attempt at the third: the
// picker shows step 3 among the five (its ceiling, its criteria, the attempts, the last
// attempt's verdict), the flight READY is that step's (its scenario, its ceiling), the scenario
// and assistance are the lesson's, and nothing overlaps or is cut at 100 % and 150 %.
TEST_P(LessonPicker, ShowsTheTraineesStepOfTheCourse) {
  std::string error;
  const auto lesson = load_lesson(kBeginner, error);
  ASSERT_TRUE(lesson) << error;
  {
    auto store = history::open_history("", error);
    ASSERT_TRUE(store) << error;
    const auto add = [&](int step, bool passed, double skill, const std::string& detail) {
      history::FlightRecord f = flight("Ada", 1000 + step, skill);
      f.scenario = lesson->steps[std::size_t(step)].scenario_name;
      history::LessonAttempt a;
      a.lesson = lesson->name;
      a.lesson_hash = lesson->hash;
      a.steps = 5;
      a.step = step;
      a.step_title = lesson->steps[std::size_t(step)].title;
      a.ceiling = lesson->steps[std::size_t(step)].ceiling;
      a.passed = passed;
      a.failed_criterion = passed ? "" : "min_skill";
      a.detail = detail;
      ASSERT_EQ(store->add_attempt(f, a, error), history::HistoryStore::Added::added) << error;
    };
    add(0, true, 71.8, "skill 71.8 (at least 65)");
    add(1, true, 79.6, "skill 79.6 (at least 72)");
    add(2, false, 74.9, "skill 74.9 (at least 77)");
  }
  cli::FlyOptions o;
  o.scenario_path = lesson->steps[0].scenario_path;
  o.pilot = "experienced";
  o.trainee = "Ada";
  o.lesson_file = kBeginner;
  cli::Trainer app(o);
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.act(ui::LiveRequest{ui::SetTrainee{"Ada"}});
  ASSERT_TRUE(frames_until(app, [&] {
    const ui::SessionChoices* c = app.run_info().session;
    return c && c->lesson_view.step == 2 && app.live() &&
           app.live()->flight().lesson.step == 2;
  }));
  frame(app);
  frame(app);
  const ui::SessionChoices& c = *app.run_info().session;
  EXPECT_EQ(c.lessons[std::size_t(c.lesson)], "beginner");
  const ui::LessonChoice& v = c.lesson_view;
  EXPECT_EQ(v.steps.size(), 5u);
  EXPECT_EQ(v.heading, "step 3 of 5: A third of the helix, slowly");
  EXPECT_EQ(v.rule, "\u03bb \u2264 0.65 \u00b7 pass: skill \u2265 77, no collision, in B \u2265 90 %");
  EXPECT_EQ(v.conditions, "ceiling: \u03bb at most 0.65 (the planner keeps 35 % or more)");
  EXPECT_EQ(v.criteria, "skill at least 77, no collision, in the ball at least 90 % of the time");
  EXPECT_EQ(v.attempts, "attempts: 1 failed (no limit)");
  EXPECT_EQ(v.verdict, "step 3 NOT PASSED: skill 74.9 (at least 77)");
  EXPECT_FALSE(v.verdict_passed);
  EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  EXPECT_EQ(app.live()->mode().scenario_name(), "lesson_helix_slow");
  EXPECT_EQ(app.live()->mode().authority_bounds(), (AuthorityBounds{0.0, 0.65}));
  EXPECT_EQ(c.scenarios[std::size_t(c.scenario)], "lesson_helix_slow");
  EXPECT_FALSE(c.assist_choosable && c.lesson == 0);
  // READY says what the step starts with: the initial λ 0.5 under the step's ceiling 0.65.
  EXPECT_EQ(app.live()->mode().telemetry().lambda, 0.5);
  EXPECT_EQ(app.live()->mode().telemetry().instructor.bounds, (AuthorityBounds{0.0, 0.65}));
  for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << problem;
  const ImGuiWindow* panel = ImGui::FindWindowByName("Session");
  ASSERT_TRUE(panel && panel->Active);
  // The five steps, the step's rule, attempts and verdict (the panel's choices) and the start
  // button under them all show on the default window without scrolling.
  EXPECT_FALSE(panel->ScrollbarY) << "the session panel scrolls";
  EXPECT_LE(panel->DC.CursorMaxPos.y, panel->InnerClipRect.Max.y + 1.0f)
      << "the start button is under the panel's bottom";
  for (const ImGuiWindow* w : GImGui->Windows) {
    if (w->ParentWindow == panel && (w->Flags & ImGuiWindowFlags_ChildWindow) && w->Active) {
      EXPECT_FALSE(w->ScrollbarY) << "the session panel's choices scroll";
    }
  }
  save_shot("lesson_picker_" + std::to_string(int(std::lround(GetParam() * 100))));
}

// Start flies the step (real time, a 1.5 s hover): after the flight the verdict shows with
// every criterion, the step advances, R flies the next step, and the history holds the attempt.
TEST_P(LessonPicker, StartFliesTheStepThenTheVerdictAndTheNextStep) {
  const fs::path dir = home_ / "lessons";
  short_hover(dir, "hover_a", 1.5);
  short_hover(dir, "hover_b", 1.5);
  std::ofstream(dir / "two.toml")
      << "name = \"two\"\ndescription = \"two short hovers\"\n"
         "[[steps]]\ntitle = \"First hover\"\nscenario = \"hover_a.toml\"\nceiling = 0.4\n"
         "[steps.pass]\nmin_time_in_ball = 0.9\nmax_collisions = 0\n"
         "[[steps]]\ntitle = \"Second hover\"\nscenario = \"hover_b.toml\"\nceiling = 0.6\n"
         "[steps.pass]\nmin_skill = 99\n";
  cli::FlyOptions o;
  o.scenario_path = (dir / "hover_a.toml").string();
  o.pilot = "novice";
  o.lesson_file = (dir / "two.toml").string();
  cli::Trainer app(o);
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.act(ui::LiveRequest{ui::SetTrainee{"Grace"}});
  // By name, as a first launch would offer it ("none" first, then the shipped beginner and
  // this file's lesson).
  app.act(ui::LiveRequest{ui::ChooseLesson{"no such lesson"}});
  frame(app);
  EXPECT_NE(app.run_info().message.find("no lesson named no such lesson"), std::string::npos);
  app.act(ui::LiveRequest{ui::ChooseLesson{"beginner"}});
  frame(app);
  EXPECT_EQ(app.run_info().session->lessons[std::size_t(app.run_info().session->lesson)],
            "beginner");
  app.act(ui::LiveRequest{ui::ChooseLesson{"two"}});
  ASSERT_TRUE(frames_until(app, [&] {
    const ui::SessionChoices* c = app.run_info().session;
    return c && c->lessons[std::size_t(c->lesson)] == "two" && c->lesson_view.step == 0 &&
           app.live() && app.live()->flight().lesson.lesson == "two" &&
           app.live()->flight().lesson.step == 0;
  }));
  EXPECT_EQ(app.live()->mode().authority_bounds(), (AuthorityBounds{0.0, 0.4}));
  // Start, as a click on the panel's button would.
  app.act(ui::LiveRequest{ui::StartFlight{}});
  until_over(app, std::chrono::seconds(30));
  ASSERT_TRUE(app.over());
  ASSERT_TRUE(frames_until(app, [&] { return app.run_info().session->lesson_view.step == 1; }));
  frame(app);
  const ui::LessonChoice& v = app.run_info().session->lesson_view;
  EXPECT_EQ(v.verdict, "step 1 PASSED");
  EXPECT_TRUE(v.verdict_passed);
  ASSERT_EQ(v.verdict_lines.size(), 3u);
  EXPECT_EQ(v.verdict_lines[0], "pass  0 collisions (at most 0)");
  EXPECT_EQ(v.verdict_lines[1], "pass  in the ball 100.0 % of the time (at least 90 %)");
  EXPECT_EQ(v.verdict_lines[2], "pass  flown to its end");
  EXPECT_EQ(v.heading, "step 2 of 2: Second hover");
  EXPECT_EQ(v.next, "Next: step 2 (R)");
  for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << problem;
  save_shot("lesson_verdict_" + std::to_string(int(std::lround(GetParam() * 100))));
  // R: the next step, READY... flown at once (R restarts).
  app.act(ui::LiveRequest{ui::RestartFlight{}});
  frame(app);
  EXPECT_EQ(app.live()->flight().lesson.step, 1);
  EXPECT_EQ(app.live()->mode().authority_bounds(), (AuthorityBounds{0.0, 0.6}));
  until_over(app, std::chrono::seconds(30));
  ASSERT_TRUE(frames_until(app, [&] {
    return app.run_info().session->lesson_view.verdict.find("step 2 NOT PASSED") == 0;
  })) << app.run_info().session->lesson_view.verdict;
  EXPECT_EQ(app.run_info().session->lesson_view.step, 1);
  EXPECT_EQ(app.run_info().session->lesson_view.next, "Try step 2 again (R)");
  // The history: both attempts, Grace on step 2 with one failed attempt.
  app.history()->wait_idle();
  auto store = history::open_history("", error);
  ASSERT_TRUE(store) << error;
  std::vector<history::LessonProgress> progress;
  ASSERT_TRUE(store->lesson_progress("Grace", progress, error)) << error;
  ASSERT_EQ(progress.size(), 1u);
  EXPECT_EQ(progress[0].step, 1);
  EXPECT_EQ(progress[0].failed_attempts, 1);
}

INSTANTIATE_TEST_SUITE_P(Scales, LessonPicker, testing::Values(1.0f, 1.5f));

}  // namespace
}  // namespace mixpilot
