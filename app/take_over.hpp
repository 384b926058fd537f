#pragma once
// Fly from here (SPEC §10) in the window: the moment under a replay's playhead made ready for a
// live flight, off the UI thread. A fresh replay of the recording flies to step k on a worker
// thread (checked step by step against the recording, as every replay is) and the flight is
// saved there (Mode::save); the recording's SHA-256, which the branch will name, is taken on
// the way. The replay's tape keeps no snapshots: one of a flight holds its score's logs, as
// long as the flight, so snapshots every second would weigh the square of its length. The UI
// polls progress() each frame and, once done(), hands moment() to the live flight.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "app/flight.hpp"

namespace mixpilot::cli {

class TakeOver {
 public:
  // Starts flying `recording` (a path) to step `k` on the worker.
  TakeOver(std::string recording, std::int64_t k);
  ~TakeOver();  // stops the worker early if need be, and joins it
  TakeOver(const TakeOver&) = delete;
  TakeOver& operator=(const TakeOver&) = delete;

  std::int64_t step() const { return k_; }
  const std::string& recording() const { return recording_; }
  // The part of the way to step k flown, 0 … 1.
  double progress() const;
  bool done() const { return done_.load(std::memory_order_acquire); }
  // After done(): the moment, or nullptr with error() (the recording cannot be read or
  // replayed, or its replay differs from it before step k).
  std::shared_ptr<const FlyFrom> moment() const { return done() ? moment_ : nullptr; }
  const std::string& error() const { return error_; }
  double seconds() const { return seconds_; }  // [s] of wall time it took, once done()

 private:
  void run();

  std::string recording_;
  std::int64_t k_;
  std::atomic<std::int64_t> flown_{0};
  std::atomic<bool> done_{false}, stop_{false};
  std::shared_ptr<const FlyFrom> moment_;
  std::string error_;
  double seconds_ = 0.0;
  std::thread worker_;  // last: it starts once the rest is made
};

}  // namespace mixpilot::cli
