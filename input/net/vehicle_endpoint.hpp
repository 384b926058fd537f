#pragma once
// The vehicle's side of the remote-vehicle link (SPEC §9; `mixpilot vehicle`): rotor commands
// in on rt/mixpilot/vehicle/command, states out on rt/mixpilot/vehicle/state
// (input/net/vehicle_msgs.idl). Single-threaded: the vehicle's loop waits here for commands or
// its next event, whichever comes first.
//
// A command is taken only when it has nu finite values, a step after the last one taken, and
// comes from the first controller heard (another writer's commands are rejected and counted).
// The closing command (end = true) is always taken from that controller.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "input/net/dds.hpp"

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
  std::uint64_t bad_value = 0;        // a non-finite value
  std::uint64_t bad_size = 0;         // not nu values
  std::uint64_t stale = 0;            // not after the last command taken
  std::uint64_t other_publisher = 0;  // commands of a second controller
  std::uint32_t publishers = 0;
  std::uint64_t states_sent = 0;
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

  [[nodiscard]] bool open(std::uint32_t domain, int nu, std::string& error);
  // Waits up to `timeout_ns` for commands; appends the sane ones to `out` (oldest first).
  void wait(std::int64_t timeout_ns, std::vector<VehicleCommand>& out);
  void publish(const VehicleStateOut& s);
  // Controllers matched on the command topic.
  std::uint32_t controllers() const;
  VehicleEndpointStats stats() const { return stats_; }

 private:
  Participant participant_;
  std::int32_t reader_ = 0, writer_ = 0, waitset_ = 0;
  int nu_ = 4;
  std::uint64_t controller_ = 0;
  std::int64_t last_step_ = -1;
  WritersHeard writers_;
  VehicleEndpointStats stats_;
};

}  // namespace mixpilot::net
