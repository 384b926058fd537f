#include "ui/scene.hpp"

#include <algorithm>
#include <cmath>

#include "core/modes/mi_mode.hpp"
#include "core/modes/obstacle_mode.hpp"
#include "core/modes/pendubot_mode.hpp"
#include "core/modes/tracking_mode.hpp"

namespace mixpilot::ui {
namespace {

// Samples of a path given as a function of time over [0, duration].
template <class F>
Eigen::Matrix3Xd sample_path(double duration, F position) {
  const int m = std::clamp(int(duration / 0.05), 2, 4000);
  Eigen::Matrix3Xd out(3, m);
  for (int i = 0; i < m; ++i) out.col(i) = position(duration * double(i) / double(m - 1));
  return out;
}

void bounds_around(Scene& s, const Eigen::Matrix3Xd& points, double margin) {
  if (points.cols() == 0) return;
  s.arena_min = points.rowwise().minCoeff().array() - margin;
  s.arena_max = points.rowwise().maxCoeff().array() + margin;
  s.arena_min.z() = std::min(0.0, s.arena_min.z());
}

}  // namespace

Scene scene_of(const Mode& mode, const std::string& input_source) {
  Scene s;
  s.mode = mode.kind();
  s.title = mode.scenario_name();
  s.input_source = input_source;
  s.dt = mode.dt();
  s.duration = double(mode.steps_total()) * mode.dt();
  if (const auto* mi = dynamic_cast<const MiMode*>(&mode)) {
    const Scenario& sc = mi->scenario();
    s.arena_min = sc.arena.min;
    s.arena_max = sc.arena.max;
    for (const Obstacle& o : sc.arena.obstacles) s.spheres.push_back({o.center, o.radius});
    s.reference = sample_path(sc.duration, [&](double t) { return sc.reference.position(t); });
    s.ball_radius = sc.controller.ph.r;
    s.hover_rotor_speed = mi->model().hover_speed();
  } else if (const auto* ob = dynamic_cast<const ObstacleMode*>(&mode)) {
    const ObstacleWorld& w = ob->world();
    const double r = ob->settings().clearance;
    for (const auto& c : w.spheres) s.spheres.push_back({c, r});
    if (!w.balls.empty()) {
      const ObstacleWorld world = w;  // a copy: the scene outlives nothing of the mode
      const int first = int(world.spheres.size());
      s.moving = [world, first](double t, std::vector<Eigen::Vector3d>& centers) {
        centers.clear();
        for (int j = first; j < world.size(); ++j) centers.push_back(world.position(j, t));
      };
      s.moving_radius = r;
    }
    const OcpTrajectory& ref = ob->scenario().reference.trajectory;
    s.reference.resize(3, Eigen::Index(ref.x.size()));
    for (std::size_t i = 0; i < ref.x.size(); ++i)
      s.reference.col(Eigen::Index(i)) = ref.x[i].head<3>();
    bounds_around(s, s.reference, 1.0);
  } else if (const auto* tr = dynamic_cast<const TrackingMode*>(&mode)) {
    const OcpTrajectory& ref = tr->scenario().reference_trajectory;
    s.reference.resize(3, Eigen::Index(ref.x.size()));
    for (std::size_t i = 0; i < ref.x.size(); ++i)
      s.reference.col(Eigen::Index(i)) = ref.x[i].head<3>();
    bounds_around(s, s.reference, 0.75);
  }
  return s;
}

double channel_value(const Telemetry& s, std::string_view name, double fallback) {
  for (int i = 0; i < s.num_channels; ++i)
    if (name == s.channels[std::size_t(i)].name) return s.channels[std::size_t(i)].value;
  return fallback;
}

void History::push(const Telemetry& s) {
  if (ring_.size() < capacity_) {
    ring_.push_back(s);
  } else {
    ring_[head_] = s;
  }
  head_ = (head_ + 1) % capacity_;
  size_ = std::min(size_ + 1, capacity_);
}

std::size_t History::first_at_or_after(double t) const {
  std::size_t lo = 0, hi = size_;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if ((*this)[mid].t < t) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

}  // namespace mixpilot::ui
