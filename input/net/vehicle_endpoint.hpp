#pragma once
// The vehicle's side of the remote-vehicle link (SPEC §9; `mixpilot vehicle`): rotor commands
// in on rt/mixpilot/vehicle/command, states out on rt/mixpilot/vehicle/state
// (input/net/vehicle_msgs.idl). Single-threaded: the vehicle's loop waits here for commands or
// its next event, whichever comes first.
//
// A command is taken only when it passes input/net/peer_checks.hpp's CommandCheck (nu values,
// none farther outside the rotors' limits than their range; a step and stamp that advance with
// this clock from the first command taken, and a step after the last one taken, whose order a
// step ahead of the pace cannot push beyond the step due) and comes from the first controller
// heard (another writer's commands are rejected). Rejections are counted by reason, the newest
// kept in words. The closing command (end = true) is always taken from that controller.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "input/net/dds.hpp"
#include "input/net/peer_checks.hpp"

namespace mixpilot::net {

struct VehicleCommand {
  static constexpr int kMaxInputs = 8;  // the IDL's bound
  std::int64_t step = -1;
  std::int64_t stamp_ns = 0;
  bool end = false;
  std::array<double, kMaxInputs> u{};  // the first nu
};

struct VehicleEndpointStats {
  std::uint64_t accepted = 0;
  std::uint64_t bad_value = 0;        // not finite, not a rotor command
  std::uint64_t bad_size = 0;         // not nu values
  std::uint64_t stale = 0;            // ahead of the pace, or not after the last command taken
  std::uint64_t other_publisher = 0;  // commands of a second controller
  std::uint32_t publishers = 0;
  std::uint64_t states_sent = 0;
  std::string last_rejection;         // the newest rejection in words, "" when none
  std::uint64_t rejected() const { return bad_value + bad_size + stale + other_publisher; }
};

struct VehicleStateOut {
  std::int64_t stamp_ns = 0;
  std::int64_t command_step = -1;
  std::int64_t command_stamp_ns = 0;
  double command_age_s = 0.0;
  std::uint8_t status = 0;  // 0 flying, 1 left its world, 2 ended
  const double* x = nullptr;
  int nx = 0;
};

class VehicleEndpoint {
 public:
  VehicleEndpoint() = default;
  VehicleEndpoint(const VehicleEndpoint&) = delete;
  VehicleEndpoint& operator=(const VehicleEndpoint&) = delete;

  // `limits`: the vehicle's inputs, its rotors' limits and the controller's period.
  [[nodiscard]] bool open(std::uint32_t domain, const CommandCheck::Limits& limits,
                          std::string& error);
  // The same for nu inputs, any value within ±1e3, a 15 ms period.
  [[nodiscard]] bool open(std::uint32_t domain, int nu, std::string& error) {
    return open(domain, CommandCheck::Limits{nu, 0.015, -1e3, 1e3, 0.5}, error);
  }
  // Waits up to `timeout_ns` for commands; appends the sane ones to `out` (oldest first).
  void wait(std::int64_t timeout_ns, std::vector<VehicleCommand>& out);
  void publish(const VehicleStateOut& s);
  // Controllers matched on the command topic.
  std::uint32_t controllers() const;
  VehicleEndpointStats stats() const;
  // Commands rejected so far, all reasons.
  std::uint64_t rejected() const { return rejections_.total(); }

 private:
  Participant participant_;
  std::int32_t reader_ = 0, writer_ = 0, waitset_ = 0;
  int nu_ = 4;
  std::uint64_t controller_ = 0;
  CommandCheck check_;
  WritersHeard writers_;
  RejectionLog rejections_;
  VehicleEndpointStats stats_;  // accepted, publishers, states_sent
};

}  // namespace mixpilot::net
