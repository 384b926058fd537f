// mixpilot lesson: a trainee's current step of a lesson (SPEC §10), flown headless by an
// emulated pilot or in the window, judged against the step's criteria and remembered in the
// history with its verdict; --until-done goes on while the steps pass.
#include "app/lesson.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight_rig.hpp"
#include "app/history_writer.hpp"
#include "app/window.hpp"
#include "core/base/input_file.hpp"
#include "core/base/output_file.hpp"
#include "core/scenario/data_files.hpp"

namespace mixpilot::cli {

namespace fs = std::filesystem;

FlyOptions lesson_flight(const Lesson& lesson, int step, FlyOptions base) {
  const LessonStep& s = lesson.steps[std::size_t(step)];
  FlyOptions o = std::move(base);
  o.scenario_path = s.scenario_path;
  o.assist = s.probe ? Assistance::off : Assistance::on;
  o.bounds = s.probe ? AuthorityBounds{} : AuthorityBounds{0.0, s.ceiling};
  o.duration.reset();
  o.from.reset();
  o.lesson = LessonTag{lesson.name, lesson.hash, step, int(lesson.steps.size()), s.title};
  return o;
}

std::string step_heading(const Lesson& lesson, int step) {
  return "step " + std::to_string(step + 1) + " of " + std::to_string(lesson.steps.size()) +
         ": " + lesson.steps[std::size_t(step)].title;
}

std::string step_conditions(const LessonStep& step) {
  if (step.probe) return "a probe: you fly alone (no assistance, every constraint kept)";
  char text[96];
  std::snprintf(text, sizeof text, "ceiling: \xCE\xBB at most %.2f (the planner keeps %.0f %% or more)",
                step.ceiling, 100.0 * (1.0 - step.ceiling));
  return text;
}

std::string step_rule(const LessonStep& step) {
  char text[160];
  std::string out;
  if (step.probe) {
    out = "probe: no assistance";
  } else {
    std::snprintf(text, sizeof text, "\xCE\xBB \xE2\x89\xA4 %.2f", step.ceiling);
    out = text;
  }
  std::string pass;
  const auto add = [&](const std::string& s) { pass += (pass.empty() ? "" : ", ") + s; };
  const LessonCriteria& c = step.pass;
  if (c.min_skill) {
    std::snprintf(text, sizeof text, "skill \xE2\x89\xA5 %g", *c.min_skill);
    add(text);
  }
  if (c.max_collisions)
    add(*c.max_collisions == 0 ? std::string("no collision")
                               : "collisions \xE2\x89\xA4 " + std::to_string(*c.max_collisions));
  if (c.min_time_in_ball) {
    std::snprintf(text, sizeof text, "in B \xE2\x89\xA5 %g %%", 100.0 * *c.min_time_in_ball);
    add(text);
  }
  return out + " \xC2\xB7 pass: " + pass;
}

std::string attempts_text(const LessonStep& step, int failed_attempts) {
  if (step.attempts == 0)
    return failed_attempts == 0 ? std::string()
                                : "attempts: " + std::to_string(failed_attempts) +
                                      " failed (no limit)";
  const int left = std::max(0, step.attempts - failed_attempts);
  return "attempts: " + std::to_string(failed_attempts) + " failed, " + std::to_string(left) +
         " of " + std::to_string(step.attempts) + " left";
}

bool read_progress(history::HistoryStore& store, const std::string& trainee,
                   const Lesson& lesson, history::LessonProgress& out, std::string& error) {
  std::vector<history::LessonProgress> all;
  if (!store.lesson_progress(trainee, all, error)) return false;
  out = history::LessonProgress{};
  out.trainee = trainee;
  out.lesson = lesson.name;
  out.lesson_hash = lesson.hash;
  out.steps = int(lesson.steps.size());
  for (const history::LessonProgress& p : all)
    if (p.lesson == lesson.name && p.lesson_hash == lesson.hash) out = p;
  return true;
}

namespace {

constexpr const char* kLessonUsage =
    "usage: mixpilot lesson LESSON --trainee NAME [--headless --pilot PILOT] [--until-done]\n"
    "                       [--record-dir DIR | --no-record] [--history LOCATION]\n"
    "       mixpilot lesson LESSON --trainee NAME --status | --reset [--history LOCATION]\n"
    "       mixpilot lesson LESSON --check\n"
    "       mixpilot lesson --list\n"
    "\n"
    "Flies the trainee's current step of a lesson (SPEC §10, docs/lesson-format.md): the step's\n"
    "scenario with its authority ceiling on λ (a probe step unassisted), judged against the\n"
    "step's pass criteria. The flight and its verdict go into the history together: a pass moves\n"
    "the trainee to the next step, whose ceiling is at least as high (the planner's share fades);\n"
    "a failure counts against the step's attempts. Prints what passed and failed and what comes\n"
    "next. Without --headless the window opens with the lesson chosen in its session panel:\n"
    "Start flies the step (a gamepad or the keyboard), the verdict shows after the flight.\n"
    "\n"
    "  LESSON             a lesson file (.toml) or a shipped lesson's name (see --list)\n"
    "  --trainee NAME     whose progress (required to fly, for --status and --reset)\n"
    "  --headless         fly without a window, as fast as possible (an emulated pilot)\n"
    "  --pilot PILOT      headless: novice | experienced | reckless | another profile of the\n"
    "                     step's scenario (default: the scenario's); the window: gamepad |\n"
    "                     keyboard | a profile (default: the window's choice)\n"
    "  --until-done       headless: fly the next step after each pass, until a step fails or\n"
    "                     the lesson is done (a failed step is not flown again: the next run\n"
    "                     tries it, while its attempts last)\n"
    "  --record-dir DIR   where the recordings of the flights go (default\n"
    "                     $XDG_DATA_HOME/mixpilot/recordings); each names the lesson and step\n"
    "                     in its metadata (lesson, lesson_step, ...)\n"
    "  --no-record        do not record the flights\n"
    "  --history LOCATION the history (an SQLite file, PATH or sqlite:PATH, default\n"
    "                     $XDG_DATA_HOME/mixpilot/history.sqlite, or postgresql://...); a\n"
    "                     lesson's progress lives there, so it cannot be off\n"
    "  --status           print the lesson's steps and where the trainee is; fly nothing\n"
    "  --reset            the trainee starts the lesson over from step 1 (the attempts stay in\n"
    "                     the history)\n"
    "  --check            read the lesson and every step's scenario, print its steps\n"
    "  --list             the shipped lessons\n"
    "  -h, --help         show this help\n"
    "\n"
    "A step whose attempts are all used and failed is closed: nothing flies until --reset (or\n"
    "an instructor's new lesson file). An edited lesson file is another lesson (its SHA-256\n"
    "differs): its progress starts at step 1.\n"
    "\n"
    "exit status: 0 the step passed (or the lesson is done, or --status / --check / --list /\n"
    "--reset done), 1 bad input or a failure (the history cannot be written, the step is\n"
    "closed), 2 usage, 4 the step was flown and did not pass, 130 interrupted\n";

// A recording's file name for a step: one name, never a path.
std::string recording_name(const Lesson& lesson, int step, const std::string& trainee) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch())
                      .count() % 1000;
  std::tm tm{};
  localtime_r(&t, &tm);
  char stamp[48];
  std::snprintf(stamp, sizeof stamp, "%04d%02d%02d-%02d%02d%02d-%03d", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, int(ms));
  std::string name = "lesson-" + lesson.name + "-step" + std::to_string(step + 1) + "-" +
                     trainee + "-" + stamp;
  for (char& c : name)
    if (c == '/' || c == '\0' || static_cast<unsigned char>(c) < 0x20) c = '_';
  return name;
}

