#pragma once
// What the UI draws from (SPEC §8): the flight's fixed description (Scene) and a rolling copy of
// its telemetry (History). Both belong to the UI thread; the simulation never sees them.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "core/modes/mode.hpp"
#include "ui/ghost.hpp"

namespace mixpilot::ui {

using SceneSphere = ViewSphere;

// What does not change during a flight: what the mode shows of itself (core/modes/mode_view.hpp)
// and what the front end adds.
struct Scene : ModeView {
  ModeKind mode = ModeKind::mixed_initiative;  // named in the title only: the view says the rest
  std::string title;         // the scenario's name
  std::string input_source;  // the pilot source, or the controller for the other modes
  double dt = 0.01;          // [s] control period
  double duration = 0.0;     // [s] of the whole run
  bool probe = false;        // a probe flight: the planner does not assist (SPEC §10)
  // A recorded flight of the scenario flying along (ui/ghost.hpp); null: none. Immutable, so a
  // frame, a replay and a screenshot share it as loaded.
  std::shared_ptr<const Ghost> ghost;
};

// The value of the channel called `name` in `s`, or `fallback` when it has none.
double channel_value(const Telemetry& s, std::string_view name, double fallback = 0.0);

// The scene of a mode, read through its interface (no effect on the flight).
Scene scene_of(const Mode& mode, const std::string& input_source);

// The telemetry the screen draws, oldest first, newest last: either a ring of the newest
// `capacity` values (a live flight), or a view of the first values of a replay's tape.
class History {
 public:
  explicit History(std::size_t capacity = 4096) : capacity_(capacity) {}
  // A view of tape[0 .. count): the replay's flight up to its playhead. `tape` must outlive it.
  static History view(const std::vector<Telemetry>& tape, std::size_t count) {
    History h(0);
    h.view_ = tape.data();
    h.size_ = std::min(count, tape.size());
    return h;
  }
  void push(const Telemetry& s);
  // Drops the newest value (a ring's; a view stays as it is).
  void pop_newest();
  void clear() {
    ring_.clear();  // keeps its capacity; push() fills it from the front again
    size_ = 0;
    head_ = 0;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  // i = 0 is the oldest kept, size() − 1 the newest.
  const Telemetry& operator[](std::size_t i) const {
    return view_ ? view_[i] : ring_[(head_ + capacity_ - size_ + i) % capacity_];
  }
  const Telemetry& newest() const { return (*this)[size_ - 1]; }
  // The first index whose time is ≥ t (size() when none): windows of the last seconds.
  std::size_t first_at_or_after(double t) const;

 private:
  std::size_t capacity_;
  std::vector<Telemetry> ring_;
  const Telemetry* view_ = nullptr;
  std::size_t head_ = 0;  // where the next value goes
  std::size_t size_ = 0;
};

}  // namespace mixpilot::ui
