#pragma once
// The chase camera (UI.md §2): behind the vehicle's heading and above it, turned about the
// vertical where an obstacle would stand between it and the vehicle, so the first view of a
// flight (READY) shows the vehicle, not a ball in front of it.
#include <Eigen/Core>

#include "ui/scene.hpp"

namespace mixpilot::ui {

// The vehicle's half size seen from the camera, arms and rotors with a margin [m]: an obstacle
// that comes this close to the line of sight is drawn as glass.
inline constexpr double kVehicleSightRadius = 0.35;
// What the chase camera must see at READY: the line of sight to the vehicle's hub with 5 cm to
// spare [m] (among close obstacles, as obstacles_cluttered's start, one stands within the margin
// above from every side).
inline constexpr double kHubSightMargin = 0.05;

// Where the chase camera stands: 2.2 m behind the vehicle's heading and 1 m above it, the
// "behind" turned about the vertical by `turn` [rad], raised by `rise` [m] more.
struct ChasePose {
  double turn = 0.0;  // [rad]
  double rise = 0.0;  // [m]
};
Eigen::Vector3d chase_eye(const Telemetry& s, ChasePose pose);

// Whether the sphere (c, r) hides part of the vehicle (a ball of radius `size` around p) from
// `eye`: it holds the eye, or it lies along the line of sight, nearer than the vehicle, and
// comes within r + size of it.
bool blocks_sight(const Eigen::Vector3d& eye, const Eigen::Vector3d& c, double r,
                  const Eigen::Vector3d& p, double size = kVehicleSightRadius);

// Whether an obstacle of the scene (its spheres, and its moving balls at s.t) hides the
// vehicle (a ball of radius `size`) from `eye`.
bool sight_blocked(const Scene& sc, const Telemetry& s, const Eigen::Vector3d& eye,
                   double size = kHubSightMargin);

// The least change from behind the vehicle from which the chase camera sees the vehicle of `s`
// with no obstacle in between: the smallest turn, 0 then ±15°, ±30°, … to 180°, at its height,
// else the same raised by 1 m, then by 2.5 m (looking down over what stands around); the
// unchanged pose when none is clear (or there is no vehicle).
ChasePose clear_chase_pose(const Scene& sc, const Telemetry& s);

}  // namespace mixpilot::ui
