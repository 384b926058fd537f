#include "ui/scene.hpp"

#include <algorithm>
#include <cmath>

namespace mixpilot::ui {

Scene scene_of(const Mode& mode, const std::string& input_source) {
  Scene s;
  static_cast<ModeView&>(s) = mode.view();
  s.mode = mode.kind();
  s.title = mode.scenario_name();
  s.input_source = input_source;
  s.dt = mode.dt();
  s.duration = double(mode.steps_total()) * mode.dt();
  s.probe = mode.identity().probe;
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

void History::pop_newest() {
  if (view_ || size_ == 0) return;
  if (ring_.size() < capacity_) ring_.pop_back();  // still filling: the newest is the last
  head_ = (head_ + capacity_ - 1) % capacity_;
  --size_;
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
