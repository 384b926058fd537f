#pragma once
// Telemetry out over DDS (SPEC §9), for ROS 2 tools and other machines, at the control rate:
//   rt/mixpilot/pose             geometry_msgs/msg/PoseStamped  the vehicle (frame "world")
//   rt/mixpilot/lambda           std_msgs/msg/Float64           the authority λ (mixed initiative)
//   rt/mixpilot/predicted_path   nav_msgs/msg/Path              the NMPC's predicted positions
//   rt/mixpilot/reference_path   nav_msgs/msg/Path              the reference at the same nodes
// Each writer names its station in its USER_DATA ("mixpilot.station=NAME"), so an instructor
// (input/net/instructor_client.hpp) tells the stations' telemetry apart while ROS 2 tools see the
// usual topics.
// The control thread only copies each step into a ring sized once (a full ring drops the step
// and counts it); a thread of its own encodes and writes, so DDS never blocks a step.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/modes/session.hpp"
#include "core/base/spsc_ring.hpp"
#include "input/net/dds.hpp"

namespace mixpilot::net {

class TelemetryPublisher final : public TelemetrySink {
 public:
  TelemetryPublisher() = default;
  ~TelemetryPublisher() override { stop(); }
  TelemetryPublisher(const TelemetryPublisher&) = delete;
  TelemetryPublisher& operator=(const TelemetryPublisher&) = delete;

  // Joins the domain, creates the four writers (of `station`, "" for none), sizes the ring from
  // `prototype` (the mode's telemetry) and starts the writing thread.
  [[nodiscard]] bool start(std::uint32_t domain, const Telemetry& prototype, std::string& error,
                           const std::string& station = "");
  // Writes what the ring still holds, then stops.
  void stop();

  void on_sample(const Telemetry& sample) override;  // control thread: a copy, never a wait

  std::uint64_t published() const { return published_.load(); }
  std::uint64_t dropped() const { return dropped_.load(); }

 private:
  void run();
  void publish(const Telemetry& s);

  Participant participant_;
  std::int32_t pose_ = 0, lambda_ = 0, predicted_ = 0, reference_ = 0;  // writers
  std::unique_ptr<SpscRing<Telemetry>> ring_;
  Telemetry taken_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> published_{0}, dropped_{0};
  std::vector<unsigned char> path_buffer_;  // the Path's PoseStamped array, sized once
};

}  // namespace mixpilot::net
