#pragma once
// What both history backends' tests check of a flight read back: every field as written, the
// doubles exact to the bit, a score that was not finite read back as NaN.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>
#include <memory>
#include <thread>

#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"

namespace mixpilot::test {

inline void expect_same_flight(const history::FlightRecord& f, const history::StoredFlight& r) {
  EXPECT_GT(r.id, 0);
  EXPECT_EQ(r.trainee, f.trainee);
  EXPECT_EQ(r.station, f.station);
  EXPECT_EQ(r.scenario, f.scenario);
  EXPECT_EQ(r.scenario_hash, f.scenario_hash);
  EXPECT_EQ(r.mode, f.mode);
  EXPECT_EQ(r.pilot, f.pilot);
  EXPECT_EQ(r.input_device, f.input_device);
  EXPECT_EQ(r.input_settings_hash, f.input_settings_hash);
  EXPECT_EQ(r.started_unix_ms, f.started_unix_ms);
  EXPECT_EQ(r.duration_s, f.duration_s);
  EXPECT_EQ(r.ended, f.ended);
  EXPECT_EQ(r.probe, f.probe);
  EXPECT_EQ(r.recording_path, f.recording_path);
  EXPECT_EQ(r.recording_hash, f.recording_hash);
  EXPECT_EQ(r.app_version, f.app_version);
  EXPECT_EQ(r.front_end, f.front_end);
  EXPECT_EQ(r.parent_recording_hash, f.parent_recording_hash);
  EXPECT_EQ(r.parent_step, f.parent_step);
  ASSERT_EQ(r.metrics.size(), f.metrics.size());
  for (std::size_t i = 0; i < f.metrics.size(); ++i) {
    EXPECT_EQ(r.metrics[i].first, f.metrics[i].first);
    if (std::isfinite(f.metrics[i].second))
      EXPECT_EQ(r.metrics[i].second, f.metrics[i].second) << f.metrics[i].first;
    else
      EXPECT_TRUE(std::isnan(r.metrics[i].second)) << f.metrics[i].first;
  }
}

// Runs child(k), k = 0..n-1, in n processes forked at once, each ending with child(k)'s value as
// its exit status; returns how many did not end with status 0 (or could not be forked).
inline int failed_children(int n, const std::function<int(int)>& child) {
  std::vector<pid_t> kids;
  for (int k = 0; k < n; ++k) {
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(child(k));
    if (pid > 0) kids.push_back(pid);
  }
  int failed = n - static_cast<int>(kids.size());
  for (pid_t pid : kids) {
    int st = 0;
    if (::waitpid(pid, &st, 0) != pid || !WIFEXITED(st) || WEXITSTATUS(st) != 0) ++failed;
  }
  return failed;
}

// Writer k of the many-writers tests, in its own process: opens the store at `location`
// (open_history; a new one or not) and adds `count` flights flight(k, i). Its exit status: 0,
// 2 when the store does not open, 3 when a flight is not added (said on stderr).
inline int write_flights(const std::string& location, int k, int count,
                         const std::function<history::FlightRecord(int k, int i)>& flight) {
  std::string error;
  auto store = history::open_history(location, error);
  if (!store) {
    std::fprintf(stderr, "child %d: %s\n", k, error.c_str());
    return 2;
  }
  for (int i = 0; i < count; ++i)
    if (store->add(flight(k, i), error) != history::HistoryStore::Added::added) {
      std::fprintf(stderr, "child %d flight %d: %s\n", k, i, error.c_str());
      return 3;
    }
  return 0;
}

// A writer process killed inside a transaction: it opens its store (`open`, in the child) and
// adds `flight(i)` for i = 0, 1, ... with `metrics` score fields each (a long transaction),
// reporting each commit on a pipe; `wait` after its `after`-th report it gets SIGKILL. What it
// reported committed before dying, and whether the kill (not an error) ended it.
struct KilledWriter {
  int last_reported = -1;  // the last flight whose commit it reported (-1: none)
  bool killed = false;     // SIGKILL ended it, not an error of its own
  int status = 0;          // waitpid's status, for messages
};
inline KilledWriter kill_a_writer_mid_transaction(
    const std::function<std::unique_ptr<history::HistoryStore>()>& open,
    const std::function<history::FlightRecord(int)>& flight, int metrics, int after,
    std::chrono::milliseconds wait) {
  KilledWriter out;
  int fds[2];
  if (::pipe(fds) != 0) return out;
  const pid_t pid = ::fork();
  if (pid < 0) return out;
  if (pid == 0) {
    ::close(fds[0]);
    auto store = open();
    if (!store) ::_exit(2);
    std::string error;
    for (int i = 0;; ++i) {
      history::FlightRecord f = flight(i);
      f.metrics.clear();
      for (int m = 0; m < metrics; ++m) f.metrics.emplace_back("m" + std::to_string(m), m);
      if (store->add(f, error) != history::HistoryStore::Added::added) ::_exit(3);
      const std::int32_t done = i;
      if (::write(fds[1], &done, sizeof done) != sizeof done) ::_exit(4);
    }
  }
  ::close(fds[1]);
  std::int32_t got = 0;
  while (out.last_reported < after && ::read(fds[0], &got, sizeof got) == sizeof got)
    out.last_reported = got;
  std::this_thread::sleep_for(wait);  // somewhere inside the next transaction
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &out.status, 0);
  out.killed = WIFSIGNALED(out.status);
  while (::read(fds[0], &got, sizeof got) == sizeof got) out.last_reported = got;  // before dying
  ::close(fds[0]);
  return out;
}

