#pragma once
// The body → world attitude of a quadrotor state (SPEC §2, §3): Euler ZYX angles after the
// position (16 states, MikroKopter) or a unit quaternion (qw, qx, qy, qz) after it (13 states,
// Crazyflie); identity for other states.
#include <Eigen/Dense>
#include <Eigen/Geometry>

namespace mixpilot::models {

inline Eigen::Quaterniond attitude(const Eigen::VectorXd& x) {
  if (x.size() >= 16)
    return Eigen::AngleAxisd(x(5), Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(x(4), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(x(3), Eigen::Vector3d::UnitX());
  if (x.size() >= 7) return Eigen::Quaterniond(x(3), x(4), x(5), x(6)).normalized();
  return Eigen::Quaterniond::Identity();
}

}  // namespace mixpilot::models