// A file in `dir` for the step's recording that does not exist yet.
std::string fresh_recording(const std::string& dir, const Lesson& lesson, int step,
                            const std::string& trainee) {
  const std::string base = recording_name(lesson, step, trainee);
  for (int n = 1;; ++n) {
    const fs::path p =
        fs::path(dir) / (base + (n > 1 ? "-" + std::to_string(n) : std::string()) + ".mcap");
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(p, ec))) return p.string();
  }
}

void print_steps(const Lesson& lesson, const history::LessonProgress* p) {
  std::printf("%s: %s\n", escape_controls(lesson.name).c_str(),
              escape_controls(lesson.description, true).c_str());
  for (std::size_t i = 0; i < lesson.steps.size(); ++i) {
    const LessonStep& s = lesson.steps[i];
    const char* mark = !p ? " " : int(i) < p->step ? "\xE2\x9C\x93" : int(i) == p->step ? ">" : " ";
    std::printf(" %s %zu. %s\n", mark, i + 1, escape_controls(s.title).c_str());
    std::printf("      %s, %s\n", escape_controls(s.scenario_name).c_str(),
                step_conditions(s).c_str());
    std::printf("      pass: %s%s\n", criteria_text(s.pass).c_str(),
                s.attempts > 0 ? (" (" + std::to_string(s.attempts) + " attempts)").c_str() : "");
  }
}