inline history::FlightRecord flight(const std::string& trainee, std::int64_t started, double skill,
                             const std::string& recording_hash = "") {
  history::FlightRecord f;
  f.trainee = trainee;
  f.station = "station-1";
  f.scenario = "lesson_hover";
  f.scenario_hash = sha256_hex("scenario");
  f.mode = "mixed_initiative";
  f.pilot = "novice";
  f.started_unix_ms = started;
  f.duration_s = 10.0;
  f.app_version = "mixpilot test";
  f.front_end = "lesson";
  f.recording_hash = recording_hash;
  if (!recording_hash.empty()) f.recording_path = "/r/" + recording_hash.substr(0, 8) + ".mcap";
  f.metrics = {{"skill", skill}};
  return f;
}

inline history::LessonAttempt attempt(int step, bool passed, const std::string& hash = "h1") {
  history::LessonAttempt a;
  a.lesson = "beginner";
  a.lesson_hash = hash;
  a.steps = 3;
  a.step = step;
  a.step_title = "step " + std::to_string(step);
  a.ceiling = 0.3 + 0.2 * step;
  a.passed = passed;
  a.failed_criterion = passed ? "" : "min_skill";
  a.detail = passed ? "skill 80.0 (at least 60)" : "skill 41.0 (at least 60)";
  return a;
}

inline history::LessonProgress progress_of(history::HistoryStore& store, const std::string& trainee,
                                    const std::string& hash = "h1") {
  std::vector<history::LessonProgress> all;
  std::string error;
  EXPECT_TRUE(store.lesson_progress(trainee, all, error)) << error;
  for (const auto& p : all)
    if (p.lesson == "beginner" && p.lesson_hash == hash) return p;
  return {};
}

