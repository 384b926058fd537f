#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "core/base/content_hash.hpp"
#include "core/base/input_file.hpp"
#include "core/base/toml_read.hpp"
#include "core/scenario/data_files.hpp"
#include "core/scenario/lesson.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
using namespace toml_read;  // NOLINT: the reading vocabulary of this file

// A shipped scenario's name: letters, digits, '_', '-' and '.', not a path.
bool plain_name(std::string_view s) {
  return !s.empty() && s != "." && s != ".." &&
         std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                  c == '_' || c == '-' || c == '.';
         });
}

std::string percent(double share) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g %%", 100.0 * share);
  return buf;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The step's `scenario`: the file it names and that file's scenario, checked. Problems are
// reported at the key.
void read_step_scenario(Section& s, LessonStep& step, const fs::path& folder, Diagnostics& d) {
  if (!s.string("scenario", step.scenario, true)) return;
  const Pos at = s.pos("scenario");
  const std::string key = s.path("scenario");
  std::string file;
  if (step.scenario.ends_with(".toml")) {
    const fs::path p(step.scenario);
    file = (p.is_absolute() ? p : folder / p).lexically_normal().string();
  } else if (plain_name(step.scenario)) {
    std::string why;
    const std::string dir = data_dir(&why);
    if (dir.empty()) {
      d.add(at, key, "a shipped scenario's name, but " + why);
      return;
    }
    file = (fs::path(dir) / "scenarios" / (step.scenario + ".toml")).string();
    std::error_code ec;
    if (!fs::exists(file, ec)) {
      d.add(at, key,
            "expected a shipped scenario's name (a file in " + dir +
                "/scenarios) or a path ending in .toml, got \"" + printable(step.scenario) + '"');
      return;
    }
  } else {
    d.add(at, key,
          "expected a shipped scenario's name (letters, digits, _ - .) or a path ending in "
          ".toml, got \"" + printable(step.scenario) + '"');
    return;
  }
  std::error_code ec;
  const fs::path abs = fs::absolute(file, ec);
  step.scenario_path = (ec ? fs::path(file) : abs).lexically_normal().string();
  std::string text, error;
  if (!read_text_file(step.scenario_path, text, error)) {
    d.add(at, key, "cannot be read: " + error);
    return;
  }
  const std::optional<std::string> mode = scenario_mode(text, step.scenario_path, error);
  if (!mode) {
    d.add(at, key, "is not a scenario that loads: " + error);
    return;
  }
  if (*mode != "mixed_initiative") {
    d.add(at, key,
          "expected a mixed_initiative scenario (a pilot shares the authority λ there), got "
          "\"" + *mode + "\" in " + step.scenario_path);
    return;
  }
  const std::optional<Scenario> sc = parse_scenario(text, step.scenario_path, error);
  if (!sc) {
    d.add(at, key, "is not a scenario that loads: " + error);
    return;
  }
  step.scenario_name = sc->name;
}

LessonStep read_step(Section s, const fs::path& folder, Diagnostics& d, bool& ceiling_ok) {
  LessonStep step;
  s.string("title", step.title, true);
  read_step_scenario(s, step, folder, d);
  s.boolean("probe", step.probe);
  // The ceiling: required of an assisted step; a probe's is 1 (written or not).
  ceiling_ok = s.num("ceiling", step.ceiling, left_open(0, 1), !step.probe);
  if (step.probe && ceiling_ok && step.ceiling != 1.0) {
    d.add(s.pos("ceiling"), s.path("ceiling"),
          "a probe flies unassisted (λ pinned to 1): expected 1 or no ceiling, got " +
              fmt(step.ceiling));
    ceiling_ok = false;
  }
  if (step.probe && !s.table()->get("ceiling")) ceiling_ok = true, step.ceiling = 1.0;
  s.integer("attempts", step.attempts, IntRange{1, kMaxLessonAttempts});

  Section pass = s.sub("pass");
  double v = 0;
  if (pass.num("min_skill", v, closed(0, 100))) step.pass.min_skill = v;
  int n = 0;
  if (pass.integer("max_collisions", n, IntRange{0, 1000000})) step.pass.max_collisions = n;
  if (pass.num("min_time_in_ball", v, closed(0, 1))) step.pass.min_time_in_ball = v;
  pass.finish();
  if (!s.table()->get("pass")) {
    d.add(s.pos(), s.path("pass"),
          "missing required table (expected pass criteria: min_skill, max_collisions, "
          "min_time_in_ball)");
  } else if (pass.table() && pass.table()->empty()) {
    d.add(pass.pos(), s.path("pass"),
          "expected at least one criterion (min_skill, max_collisions, min_time_in_ball)");
  }
  s.finish();
  return step;
}

