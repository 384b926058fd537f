#pragma once
// What a mode shows of itself (SPEC §8): the world it flies in, how to look at it and which of
// its channels to plot. Front ends draw from this description and from the telemetry alone, so
// a new mode is drawn without the UI knowing its type.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/modes/reference_progress.hpp"
#include "core/nlp/ocp.hpp"

namespace mixpilot {

// How the flight is looked at: a quadrotor in a 3D arena, or the Pendubot's arm side-on.
enum class ViewKind { arena_3d, arm_2d };

// What a plotted series stands for; the UI picks its colour from it.
enum class SeriesRole {
  pilot,       // what the pilot asked for
  applied,     // what the controller applied
  soft_limit,  // a bound a flight should keep (the ball's radius)
  hard_limit,  // a bound of the vehicle (the rotor speed's)
  timing,      // computing time
  other,       // anything else: colours in turn
};

struct PlotSeries {
  const char* channel = "";  // a Telemetry channel's name (a string literal of the mode)
  SeriesRole role = SeriesRole::other;
};

struct PlotSpec {
  const char* title = "";
  std::vector<PlotSeries> series;
};

struct ViewSphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // [m]
  double radius = 0.1;                               // [m]
};

struct ModeView {
  ViewKind view = ViewKind::arena_3d;
  // The pilot shares the authority with the planner (mixed initiative): the authority bar, λ
  // colouring, the sticks and the ball B are shown.
  bool shared_authority = false;
  Eigen::Vector3d arena_min{-3.0, -3.0, 0.0};  // [m] quadrotor modes: the flight volume
  Eigen::Vector3d arena_max{3.0, 3.0, 3.0};    // [m]
  std::vector<ViewSphere> spheres;             // static obstacles
  // Moving obstacles: their centres at time t (the obstacle mode's thrown balls). It holds a
  // copy of what it needs: it outlives nothing of the mode.
  std::function<void(double t, std::vector<Eigen::Vector3d>& centers)> moving;
  double moving_radius = 0.1;      // [m]
  Eigen::Matrix3Xd reference;      // 3 x M: the whole reference path, for drawing
  // η^r(τ) at any reference time, for progress along it (core/modes/reference_progress.hpp:
  // a ghost's ahead / behind). It holds a copy of what it needs. Empty: the mode has none.
  ReferencePath reference_at;
  double ball_radius = 0.0;        // [m] r of the ball B (shared authority), 0: none
  // [m] the vehicle's sphere, which Telemetry::clearance is measured from (0: none measured)
  double vehicle_radius = 0.0;
  double hover_rotor_speed = 1.0;  // Ω at hover (shared authority: the thrust stick's centre)
  double link1 = 0.0, link2 = 0.0;  // [m] arm view: the two links
  // The plots, in order; empty: one plot per telemetry channel.
  std::vector<PlotSpec> plots;
};

// What a mode says about the flight for a recording's metadata and a front end's choices.
struct ModeIdentity {
  std::string pilot;                  // the pilot flying ("" where the controller flies)
  std::vector<std::string> pilots;    // the scenario's own pilots a user may pick ("": none)
  std::optional<std::uint64_t> seed;  // the plant's random seed, where it has one
  // A probe flight (SPEC §10): the planner does not assist (λ pinned to 1 in the cost, every
  // constraint kept), so the score is the pilot's own skill.
  bool probe = false;
};

// Samples of a path given as p(t) over [0, duration], every 50 ms (2 to 4000 samples).
Eigen::Matrix3Xd sample_path(double duration, const std::function<Eigen::Vector3d(double)>& p);

// The positions (the first three states) of a reference trajectory's nodes, 3 x M.
Eigen::Matrix3Xd positions_of(const OcpTrajectory& reference);

// The arena of a view that has no walls: the box around `points` grown by `margin`, its floor
// at z = 0 or below.
void fit_arena(ModeView& view, const Eigen::Matrix3Xd& points, double margin);

}  // namespace mixpilot
