#pragma once
// The controller's side of a vehicle over DDS (SPEC §9; core/modes/vehicle_link.hpp): rotor
// commands out on rt/mixpilot/vehicle/command, states in on rt/mixpilot/vehicle/state
// (input/net/vehicle_msgs.idl).
//
// A reader thread takes the states and hands the newest sane one to the control thread through
// a triple buffer; the control thread never waits. A state reaches the controller only when it
// has nx finite values, a finite command age in [0, 10] s, echoes a command this controller sent
// (step and stamp both match one of the last kEchoRing commands, or −1 before the first), and is
// newer than the last one taken (measured later on the vehicle's clock, and no earlier command
// in effect). The first
// writer heard is the vehicle; states of another writer are rejected and counted. Commands are
// written best effort on the control thread: one non-blocking send, no queue to wait on.
#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "core/modes/vehicle_link.hpp"
#include "input/latest.hpp"
#include "input/net/dds.hpp"

namespace mixpilot::net {

struct RemoteVehicleStats {
  std::uint64_t accepted = 0;
  std::uint64_t bad_value = 0;        // a non-finite state value, a command age outside [0, 10] s
  std::uint64_t bad_size = 0;         // not nx state values
  std::uint64_t unknown_command = 0;  // echoes a command this controller did not send
  std::uint64_t stale = 0;            // not measured after the last state taken
  std::uint64_t other_publisher = 0;  // states of a second writer
  std::uint32_t publishers = 0;       // writers heard
  std::uint64_t commands_sent = 0;
};

class RemoteVehicle final : public VehicleLink {
 public:
  static constexpr int kEchoRing = 128;  // sent commands an echo is checked against

  struct Options {
    std::uint32_t domain = 0;
    int nx = 13;              // the model's state size
    double timeout_s = 0.25;  // silent this long: the vehicle is lost
  };

  RemoteVehicle() = default;
  ~RemoteVehicle() override { stop(); }
  RemoteVehicle(const RemoteVehicle&) = delete;
  RemoteVehicle& operator=(const RemoteVehicle&) = delete;

  [[nodiscard]] bool start(const Options& options, std::string& error);
  void stop();
  // Waits up to `seconds` for the vehicle's first state (before the flight, not in it).
  [[nodiscard]] bool wait_for_vehicle(double seconds) const;

  const VehicleSample& latest() override { return for_control_.read(); }
  void send(std::int64_t k, std::int64_t stamp_ns, const double* u, int nu) override;
  void finish() override;
  double timeout_s() const override { return options_.timeout_s; }

  bool heard() const { return heard_.load(std::memory_order_acquire); }
  RemoteVehicleStats stats() const;

 private:
  void run();
  bool echo_known(std::int64_t step, std::int64_t stamp) const;

  Options options_;
  Participant participant_;
  std::int32_t reader_ = 0, writer_ = 0, waitset_ = 0;
  std::thread thread_;
  std::atomic<bool> running_{false}, heard_{false}, finished_{false};
  input::Latest<VehicleSample> for_control_;
  // Sent commands, for the echo check: stamp of step k at k mod kEchoRing, written before sent_.
  std::array<std::atomic<std::int64_t>, kEchoRing> sent_stamps_{};
  std::atomic<std::int64_t> sent_{0};

  // Reader thread.
  VehicleSample sample_;
  std::uint64_t vehicle_writer_ = 0;
  std::int64_t last_stamp_ns_ = 0;  // the vehicle's clock at the last state taken
  WritersHeard writers_;

  std::atomic<std::uint64_t> accepted_{0}, bad_value_{0}, bad_size_{0}, unknown_{0}, stale_{0},
      other_{0};
  std::atomic<std::uint32_t> publishers_{0};
};

}  // namespace mixpilot::net
