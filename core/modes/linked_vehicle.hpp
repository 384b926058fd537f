#pragma once
// The vehicle behind a VehicleLink (core/modes/vehicle_link.hpp), as every quadrotor mode flies
// it (SPEC §9): the link, the feed that judges it (core/modes/vehicle_feed.hpp), the round-trip
// estimate and the state predictor of SPEC §5.2 (core/control/delay_predictor.hpp). Each step
// reads the newest state and judges it, the mode predicts it over the estimated round-trip
// time plus the time it waited here, and the step's command goes out at once: the link is the
// delay line, nothing is simulated. (input/net/remote_vehicle.hpp is one such link, over DDS.)
//
// The step's stamp is taken once, by read(); send() stamps the command with it.
// setup() sizes; the rest allocates nothing.
#include <cstddef>
#include <cstdint>

#include "core/control/delay_predictor.hpp"
#include "core/control/rtt_estimator.hpp"
#include "core/modes/vehicle_feed.hpp"
#include "core/modes/vehicle_link.hpp"

namespace mixpilot {

template <class Model>
class LinkedVehicle {
 public:
  using State = typename Model::State;
  using Input = typename Model::Input;

  enum class Status {
    flying,
    left_world,  // its newest state is outside its world, not finite, or it says it left
    lost,        // the feed gave up on it (VehicleFeed::lost_reason())
  };

  // What step k learns of the vehicle.
  struct Reading {
    Status status = Status::flying;
    const char* reason = "";    // why it is not flying (a literal or the feed's; "" flying)
    bool heard = false;         // a state has arrived: the newest was read
    bool fresh = false;         // it is new since the last step and echoes a command
    double sigma = 0.0;         // fresh: when it was measured, on the controller's clock [s]
    int horizon_substeps = 0;   // predict() over this
  };

  // dt: control period; substeps per period of h = dt / substeps; max_substeps: the longest
  // prediction (VehicleFeed::kMaxRtt at least); samples: round-trip samples kept for the median.
  // The vehicle leaves `world` (or says it did, or its state is not finite) for `left_reason`
  // unless the world names how.
  void setup(const Model& model, double dt, int substeps, int max_substeps, std::size_t samples,
             const VehicleWorld& world, const char* left_reason) {
    const double h = dt / substeps;
    predictor_.setup(model, substeps, h, 0, max_substeps);
    feed_.setup(Model::nx, dt, h, max_substeps, samples);
    substeps_ = substeps;
    world_ = world;
    left_reason_ = left_reason;
    link_ = nullptr;
    now_ns_ = 0;
  }
  // Flies the vehicle behind `link` (nullptr: none). The link outlives the flight.
  void attach(VehicleLink* link) { link_ = link; }
  bool attached() const { return link_ != nullptr; }

  // Step k: stamps it, takes the newest state into y (left as it is before any arrives) and
  // judges it: outside the world first, then the feed's verdict.
  [[nodiscard]] Reading read(std::int64_t k, State& y) {
    now_ns_ = link_->now_ns();
    const VehicleFeed::Reading f = feed_.read(*link_, k, now_ns_, substeps_);
    Reading r;
    r.heard = f.heard;
    r.fresh = f.fresh;
    r.sigma = f.sigma;
    r.horizon_substeps = f.horizon_substeps;
    if (f.heard) {
      const VehicleSample& v = *f.sample;
      for (int i = 0; i < Model::nx; ++i) y(i) = v.x(i);
      const char* outside = world_.outside(y.template head<3>());
      if (outside || v.left_world || !y.allFinite()) {
        r.status = Status::left_world;
        r.reason = outside ? outside : left_reason_;
        return r;
      }
    }
    if (f.lost) {
      r.status = Status::lost;
      r.reason = feed_.lost_reason();
    }
    return r;
  }
  // What is known of the vehicle at t_k: y predicted over the reading's horizon with the
  // commands sent (SPEC §5.2).
  void predict(const State& y, State& predicted, const Reading& r) const {
    predictor_.predict(y, predicted, r.horizon_substeps);
  }
  // Command k leaves now (the step's stamp), and the predictor keeps it.
  void send(std::int64_t k, const Input& u) {
    predictor_.record_sent(u);
    feed_.send(*link_, k, now_ns_, u.data(), Model::nu);
  }
  // The flight is over (lost, or its last step sent).
  void finish() { link_->finish(); }

  const VehicleFeed& feed() const { return feed_; }
  const RttEstimator& rtt() const { return feed_.rtt(); }

 private:
  VehicleLink* link_ = nullptr;
  VehicleFeed feed_;
  DelayPredictor<Model> predictor_;
  VehicleWorld world_;
  const char* left_reason_ = "";
  int substeps_ = 1;
  std::int64_t now_ns_ = 0;  // the step's stamp (VehicleLink::now_ns())
};

}  // namespace mixpilot
