#pragma once
// A remote vehicle inside the test process, on a simulated clock (core/modes/vehicle_link.hpp):
// command k leaves at t_k = k·Δt and acts from t_k + τ_c; the state measured when it starts
// acting (the modes' plant, core/modes/simulated_vehicle.hpp's VehiclePlant: s RK4 substeps of
// h per period) arrives τ_m later, echoing k and its stamp with age 0. The controller's clock
// is the time of the step in progress. With it a mode's remote path can be compared with its
// simulated plant step for step, and checked for allocations. setup() sizes; the rest allocates
// nothing.
//
// A hostile vehicle is the same link with `mutate` set: it may rewrite each state (what the
// vehicle claims) before it is sent; `timeout` is the link's silence limit.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/modes/simulated_vehicle.hpp"
#include "core/modes/vehicle_link.hpp"

namespace mixpilot::test {

template <class Model>
class DelayedPlantLink final : public VehicleLink {
 public:
  using State = typename Model::State;
  using Input = typename Model::Input;

  DelayedPlantLink(const Model& model, const State& x0, double dt, int substeps, double tau_c,
                   double tau_m, std::size_t capacity)
      : plant_(model), x_(x0), dt_ns_(std::llround(dt * 1e9)), s_(substeps), h_(dt / substeps),
        rtt_ns_(std::llround((tau_c + tau_m) * 1e9)) {
    pending_.reserve(capacity);
    current_.x.setZero(Model::nx);
  }

  const VehicleSample& latest() override {
    while (next_ < pending_.size() && pending_[next_].received_ns <= now_ns()) current_ = pending_[next_++];
    return current_;
  }
  void send(std::int64_t k, std::int64_t stamp_ns, const double* u, int nu) override {
    if (k > 0) {  // the plant from command k−1's start to command k's
      State xn;
      for (int j = 0; j < s_; ++j) {
        plant_.substep(x_, u_, h_, xn);
        x_ = xn;
      }
    }
    std::copy_n(u, nu, u_.data());
    if (pending_.size() < pending_.capacity()) {
      VehicleSample v = current_;
      v.serial = std::uint64_t(k) + 1;
      v.x = x_;
      v.command = k;
      v.command_stamp_ns = stamp_ns;
      v.command_age_s = 0.0;
      v.received_ns = stamp_ns + rtt_ns_;
      if (mutate) mutate(k, v);
      pending_.push_back(v);
    }
    ++sent_;
  }
  void finish() override { finished_ = true; }
  double timeout_s() const override { return timeout; }
  std::int64_t now_ns() const override { return sent_ * dt_ns_ + paused_ns; }

  bool finished() const { return finished_; }

  // What the vehicle claims for command k's state (the true one in, the claim out).
  std::function<void(std::int64_t k, VehicleSample& v)> mutate;
  double timeout = 1.0;  // [s]
  std::int64_t paused_ns = 0;  // the controller's clock ran on this long without a step

 private:
  VehiclePlant<Model> plant_;
  State x_;
  Input u_ = Input::Zero();
  std::int64_t dt_ns_;
  int s_;
  double h_;
  std::int64_t rtt_ns_;
  std::vector<VehicleSample> pending_;  // reserved: one per command
  std::size_t next_ = 0;
  VehicleSample current_;
  std::int64_t sent_ = 0;
  bool finished_ = false;
};

}  // namespace mixpilot::test