// Lessons (SPEC §10), for both backends' tests: a flight of `trainee` and a lesson attempt of
// the 3-step lesson "beginner" (version `hash`).
// The attempts and the progress (SPEC §10), written with the flight in one transaction: a
// failure counts, a pass moves on, an attempt at another step than the trainee's is refused
// and writes nothing, a known recording adds nothing, a reset starts over and keeps the
// attempts, another version of the lesson (hash) is its own, and each flight's row says its
// lesson, step and verdict.
inline void progress_round_trip(history::HistoryStore& store) {
  std::string error;
  using Added = history::HistoryStore::Added;
  ASSERT_EQ(store.add_attempt(flight("Ada", 1000, 41.0, "rec1"), attempt(0, false), error),
            Added::added)
      << error;
  history::LessonProgress p = progress_of(store, "Ada");
  EXPECT_EQ(p.step, 0);
  EXPECT_EQ(p.failed_attempts, 1);
  EXPECT_EQ(p.steps, 3);
  ASSERT_EQ(store.add_attempt(flight("Ada", 2000, 80.0), attempt(0, true), error), Added::added)
      << error;
  p = progress_of(store, "Ada");
  EXPECT_EQ(p.step, 1);
  EXPECT_EQ(p.failed_attempts, 0);
  // Step 0 again, or step 2: not the trainee's step; nothing written (no flight either).
  for (int wrong : {0, 2}) {
    EXPECT_FALSE(store.add_attempt(flight("Ada", 3000, 80.0), attempt(wrong, true), error));
    EXPECT_NE(error.find("the trainee is on step 2 of beginner, not step " +
                         std::to_string(wrong + 1)),
              std::string::npos)
        << error;
  }
  // The same recording again: already known, the progress unmoved.
  EXPECT_EQ(store.add_attempt(flight("Ada", 4000, 80.0, "rec1"), attempt(1, true), error),
            Added::already_known);
  EXPECT_EQ(progress_of(store, "Ada").step, 1);
  // A refused attempt: its texts checked like a flight's.
  history::LessonAttempt bad = attempt(1, true);
  bad.failed_criterion = "min_skill";
  EXPECT_FALSE(store.add_attempt(flight("Ada", 5000, 80.0), bad, error));
  EXPECT_NE(error.find("a verdict names a failed criterion exactly when it failed"),
            std::string::npos)
      << error;
  bad = attempt(3, true);
  EXPECT_FALSE(store.add_attempt(flight("Ada", 5000, 80.0), bad, error));
  EXPECT_NE(error.find("step 3 is not one of the lesson's 3"), std::string::npos) << error;
  ASSERT_EQ(store.add_attempt(flight("Ada", 6000, 81.0), attempt(1, true), error), Added::added);
  ASSERT_EQ(store.add_attempt(flight("Ada", 7000, 82.0), attempt(2, true), error), Added::added);
  p = progress_of(store, "Ada");
  EXPECT_EQ(p.step, 3);
  EXPECT_TRUE(p.completed());
  EXPECT_FALSE(store.add_attempt(flight("Ada", 8000, 80.0), attempt(2, true), error));
  EXPECT_NE(error.find("has passed every step of beginner already"), std::string::npos) << error;
  // Another trainee, another version of the lesson: their own progress.
  ASSERT_EQ(store.add_attempt(flight("Grace", 9000, 50.0), attempt(0, false), error),
            Added::added);
  ASSERT_EQ(store.add_attempt(flight("Ada", 9500, 90.0), attempt(0, true, "h2"), error),
            Added::added);
  EXPECT_EQ(progress_of(store, "Grace").failed_attempts, 1);
  EXPECT_EQ(progress_of(store, "Ada", "h2").step, 1);
  std::vector<history::LessonProgress> all;
  ASSERT_TRUE(store.lesson_progress("", all, error)) << error;
  EXPECT_EQ(all.size(), 3u);
  // The attempts, oldest first, with their flights' skill and verdicts.
  std::vector<history::StoredAttempt> attempts;
  ASSERT_TRUE(store.lesson_attempts("Ada", "beginner", "h1", attempts, error)) << error;
  ASSERT_EQ(attempts.size(), 4u);
  EXPECT_FALSE(attempts[0].passed);
  EXPECT_EQ(attempts[0].failed_criterion, "min_skill");
  EXPECT_EQ(attempts[0].detail, "skill 41.0 (at least 60)");
  EXPECT_EQ(attempts[0].skill, 41.0);
  EXPECT_EQ(attempts[0].recording_path, "/r/rec1.mcap");
  EXPECT_EQ(attempts[0].ceiling, 0.3);
  EXPECT_EQ(attempts[3].step, 2);
  EXPECT_EQ(attempts[3].step_title, "step 2");
  EXPECT_EQ(attempts[3].steps, 3);
  // Every flight's row names its attempt; a plain flight none.
  ASSERT_EQ(store.add(flight("Ada", 9900, 70.0), error), Added::added) << error;
  std::vector<history::StoredFlight> rows;
  history::Query q;
  q.trainee = "Ada";
  ASSERT_TRUE(store.query(q, rows, error)) << error;
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[0].lesson, "beginner");
  EXPECT_EQ(rows[0].lesson_step, 0);
  EXPECT_FALSE(rows[0].lesson_passed);
  EXPECT_EQ(rows[0].lesson_failed, "min_skill");
  EXPECT_TRUE(rows[1].lesson_passed);
  EXPECT_EQ(rows[1].lesson_failed, "");
  EXPECT_EQ(rows[5].lesson, "");
  EXPECT_EQ(rows[5].lesson_step, -1);
  // A reset: step 1 again, the attempts kept.
  ASSERT_TRUE(store.reset_lesson("Ada", "beginner", "h1", error)) << error;
  p = progress_of(store, "Ada");  // the row stays (a push carries the reset), at step 0
  EXPECT_EQ(p.steps, 3);
  EXPECT_EQ(p.step, 0);
  EXPECT_EQ(p.failed_attempts, 0);
  ASSERT_TRUE(store.lesson_attempts("Ada", "beginner", "h1", attempts, error)) << error;
  EXPECT_EQ(attempts.size(), 4u);
  ASSERT_EQ(store.add_attempt(flight("Ada", 9990, 80.0), attempt(0, true), error), Added::added)
      << error;
  EXPECT_EQ(progress_of(store, "Ada").step, 1);
}

}  // namespace mixpilot::test
