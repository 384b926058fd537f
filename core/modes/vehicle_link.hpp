#pragma once
// The controller's side of a vehicle that runs elsewhere (SPEC §9: another process, another
// machine, a real quadrotor): commands go out stamped, states come back echoing the newest
// command in effect when they were measured (core/control/rtt_estimator.hpp). A mode with a
// link sends its commands through it and starts each step from the newest state, predicted
// over the estimated round-trip time; its own plant does not run. The network variant is
// input/net/remote_vehicle.hpp; core never sees how the bytes travel.
//
// Its calls are made on the control thread, never wait and allocate nothing.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

namespace mixpilot {

// The controller's steady clock [ns] (the stamps of VehicleLink).
inline std::int64_t vehicle_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct VehicleSample {
  static constexpr int kMaxState = 16;
  using StateVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxState, 1>;

  std::uint64_t serial = 0;     // 0: nothing received yet; grows with each new sample
  StateVector x;                // nx: the vehicle's state when measured
  std::int64_t command = -1;    // the newest command in effect then (its step k), −1: none yet
  std::int64_t command_stamp_ns = 0;  // that command's send stamp, echoed (controller's clock)
  double command_age_s = 0.0;   // how long that command had acted when the state was measured
  std::int64_t received_ns = 0; // when the sample arrived (VehicleLink::now_ns())
  bool left_world = false;      // the vehicle says it left its world (its state is the last inside)
  bool ended = false;           // the vehicle says its flight is over
};

// What a mode's remote vehicle sends (SPEC §9): nx state values, each within max_abs (beyond
// it a value is not physical and the link rejects the state). nx = 0: the mode flies none.
struct VehicleStateSpec {
  int nx = 0;
  std::array<double, VehicleSample::kMaxState> max_abs{};
};

class VehicleLink {
 public:
  virtual ~VehicleLink() = default;
  // The newest sane state (serial 0 before the first).
  virtual const VehicleSample& latest() = 0;
  // Command k leaves now, stamped `stamp_ns` (now_ns()), u of size nu.
  virtual void send(std::int64_t k, std::int64_t stamp_ns, const double* u, int nu) = 0;
  // The flight is over: the vehicle may stop.
  virtual void finish() = 0;
  // How long the vehicle may stay silent before it counts as lost [s].
  virtual double timeout_s() const = 0;
  // States that arrived and were rejected so far (they never reach latest()), and the newest
  // rejection in words into `text` (at most `size` bytes, "" when none): what a lost vehicle's
  // reason quotes when its states arrived but none was taken.
  virtual std::uint64_t rejected() const { return 0; }
  virtual void describe_rejection(char* text, std::size_t size) const {
    if (size > 0) text[0] = '\0';
  }
  // The controller's clock, on which commands are stamped and states received [ns]: the steady
  // clock (a simulated one in tests).
  virtual std::int64_t now_ns() const { return vehicle_clock_ns(); }
};

}  // namespace mixpilot
