#pragma once
// Cyclone DDS for mixpilot's network peers (SPEC §9): a participant in a domain, and the check
// that the configuration in force keeps traffic on this machine. Cyclone reads its
// configuration from CYCLONEDDS_URI; without one it discovers peers by multicast on every
// interface, which tests, demos and CI must never do (assets/dds-loopback.xml).
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace mixpilot::net {

// Whether CYCLONEDDS_URI names a configuration that keeps DDS on loopback: interface `lo`,
// multicast off, the peer 127.0.0.1. `why` says what is missing otherwise.
[[nodiscard]] bool loopback_only(std::string& why);

// The project's loopback configuration, as a CYCLONEDDS_URI value.
std::string loopback_config_uri();

// Nothing leaves this machine unless the user configures DDS: without CYCLONEDDS_URI, sets it
// to the loopback configuration (before the first participant is created).
void use_loopback_unless_configured();

// A domain participant; deleting it deletes every reader, writer and topic it made.
class Participant {
 public:
  Participant() = default;
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  [[nodiscard]] bool open(std::uint32_t domain, std::string& error);
  void close();
  std::int32_t handle() const { return handle_; }  // dds_entity_t
  std::uint32_t domain() const { return domain_; }

 private:
  std::int32_t handle_ = 0;
  std::uint32_t domain_ = 0;
};

// The writers heard on a topic (their publication handles), each counted once: how a reader
// tells a second publisher from its own.
class WritersHeard {
 public:
  // Notes `writer`; returns how many distinct writers have been heard.
  std::uint32_t note(std::uint64_t writer) {
    if (std::find(writers_.begin(), writers_.end(), writer) == writers_.end())
      writers_.push_back(writer);
    return std::uint32_t(writers_.size());
  }

 private:
  std::vector<std::uint64_t> writers_;
};

// "rt/joy" from "joy", "/joy" or "rt/joy" (ROS 2's topic prefix rule).
std::string dds_topic(const std::string& ros_name);

// A DDS return code's text.
std::string dds_error(std::int32_t rc);

// System-clock nanoseconds (ROS time: the stamps of ROS 2 headers).
std::int64_t system_ns();

}  // namespace mixpilot::net
