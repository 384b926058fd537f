#pragma once
// What a mode does with a remote vehicle's states each step (core/modes/vehicle_link.hpp),
// shared by the modes that fly one: take the newest state, turn each new one into a round-trip
// sample (core/control/rtt_estimator.hpp), say how long the vehicle has been silent, and give
// the horizon over which the state is to be predicted (SPEC §5.2, §9).
//
// setup() sizes; read() allocates nothing.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/control/rtt_estimator.hpp"
#include "core/modes/vehicle_link.hpp"
#include "core/numerics/stats.hpp"

namespace mixpilot {

class VehicleFeed {
 public:
  // The longest round-trip time a prediction covers [s].
  static constexpr double kMaxRtt = 0.5;

  // What step k learns.
  struct Reading {
    const VehicleSample* sample = nullptr;  // the state read (the link's, valid for this step)
    bool heard = false;      // a state of the right size has arrived (else: the start state)
    bool fresh = false;      // it is new since the last step, and it echoes a command
    double sigma = 0.0;      // fresh: when it was measured on the controller's clock, t_j + a [s]
    double silent_s = 0.0;   // since the newest state arrived (since command 0 before any) [s]
    int horizon_substeps = 0;  // the prediction horizon
  };

  // dt: control period; h: the predictor's substep; `samples`: round-trip samples kept for
  // the median (more are counted in the estimate, not kept).
  void setup(int nx, double dt, double h, int max_substeps, std::size_t samples) {
    nx_ = nx;
    dt_ = dt;
    h_ = h;
    max_substeps_ = max_substeps;
    rtt_.reset();
    samples_.clear();
    samples_.reserve(samples);
    last_serial_ = 0;
    t0_ns_ = 0;
  }

  // Step k at `now` (link.now_ns()); substeps_per_period: of the predictor.
  Reading read(VehicleLink& link, std::int64_t k, std::int64_t now, int substeps_per_period) {
    if (k == 0) t0_ns_ = now;
    // Read once: the link may hand over a newer state at any call.
    const VehicleSample& v = link.latest();
    Reading r;
    r.sample = &v;
    r.heard = v.serial != 0 && v.x.size() == nx_;
    if (r.heard && v.serial != last_serial_) {
      last_serial_ = v.serial;
      if (v.command >= 0) {
        // τ = t_recv − T_j − a (core/control/rtt_estimator.hpp)
        const double tau = 1e-9 * double(v.received_ns - v.command_stamp_ns) - v.command_age_s;
        if (rtt_.add(tau) && samples_.size() < samples_.capacity()) samples_.push_back(tau);
        r.fresh = true;
        r.sigma = double(v.command) * dt_ + v.command_age_s;
      }
    }
    r.silent_s = 1e-9 * double(now - (r.heard ? std::max(v.received_ns, t0_ns_) : t0_ns_));
    // A vehicle that has applied no command yet rests until command 0 acts (σ = 0): the whole
    // history is predicted. Else the estimate plus the time the state waited here.
    if (!r.heard || v.command < 0) {
      r.horizon_substeps = int(std::min<std::int64_t>(k * substeps_per_period, max_substeps_));
    } else {
      const double wait = 1e-9 * double(now - v.received_ns);
      r.horizon_substeps =
          std::clamp(int(std::lround((rtt_.estimate() + wait) / h_)), 0, max_substeps_);
    }
    horizon_substeps_ = r.horizon_substeps;
    return r;
  }

  const RttEstimator& rtt() const { return rtt_; }
  // The median of the samples kept [s] (0 without any). Allocates: not for the loop.
  double measured_median() const { return percentile(samples_, 0.5); }
  std::size_t sample_count() const { return samples_.size(); }
  double horizon_s() const { return double(horizon_substeps_) * h_; }

 private:
  int nx_ = 0;
  double dt_ = 0.0, h_ = 0.0;
  int max_substeps_ = 0;
  RttEstimator rtt_;
  std::vector<double> samples_;  // round-trip samples [s], reserved
  std::uint64_t last_serial_ = 0;
  std::int64_t t0_ns_ = 0;        // the stamp of command 0
  int horizon_substeps_ = 0;
};

}  // namespace mixpilot