Lesson read_lesson(const toml::table& root, const std::string& source_name, Diagnostics& d) {
  Lesson l;
  Section s(d, &root, "", Pos{1, 1});
  s.string("name", l.name, true);
  s.string("description", l.description, true);
  const fs::path folder = fs::path(source_name).parent_path();
  if (const toml::node* steps = s.take("steps", true, "an array of tables ([[steps]])")) {
    const toml::array* a = steps->as_array();
    if (!a || !a->is_array_of_tables() || a->empty()) {
      d.add(pos_of(steps->source()), "steps",
            "expected an array of tables ([[steps]]), at least one, got " + describe(*steps));
    } else if (a->size() > kMaxLessonSteps) {
      d.add(pos_of(steps->source()), "steps",
            outside("the number of steps", double(a->size()), closed(1, kMaxLessonSteps)));
    } else {
      // The assistance fades: each step's ceiling (a probe's counts as 1) at least the one
      // before, said at the ceiling that falls.
      double previous = 0.0;
      std::size_t previous_index = 0;
      for (std::size_t i = 0; i < a->size(); ++i) {
        const toml::node& e = *a->get(i);
        const std::string path = "steps[" + std::to_string(i) + ']';
        Section step(d, e.as_table(), path, pos_of(e.source()));
        bool ceiling_ok = false;
        l.steps.push_back(read_step(step, folder, d, ceiling_ok));
        const LessonStep& st = l.steps.back();
        if (!ceiling_ok) continue;
        if (st.flown_ceiling() < previous) {
          d.add(step.pos(st.probe ? "probe" : "ceiling"), path + ".ceiling",
                "expected at least steps[" + std::to_string(previous_index) + "]'s ceiling " +
                    fmt(previous) + " (passing a step never lowers the ceiling: the planner's "
                    "share only fades), got " + fmt(st.flown_ceiling()));
        } else {
          previous = st.flown_ceiling();
          previous_index = i;
        }
      }
    }
  }
  s.finish();
  return l;
}

}  // namespace

std::optional<Lesson> parse_lesson(std::string_view text, const std::string& source_name,
                                   std::string& error) {
  auto l = parse_document<Lesson>(text, source_name, error,
                                 [&](const toml::table& root, Diagnostics& d) {
                                   return read_lesson(root, source_name, d);
                                 });
  if (l) {
    l->source_text = std::string(text);
    l->hash = sha256_hex(text);
  }
  return l;
}

std::optional<Lesson> load_lesson(const std::string& path, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_lesson(text, path, error);
}

std::string lesson_path(const std::string& arg) {
  if (arg.find('/') != std::string::npos || arg.ends_with(".toml") || !plain_name(arg)) return arg;
  const std::string dir = data_dir();
  return dir.empty() ? "" : (fs::path(dir) / "scenarios" / "lessons" / (arg + ".toml")).string();
}

std::vector<std::string> shipped_lessons() {
  std::vector<std::string> out;
  const std::string dir = data_dir();
  if (dir.empty()) return out;
  std::error_code ec;
  for (fs::directory_iterator it(fs::path(dir) / "scenarios" / "lessons", ec), end;
       !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".toml") out.push_back(it->path().lexically_normal().string());
  std::sort(out.begin(), out.end());
  return out;
}

LessonVerdict judge(const LessonStep& step, const LessonScore& score) {
  LessonVerdict v;
  const auto add = [&](const char* key, std::string text, bool passed) {
    v.results.push_back({key, std::move(text), passed});
  };
  const LessonCriteria& c = step.pass;
  char buf[96];
  if (c.min_skill) {
    std::snprintf(buf, sizeof buf, "skill %.1f (at least %s)", score.skill,
                  number(*c.min_skill).c_str());
    add("min_skill", buf, score.skill >= *c.min_skill);
  }
  if (c.max_collisions) {
    std::snprintf(buf, sizeof buf, "%.0f collision%s (at most %d)", score.collisions,
                  score.collisions == 1 ? "" : "s", *c.max_collisions);
    add("max_collisions", buf, score.collisions <= double(*c.max_collisions));
  }
  if (c.min_time_in_ball) {
    std::snprintf(buf, sizeof buf, "in the ball %.1f %% of the time (at least %s)",
                  100.0 * score.time_in_ball, percent(*c.min_time_in_ball).c_str());
    add("min_time_in_ball", buf, score.time_in_ball >= *c.min_time_in_ball);
  }
  add("completed", score.completed ? "flown to its end" : "not flown to its end",
      score.completed);
  v.passed = std::all_of(v.results.begin(), v.results.end(),
                         [](const CriterionResult& r) { return r.passed; });
  for (const CriterionResult& r : v.results) {
    if (r.passed) continue;
    v.failed = r.key;
    v.detail = r.text;
    break;
  }
  return v;
}

std::string criteria_text(const LessonCriteria& c) {
  std::string out;
  const auto add = [&](const std::string& s) { out += (out.empty() ? "" : ", ") + s; };
  if (c.min_skill) add("skill at least " + number(*c.min_skill));
  if (c.max_collisions)
    add(*c.max_collisions == 0 ? std::string("no collision")
                               : "at most " + std::to_string(*c.max_collisions) + " collision" +
                                     (*c.max_collisions == 1 ? "" : "s"));
  if (c.min_time_in_ball) add("in the ball at least " + percent(*c.min_time_in_ball) + " of the time");
  return out;
}

}  // namespace mixpilot
