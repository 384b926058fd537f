#include "ui/chase_camera.hpp"

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "models/attitude.hpp"

namespace mixpilot::ui {

Eigen::Vector3d chase_eye(const Telemetry& s, ChasePose pose) {
  const Eigen::Vector3d p = s.x.head<3>();
  const Eigen::Vector3d fwd = models::attitude(s.x).toRotationMatrix().col(0);
  Eigen::Vector3d back(-fwd.x(), -fwd.y(), 0.0);
  if (back.norm() < 1e-6) back = Eigen::Vector3d(-1, 0, 0);
  back = Eigen::AngleAxisd(pose.turn, Eigen::Vector3d::UnitZ()) * back.normalized();
  return p + 2.2 * back + Eigen::Vector3d(0, 0, 1.0 + pose.rise);
}

bool blocks_sight(const Eigen::Vector3d& eye, const Eigen::Vector3d& c, double r,
                  const Eigen::Vector3d& p, double size) {
  if ((c - eye).norm() <= r) return true;
  const Eigen::Vector3d sight = p - eye;
  const double length = sight.norm();
  if (length < 1e-9) return false;
  const double along = (c - eye).dot(sight) / length;
  if (along <= 0.0 || along - r >= length) return false;
  const double t = std::min(along, length);
  return (eye + t / length * sight - c).norm() < r + size;
}

bool sight_blocked(const Scene& sc, const Telemetry& s, const Eigen::Vector3d& eye, double size) {
  if (s.x.size() < 3) return false;
  const Eigen::Vector3d p = s.x.head<3>();
  for (const SceneSphere& o : sc.spheres)
    if (blocks_sight(eye, o.center, o.radius, p, size)) return true;
  if (sc.moving) {
    std::vector<Eigen::Vector3d> centres;
    sc.moving(s.t, centres);
    for (const Eigen::Vector3d& c : centres)
      if (blocks_sight(eye, c, sc.moving_radius, p, size)) return true;
  }
  return false;
}

ChasePose clear_chase_pose(const Scene& sc, const Telemetry& s) {
  if (s.x.size() < 3) return {};
  constexpr double kStep = M_PI / 12.0;  // 15°
  for (const double rise : {0.0, 1.0, 2.5})
    for (int i = 0; i <= 12; ++i)
      for (const int sign : {+1, -1}) {
        const ChasePose pose{sign * i * kStep, rise};
        if (!sight_blocked(sc, s, chase_eye(s, pose))) return pose;
        if (i == 0 || i == 12) break;  // 0 and 180° once
      }
  return {};
}

}  // namespace mixpilot::ui
