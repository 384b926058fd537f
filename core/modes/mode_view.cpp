#include "core/modes/mode_view.hpp"

#include <algorithm>

namespace mixpilot {

Eigen::Matrix3Xd sample_path(double duration, const std::function<Eigen::Vector3d(double)>& p) {
  const int m = std::clamp(int(duration / 0.05), 2, 4000);
  Eigen::Matrix3Xd out(3, m);
  for (int i = 0; i < m; ++i) out.col(i) = p(duration * double(i) / double(m - 1));
  return out;
}

Eigen::Matrix3Xd positions_of(const OcpTrajectory& reference) {
  Eigen::Matrix3Xd out(3, Eigen::Index(reference.x.size()));
  for (std::size_t i = 0; i < reference.x.size(); ++i) out.col(Eigen::Index(i)) = reference.x[i].head<3>();
  return out;
}

void fit_arena(ModeView& view, const Eigen::Matrix3Xd& points, double margin) {
  if (points.cols() == 0) return;
  view.arena_min = points.rowwise().minCoeff().array() - margin;
  view.arena_max = points.rowwise().maxCoeff().array() + margin;
  view.arena_min.z() = std::min(0.0, view.arena_min.z());
}

}  // namespace mixpilot
