#pragma once
// A ghost (SPEC §10 debrief): a recorded flight of the scenario being flown, flying along in
// step by time — at the flight's time t it is where the recording was at t — drawn as a
// translucent vehicle with its trail, and the HUD's "ghost: ahead / behind by X s" along the
// reference. A plain, immutable snapshot: the app reads the recording and computes its progress
// off the UI thread (app/ghost.hpp); a frame only draws it. The control thread never sees it.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/modes/reference_progress.hpp"

namespace mixpilot {
struct Telemetry;
}

namespace mixpilot::ui {

struct Scene;

struct Ghost {
  std::string label;          // what the legend calls it ("your best: attempt 7, skill 81")
  std::string path;           // its recording
  std::string scenario_hash;  // SHA-256 of the scenario it flies (the flight's: checked)
  double dt = 0.0;            // [s] its control period, the flight's
  std::int64_t first_step = 0;  // its first recorded step (a branch's: the take-over)
  // nx x K: column j the recorded state at step first_step + j (a step the recording dropped
  // holds the state before it).
  Eigen::MatrixXd states;
  // K: progress τ_j [s] of column j along the reference (core/modes/reference_progress.hpp),
  // searched around its own time; NaN where there is none (a lost vehicle's non-finite state).
  std::vector<double> progress;

  std::int64_t steps() const { return std::int64_t(states.cols()); }
  // [s] the time of its last step (it shows until then).
  double last_t() const { return double(first_step + steps() - 1) * dt; }
};

// The ghost's column at the flight's time t (step k = round(t / Δt)); nullopt before its first
// step and after its last (a shorter flight, a branch before its take-over).
std::optional<std::size_t> ghost_column(const Ghost& ghost, double t);

// Ahead / behind along the reference at one time: τ_live − τ_ghost.
struct GhostGap {
  double t = 0.0;      // [s] the flight's time
  double live = 0.0;   // [s] τ of the flight's vehicle
  double ghost = 0.0;  // [s] τ of the ghost at t
  double ahead = 0.0;  // [s] live − ghost: > 0 the flight is ahead of the ghost
};

// The gap of the flight's telemetry `live` to the scene's ghost at live.t (τ_live searched as
// the ghost's was, ProgressSearch's defaults); nullopt without a ghost, a reference, or a ghost
// at that time.
std::optional<GhostGap> ghost_gap(const Scene& scene, const Telemetry& live);
// The same for `ghost` along `reference`.
std::optional<GhostGap> ghost_gap(const Ghost& ghost, const ReferencePath& reference,
                                  const Telemetry& live);

// What the HUD says: "ghost: you are ahead by 0.8 s", "ghost: you are behind by 1.2 s", or
// "ghost: level with you" (|gap| < 0.05 s, 0.0 at one decimal).
std::string ghost_gap_text(const GhostGap& gap);

// The HUD's ghost line at the flight's step `live`: the gap with what the ghost is
// ("ghost: you are behind by 1.2 s · your best: attempt 3, skill 81"), or where there is no gap
// why ("ghost: ended at 12.3 s", "ghost: flies from 10.0 s").
std::string ghost_hud_text(const Scene& scene, const Telemetry& live);

}  // namespace mixpilot::ui