struct LessonOptions {
  std::string lesson_arg;
  std::string trainee;
  std::string pilot;
  std::string history;
  std::string record_dir;
  bool no_record = false, headless = false, until_done = false;
  bool status = false, reset = false, check = false, list = false;
};

int list_lessons() {
  const std::vector<std::string> files = shipped_lessons();
  if (files.empty()) {
    std::string why;
    const std::string dir = data_dir(&why);
    std::fprintf(stderr, "mixpilot lesson: no shipped lessons (%s)\n",
                 dir.empty() ? why.c_str() : (dir + "/scenarios/lessons holds none").c_str());
    return kExitError;
  }
  int status = kExitOk;
  for (const std::string& f : files) {
    std::string error;
    const auto l = load_lesson(f, error);
    if (!l) {
      std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error, true).c_str());
      status = kExitError;
      continue;
    }
    std::printf("%-14s %zu steps  %s\n", fs::path(f).stem().c_str(), l->steps.size(),
                escape_controls(l->description).c_str());
  }
  return status;
}

// One step flown headless: its rig, recording, history row and verdict. The exit status
// (kExitOk passed, kExitStepFailed, kExitError, kExitInterrupted) and, in `passed`, whether it
// passed.
int fly_step(const LessonOptions& lo, const Lesson& lesson, int step, HistoryWriter& writer,
             bool& passed) {
  passed = false;
  const LessonStep& s = lesson.steps[std::size_t(step)];
  FlyOptions base;
  base.command = "lesson";
  base.headless = true;
  base.pilot = lo.pilot;
  base.trainee = lo.trainee;
  base.history = lo.history;
  const FlyOptions o = lesson_flight(lesson, step, base);
  std::string error;
  int status = kExitOk;
  const std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, error, status);
  if (!rig) {
    std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error, true).c_str());
    return status == kExitOk ? kExitError : status;
  }
  std::string path;
  if (!lo.no_record) {
    std::error_code ec;
    fs::create_directories(lo.record_dir, ec);
    path = fresh_recording(lo.record_dir, lesson, step, lo.trainee);
    if (!rig->record(path, lo.trainee, RecordingSink::Settings{}, false, error)) {
      std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error).c_str());
      return kExitError;
    }
  }
  rig->remember(&writer, lo.trainee, "lesson");
  rig->judge_as(s);
  std::printf("mixpilot lesson: %s, %s\n  %s: %s, pilot %s\n",
              escape_controls(lesson.name).c_str(), escape_controls(step_heading(lesson, step)).c_str(),
              escape_controls(s.scenario_name).c_str(), step_conditions(s).c_str(),
              escape_controls(rig->flight().pilot).c_str());
  std::fflush(stdout);
  rig->start();
  while (!interrupted() && rig->step()) {
  }
  const bool stopped = interrupted() && !rig->mode().finished();
  const FlightRig::Closed c = rig->close(stopped);
  if (!c.recorded.empty()) std::printf("  recorded %s\n", escape_controls(c.recorded).c_str());
  if (!c.error.empty()) std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(c.error).c_str());
  writer.wait_idle();
  std::vector<HistoryWriter::Outcome> outcomes;
  writer.poll(outcomes);
  bool remembered = false;
  for (const auto& out : outcomes) {
    if (out.remembered) remembered = true;
    else std::fprintf(stderr, "mixpilot lesson: history: %s\n", escape_controls(out.error).c_str());
  }
  if (!c.verdict) {
    std::fprintf(stderr, "mixpilot lesson: the flight did not fly: no verdict\n");
    return stopped ? kExitInterrupted : kExitError;
  }
  for (const CriterionResult& r : c.verdict->results)
    std::printf("  %s %s\n", r.passed ? "pass" : "FAIL", r.text.c_str());
  passed = c.verdict->passed;
  std::printf("  %s\n", passed ? "PASSED" : ("NOT PASSED: " + c.verdict->detail).c_str());
  if (!remembered) {
    std::fprintf(stderr, "mixpilot lesson: the attempt is not in the history: the lesson's "
                         "progress did not move\n");
    return kExitError;
  }
  if (stopped) return kExitInterrupted;
  return passed ? kExitOk : kExitStepFailed;
}

