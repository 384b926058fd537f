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
#include <functional>
#include <memory>
#include <thread>

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

}  // namespace mixpilot::test
