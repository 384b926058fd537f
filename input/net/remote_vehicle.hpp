#pragma once
// The controller's side of a vehicle over DDS (SPEC §9; core/modes/vehicle_link.hpp): rotor
// commands out on rt/mixpilot/vehicle/command, states in on rt/mixpilot/vehicle/state
// (input/net/vehicle_msgs.idl).
//
// A reader thread takes the states and hands the newest sane one to the control thread through
// a triple buffer; the control thread never waits. A state reaches the controller only when it
// passes input/net/peer_checks.hpp's StateCheck: nx values, each within what the vehicle can
// physically have; a known status; an echo of a command this controller sent (step and stamp
// both match one of the last SentCommands::kRing commands, or step −1, stamp 0, age 0 before
// the first); a command age no longer than the time since that command left; a stamp in line
// with the vehicle's other states; newer than the last one taken (a later command, or the same
// one measured later). The first writer heard is the vehicle; states of another writer are
// rejected. Every rejection is counted by reason and the newest kept in words. Commands are
// written best effort on the control thread: one non-blocking send, no queue to wait on.
#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "core/modes/vehicle_link.hpp"
#include "core/base/latest.hpp"
#include "input/net/dds.hpp"
#include "input/net/peer_checks.hpp"

namespace mixpilot::net {

struct RemoteVehicleStats {
  std::uint64_t accepted = 0;
  std::uint64_t bad_value = 0;        // not finite, not a physical state, an unknown status
  std::uint64_t bad_size = 0;         // not nx state values
  std::uint64_t unknown_command = 0;  // echoes a command this controller did not send
  std::uint64_t stale = 0;            // an impossible age or stamp, not after the last taken
  std::uint64_t other_publisher = 0;  // states of a second writer
  std::uint32_t publishers = 0;       // writers heard
  std::uint64_t commands_sent = 0;
  std::string last_rejection;         // the newest rejection in words, "" when none
  std::uint64_t rejected() const {
    return bad_value + bad_size + unknown_command + stale + other_publisher;
  }
};

class RemoteVehicle final : public VehicleLink {
 public:
  static constexpr int kEchoRing = SentCommands::kRing;  // sent commands an echo is checked against
  using StateBounds = std::array<double, StateCheck::kMaxState>;
  // |x_i| ≤ 1e6 for every i: only what no vehicle state can be.
  static StateBounds any_state() {
    StateBounds b;
    b.fill(1e6);
    return b;
  }

  struct Options {
    std::uint32_t domain = 0;
    int nx = 13;              // the model's state size
    double timeout_s = 0.25;  // silent this long: the vehicle is lost
    StateBounds max_abs = any_state();  // beyond these a state value is not physical
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
  std::uint64_t rejected() const override { return rejections_.total(); }
  void describe_rejection(char* text, std::size_t size) const override;

  bool heard() const { return heard_.load(std::memory_order_acquire); }
  RemoteVehicleStats stats() const;

 private:
  void run();

  Options options_;
  Participant participant_;
  std::int32_t reader_ = 0, writer_ = 0, waitset_ = 0;
  std::thread thread_;
  std::atomic<bool> running_{false}, heard_{false}, finished_{false};
  Latest<VehicleSample> for_control_;
  SentCommands sent_;  // for the echo check

  // Reader thread.
  VehicleSample sample_;
  std::uint64_t vehicle_writer_ = 0;
  StateCheck check_;
  WritersHeard writers_;

  std::atomic<std::uint64_t> accepted_{0};
  RejectionLog rejections_;
  std::atomic<std::uint32_t> publishers_{0};
};

}  // namespace mixpilot::net
