#pragma once
// The ghost (SPEC §10): a recorded flight of the scenario being flown, read from its recorded
// states (it is not flown again) into the immutable snapshot the screen draws (ui/ghost.hpp),
// its progress along the reference computed once (core/modes/reference_progress.hpp). The
// window loads it on a GhostLoader's thread, never the UI's; the headless commands read it
// before their flight. Which recording: `--ghost REC.mcap`, or the trainee's best flight of the
// scenario in the history whose recording is still on this disk (--ghost best; the window's
// default).
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "app/flight.hpp"
#include "core/modes/reference_progress.hpp"
#include "ui/ghost.hpp"
#include "ui/progress.hpp"

namespace mixpilot::cli {

// What a ghost must be a flight of: the flight's scenario, by name and content, and its mode,
// control period and reference.
struct GhostTarget {
  std::string scenario_name;
  std::string scenario_hash;  // SHA-256 hex of the scenario's text
  ModeKind mode = ModeKind::mixed_initiative;
  double dt = 0.0;            // [s]
  ReferencePath reference;    // η^r(τ) (a copy: usable on any thread)
};

// The target of the flight `f`; nullopt with the reason when its mode flies no ghost (only a
// pilot's flight has one to race: mixed initiative).
std::optional<GhostTarget> ghost_target(const Flight& f, std::string& error);

// The recording at `path` as a ghost of `target`, named `label` in the legend; nullptr with the
// reason: not a readable recording, a recording of another scenario (its name, or its content:
// the file was edited since) or mode, or one without the vehicle's states.
std::shared_ptr<const ui::Ghost> load_ghost(const std::string& path, const GhostTarget& target,
                                            std::string label, std::string& error);

// The legend's name of the flight `f` of the trainee's history: "your best: attempt 7, skill
// 81.2" (`best`), else "attempt 7, skill 81.2"; a probe says so.
std::string ghost_label(const ui::ProgressFlight& f, bool best);

// --ghost best for a command that may wait on the history (not the window, which reads its
// snapshot): the best recorded flight of `trainee` ("" the login name) on `target`'s scenario
// in the history at `location` (as open_history takes it). nullopt with `why`: the history
// cannot be read, or it holds no such flight.
std::optional<ui::ProgressFlight> best_ghost_flight(const std::string& location,
                                                    const std::string& trainee,
                                                    const GhostTarget& target, std::string& why);

// --ghost's value: "best", "off" or a recording's path; the window's default ("") is best.
struct GhostChoice {
  enum class Kind { off, best, file };
  Kind kind = Kind::best;
  std::string path;  // Kind::file
  static GhostChoice of(const std::string& option);
};

// load_ghost() on a thread of its own. The UI polls done() each frame.
class GhostLoader {
 public:
  GhostLoader(std::string path, GhostTarget target, std::string label);
  ~GhostLoader();  // joins (reading a recording takes as long as the file is large)
  GhostLoader(const GhostLoader&) = delete;
  GhostLoader& operator=(const GhostLoader&) = delete;

  const std::string& path() const { return path_; }
  const GhostTarget& target() const { return target_; }
  bool done() const { return done_.load(std::memory_order_acquire); }
  // Blocks until done() (a headless command, which has no frames to draw meanwhile).
  void wait() {
    if (worker_.joinable()) worker_.join();
  }
  // After done(): the ghost, or nullptr with error().
  std::shared_ptr<const ui::Ghost> ghost() const { return done() ? ghost_ : nullptr; }
  const std::string& error() const { return error_; }

 private:
  std::string path_, label_;
  GhostTarget target_;
  std::shared_ptr<const ui::Ghost> ghost_;
  std::string error_;
  std::atomic<bool> done_{false};
  std::thread worker_;  // last: it starts once the rest is made
};

}  // namespace mixpilot::cli