// What comes next, said after a step or for --status.
void say_next(const Lesson& lesson, const history::LessonProgress& p) {
  if (p.completed()) {
    std::printf("next: nothing; every step of %s is passed\n", escape_controls(lesson.name).c_str());
    return;
  }
  const LessonStep& s = lesson.steps[std::size_t(p.step)];
  if (out_of_attempts(s, p.failed_attempts)) {
    std::printf("next: step %d is closed (%d attempts failed); `mixpilot lesson %s --trainee "
                "NAME --reset` starts the lesson over\n",
                p.step + 1, p.failed_attempts, escape_controls(lesson.source_path).c_str());
    return;
  }
  const std::string attempts = attempts_text(s, p.failed_attempts);
  std::printf("next: %s (%s)%s%s\n", escape_controls(step_heading(lesson, p.step)).c_str(),
              step_conditions(s).c_str(), attempts.empty() ? "" : "; ", attempts.c_str());
}

int run_lesson(const LessonOptions& lo) {
  if (lo.list) return list_lessons();
  const std::string path = lesson_path(lo.lesson_arg);
  if (path.empty()) {
    std::string why;
    data_dir(&why);
    std::fprintf(stderr, "mixpilot lesson: no shipped lesson '%s' (%s)\n",
                 escape_controls(lo.lesson_arg).c_str(), why.c_str());
    return kExitError;
  }
  std::string error;
  std::optional<Lesson> lesson = load_lesson(path, error);
  if (!lesson) {
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(path, ec)) && lo.lesson_arg.find('/') == std::string::npos &&
        !lo.lesson_arg.ends_with(".toml"))
      error = "no shipped lesson '" + lo.lesson_arg + "' (mixpilot lesson --list)";
    std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error, true).c_str());
    return kExitError;
  }
  if (lo.check) {
    print_steps(*lesson, nullptr);
    return kExitOk;
  }
  // The progress: read here, written by the writer's thread with each flight.
  std::unique_ptr<history::HistoryStore> store = history::open_history(lo.history, error);
  if (!store) {
    std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  history::LessonProgress p;
  if (!read_progress(*store, lo.trainee, *lesson, p, error)) {
    std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  if (lo.reset) {
    if (!store->reset_lesson(lo.trainee, lesson->name, lesson->hash, error)) {
      std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error).c_str());
      return kExitError;
    }
    std::printf("mixpilot lesson: %s starts %s over at step 1\n",
                escape_controls(lo.trainee).c_str(), escape_controls(lesson->name).c_str());
    return kExitOk;
  }
  if (lo.status) {
    std::printf("%s in ", escape_controls(lo.trainee).c_str());
    print_steps(*lesson, &p);
    std::vector<history::StoredAttempt> attempts;
    if (!store->lesson_attempts(lo.trainee, lesson->name, lesson->hash, attempts, error)) {
      std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error).c_str());
      return kExitError;
    }
    std::printf("%zu attempt%s\n", attempts.size(), attempts.size() == 1 ? "" : "s");
    for (const history::StoredAttempt& a : attempts)
      std::printf("  step %d: %s (skill %.1f)%s%s\n", a.step + 1, a.passed ? "passed" : "failed",
                  a.skill, a.passed ? "" : ": ", a.passed ? "" : escape_controls(a.detail).c_str());
    say_next(*lesson, p);
    return kExitOk;
  }
  if (!lo.headless) {
    // The window, with the lesson chosen for the trainee: its picker flies the steps.
    FlyOptions o;
    o.command = "lesson";
    o.pilot = lo.pilot;
    o.trainee = lo.trainee;
    o.history = lo.history;
    o.lesson_file = path;
    if (!p.completed()) o = lesson_flight(*lesson, p.step, o);
    else o.scenario_path = lesson->steps.back().scenario_path;
    o.lesson = {};  // the picker tags the flights it makes
    return run_fly(o);
  }
  catch_interrupts();
  HistoryWriter writer(lo.history);
  for (;;) {
    if (p.completed()) {
      std::printf("mixpilot lesson: %s has passed every step of %s\n",
                  escape_controls(lo.trainee).c_str(), escape_controls(lesson->name).c_str());
      return kExitOk;
    }
    const LessonStep& s = lesson->steps[std::size_t(p.step)];
    if (out_of_attempts(s, p.failed_attempts)) {
      std::fprintf(stderr, "mixpilot lesson: %s: step %d is closed: its %d attempts failed; "
                   "--reset starts the lesson over\n",
                   escape_controls(lo.trainee).c_str(), p.step + 1, s.attempts);
      return kExitError;
    }
    bool passed = false;
    const int status = fly_step(lo, *lesson, p.step, writer, passed);
    if (status != kExitOk && status != kExitStepFailed) return status;
    if (!read_progress(*store, lo.trainee, *lesson, p, error)) {
      std::fprintf(stderr, "mixpilot lesson: %s\n", escape_controls(error).c_str());
      return kExitError;
    }
    say_next(*lesson, p);
    if (!passed || !lo.until_done || p.completed()) return status;
  }
}

}  // namespace

