#pragma once
// A recording shown in the app (SPEC §8 "Replay"): its session flown again from the embedded
// scenario into a tape of every step's telemetry, on a loader thread, so the window can play it
// at any speed, scrub back and forth and jump to events while the rest still loads. The replay
// is checked step by step against the recording (core/recording/replay.hpp).
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/flight_rig.hpp"
#include "core/modes/debrief.hpp"
#include "core/recording/replay.hpp"
#include "ui/scene.hpp"

namespace mixpilot::cli {

class ReplayTape {
 public:
  // `rig` is an assembled replay (FlightRig::assemble of a recording, which checks it step by
  // step); `path` names the recording.
  ReplayTape(std::unique_ptr<FlightRig> rig, std::string path);
  ~ReplayTape();
  ReplayTape(const ReplayTape&) = delete;
  ReplayTape& operator=(const ReplayTape&) = delete;

  void start();  // flies the tape on the loader thread
  void fly();    // flies it on this thread (headless), with a progress bar on a terminal
  void stop();   // ends the loader early (closing the window)

  // The UI's side: tape()[0 .. ready()) are final and never change again.
  std::size_t ready() const { return ready_.load(std::memory_order_acquire); }
  bool done() const { return done_.load(std::memory_order_acquire); }
  const std::vector<Telemetry>& tape() const { return tape_; }
  // Steps of the replay: as recorded while loading; once done, as flown (a lost vehicle ends
  // a run early).
  std::size_t steps() const { return done() ? ready() : tape_.size(); }
  double dt() const { return dt_; }
  const ui::Scene& scene() const { return scene_; }
  // The UI's: a ghost flying along the replay (ui/ghost.hpp; the loader never reads the scene).
  void set_ghost(std::shared_ptr<const ui::Ghost> ghost) { scene_.ghost = std::move(ghost); }
  // How the debrief reads this flight (SPEC §10, core/modes/debrief.hpp): its Δt, ball and
  // vehicle radius, the default thresholds.
  const DebriefSettings& debrief() const { return debrief_; }
  const std::string& path() const { return path_; }
  const Mode& mode() const { return rig_->mode(); }  // read it only once done()

  // After done(): the replay's metrics (the score card), and what differed from the recording
  // ("" when every step was reproduced bit for bit; "interrupted" when stopped early).
  const Metrics& metrics() const { return metrics_; }
  const std::string& mismatch() const { return mismatch_; }

 private:
  void load();

  std::unique_ptr<FlightRig> rig_;
  std::string path_;
  double dt_ = 0.01;
  ui::Scene scene_;
  DebriefSettings debrief_;
  std::vector<Telemetry> tape_;  // sized once, filled in order
  std::atomic<std::size_t> ready_{0};
  std::atomic<bool> done_{false}, stop_{false};
  std::thread loader_;
  Metrics metrics_;
  std::string mismatch_;
};

// The tape's step shown at playhead time t: the step k with t_k ≤ t < t_k + Δt, within what
// is ready (0 when nothing is).
std::size_t tape_index(const ReplayTape& tape, double t);

}  // namespace mixpilot::cli
