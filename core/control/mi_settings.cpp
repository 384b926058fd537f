#include "core/control/mi_settings.hpp"

#include <cmath>

namespace mixpilot {

Eigen::Vector3d HelixReference::position(double t) const {
  const double a = phase + angular_rate * t;
  return {center.x() + radius * std::cos(a), center.y() + radius * std::sin(a),
          start_height + climb_rate * t};
}

Eigen::Vector3d HelixReference::velocity(double t) const {
  const double a = phase + angular_rate * t;
  return {-radius * angular_rate * std::sin(a), radius * angular_rate * std::cos(a), climb_rate};
}

}  // namespace mixpilot