int lesson_command(int argc, char** argv) {
  const char* cmd = "lesson";
  LessonOptions lo;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&] { return option_value(cmd, argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kLessonUsage, stdout);
      return kExitOk;
    } else if (a == "--trainee") {
      lo.trainee = value();
      if (const std::string why = history::check_trainee(lo.trainee); !why.empty())
        usage_error(cmd, "--trainee: " + why);
    } else if (a == "--pilot") {
      lo.pilot = value();
    } else if (a == "--history") {
      lo.history = value();
      if (lo.history == "off")
        usage_error(cmd, "--history off: a lesson's progress lives in the history");
    } else if (a == "--record-dir") {
      lo.record_dir = value();
    } else if (a == "--no-record") {
      lo.no_record = true;
    } else if (a == "--headless") {
      lo.headless = true;
    } else if (a == "--until-done") {
      lo.until_done = true;
    } else if (a == "--status") {
      lo.status = true;
    } else if (a == "--reset") {
      lo.reset = true;
    } else if (a == "--check") {
      lo.check = true;
    } else if (a == "--list") {
      lo.list = true;
    } else if (!a.empty() && a[0] == '-') {
      usage_error(cmd, "unknown option '" + escape_controls(a) + "'");
    } else if (lo.lesson_arg.empty()) {
      lo.lesson_arg = file_argument(cmd, "a lesson", a);
    } else {
      usage_error(cmd, "one lesson at a time (got '" + escape_controls(lo.lesson_arg) + "' and '" +
                           escape_controls(a) + "')");
    }
  }
  const int actions = int(lo.status) + int(lo.reset) + int(lo.check) + int(lo.list);
  if (actions > 1) usage_error(cmd, "one of --status, --reset, --check and --list");
  if (lo.list) {
    if (!lo.lesson_arg.empty()) usage_error(cmd, "--list takes no lesson");
    return run_lesson(lo);
  }
  if (lo.lesson_arg.empty()) usage_error(cmd, "which lesson? (mixpilot lesson --list)");
  if (!lo.check && lo.trainee.empty())
    usage_error(cmd, "whose lesson? (--trainee NAME: the progress is the trainee's)");
  const bool flies = actions == 0;
  if (!flies && (lo.headless || lo.until_done || !lo.pilot.empty() || lo.no_record ||
                 !lo.record_dir.empty()))
    usage_error(cmd, "--status, --reset and --check fly nothing: no --headless, --pilot, "
                     "--until-done, --record-dir or --no-record with them");
  if (lo.no_record && !lo.record_dir.empty())
    usage_error(cmd, "--no-record and --record-dir contradict each other");
  if (flies && !lo.headless) {
    if (lo.until_done)
      usage_error(cmd, "--until-done is for --headless flights (in the window, the lesson "
                       "picker offers the next step after each flight)");
    if (!lo.record_dir.empty() || lo.no_record)
      usage_error(cmd, "in the window, the session panel's record switch decides");
  }
  if (flies && lo.headless && (lo.pilot == "keyboard" || is_device_pilot(lo.pilot) ||
                               lo.pilot.ends_with(".mcap")))
    usage_error(cmd, "--headless flies an emulated pilot (novice, experienced, reckless or "
                     "another profile of the scenario); a person flies in the window (without "
                     "--headless)");
  if (flies && lo.headless && !lo.no_record && lo.record_dir.empty()) {
    std::string why;
    const std::string base = xdg_dir("XDG_DATA_HOME", ".local/share", &why);
    if (base.empty())
      usage_error(cmd, "no folder for recordings (" + why + "): --record-dir DIR or --no-record");
    lo.record_dir = base + "/mixpilot/recordings";
  }
  return run_lesson(lo);
}

}  // namespace mixpilot::cli
