#pragma once
// Lessons (SPEC §10, docs/lesson-format.md): an ordered list of steps, each a scenario flown
// with an authority ceiling on λ (the instructor bound of SPEC §10: λ_applied ≤ ceiling) and
// judged against pass criteria. A trainee is on one step at a time; passing it moves them to the
// next, whose ceiling is at least as high (the reader checks the ceilings never fall), so the
// planner's guaranteed share 1 − ceiling fades as the trainee passes. A probe step flies
// unassisted (λ pinned to 1): its ceiling counts as 1.
//
// Read from TOML like the scenarios (core/base/toml_read.hpp): every error is
// `<file>:<line>:<col>: <key path>: <what was expected>`, unknown keys are errors, no exception
// escapes.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot {

// What a step's flight must reach to pass (at least one is given). Each judges the step's own
// flight: the assisted flight under the ceiling, or the probe of a probe step.
struct LessonCriteria {
  std::optional<double> min_skill;         // score field `skill` ≥ this (0..100)
  std::optional<int> max_collisions;       // `collisions` ≤ this
  std::optional<double> min_time_in_ball;  // `time_in_ball` ≥ this (a share, 0..1)
};

struct LessonStep {
  std::string title;
  std::string scenario;       // as written: a shipped scenario's name, or a path (.toml)
  std::string scenario_path;  // the file it names, absolute
  std::string scenario_name;  // that scenario's own name (its `name` key)
  double ceiling = 1.0;       // the authority ceiling on λ of the step's flights, (0, 1]
  bool probe = false;         // flown unassisted (SPEC §10's probe): its ceiling counts as 1
  LessonCriteria pass;
  int attempts = 0;           // failed attempts allowed before the step is closed; 0: any number

  // The ceiling the step's flight is flown with: 1 for a probe (λ is pinned to 1 anyway).
  double flown_ceiling() const { return probe ? 1.0 : ceiling; }
};

struct Lesson {
  std::string name;
  std::string description;
  std::vector<LessonStep> steps;
  std::string source_path;  // the file it was read from
  std::string source_text;  // its text
  std::string hash;         // SHA-256 hex of source_text: a changed file is another lesson
};

// At most this many steps (a course of a few dozen is already long) and attempts per step.
inline constexpr std::size_t kMaxLessonSteps = 64;
inline constexpr int kMaxLessonAttempts = 1000;

// Reads and checks the lesson at `path`: its keys, each step's scenario (it must be a
// mixed_initiative scenario that loads), the ceilings never falling. nullopt with one line per
// problem, sorted by position, in `error`.
std::optional<Lesson> load_lesson(const std::string& path, std::string& error);
// The same from text; `source_name` names it in messages and is the folder relative scenario
// paths are read from.
std::optional<Lesson> parse_lesson(std::string_view text, const std::string& source_name,
                                   std::string& error);

// A lesson named on a command line: a path (anything with a '/' or ending in .toml), else a
// shipped lesson's name, scenarios/lessons/NAME.toml in the data folder ("" when there is none).
std::string lesson_path(const std::string& arg);
// The shipped lessons' files (scenarios/lessons/*.toml in the data folder), sorted.
std::vector<std::string> shipped_lessons();

// What a flight scored, as far as a lesson judges it.
struct LessonScore {
  double skill = 0.0;
  double time_in_ball = 0.0;
  double collisions = 0.0;
  bool completed = true;  // flown to its end (not interrupted, the vehicle not lost)
};
struct CriterionResult {
  std::string key;   // "min_skill", "max_collisions", "min_time_in_ball", "completed"
  std::string text;  // "skill 62.4 (at least 50)"
  bool passed = false;
};
struct LessonVerdict {
  bool passed = false;
  std::string failed;  // the first criterion that failed ("" when passed)
  std::string detail;  // its text
  // Every criterion of the step (skill, collisions, time in B, in that order) and `completed`.
  std::vector<CriterionResult> results;
};
// The step's criteria against the score: passed when every one holds and the flight was
// completed (an interrupted or lost flight fails with the criterion "completed").
LessonVerdict judge(const LessonStep& step, const LessonScore& score);
// The criteria in words: "skill at least 50, no collision, in the ball at least 80 % of the time".
std::string criteria_text(const LessonCriteria& c);

}  // namespace mixpilot
