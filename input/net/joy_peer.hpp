#pragma once
// sensor_msgs/msg/Joy over DDS (SPEC §9): a peer's sticks as a pilot source, and a writer for
// joy-publish and tests. The reader maps the axes exactly as a gamepad's (SDL's order and signs:
// left x, left y down, right x, right y down, then triggers), so the input settings apply
// unchanged.
//
// A sample reaches the controller only when it is sane (input/net/peer_checks.hpp): 4 to
// JoyInput::kMaxAxes axes, each finite and in [-1, 1]; at most JoyInput::kMaxButtons buttons,
// each 0 or 1; a stamp no older than `max_age_s`, no more than `clock_tolerance_s` ahead of this
// machine's clock, and not older than the last one taken (whose stamp counts as no later than
// its arrival, so one sample from the future cannot make later ones stale). Others are
// rejected and counted by reason, the newest kept in words. The first writer heard is the
// pilot; samples of another writer are rejected and counted (the trainer reports a second
// publisher instead of mixing two), until the pilot's writer has been silent for `handover_s`.
// A silent peer, or one whose samples are all rejected, is an input loss (DevicePilot's
// timeout).
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "core/base/latest.hpp"
#include "input/net/dds.hpp"
#include "input/net/peer_checks.hpp"
#include "input/source.hpp"

namespace mixpilot::net {

struct JoyPeerStats {
  std::uint64_t accepted = 0;
  std::uint64_t bad_value = 0;         // a non-finite axis, or one outside [-1, 1]
  std::uint64_t bad_size = 0;          // too few or too many axes, too many buttons
  std::uint64_t stale = 0;             // a stamp too old, in the future, or going back
  std::uint64_t other_publisher = 0;   // samples of a second writer
  std::uint32_t publishers = 0;        // writers heard
  std::string last_rejection;          // the newest rejection in words, "" when none
  std::uint64_t rejected() const { return bad_value + bad_size + stale + other_publisher; }
  // Publisher stamp → the control step's read of the sample, over the samples the controller
  // used [ms]; 0 when none.
  double latency_p50_ms = 0, latency_p99_ms = 0;
  std::uint64_t latency_samples = 0;
};

class JoyPeer final : public input::StickSource {
 public:
  struct Options {
    std::uint32_t domain = 0;
    std::string topic = "rt/joy";
    double max_age_s = 0.5;
    double clock_tolerance_s = 0.05;  // a stamp ahead of this machine's clock by more is stale
    double handover_s = 1.0;
  };

  JoyPeer() = default;
  ~JoyPeer() override { stop(); }
  JoyPeer(const JoyPeer&) = delete;
  JoyPeer& operator=(const JoyPeer&) = delete;

  // Joins the domain, subscribes and starts the reader thread.
  [[nodiscard]] bool start(const Options& options, std::string& error);
  void stop();

  std::string name() const override { return "dds"; }
  const input::StickReading& latest() override;
  // Whether a sane sample has arrived yet.
  bool heard() const { return heard_.load(std::memory_order_relaxed); }
  JoyPeerStats stats() const;
  const Options& options() const { return options_; }

 private:
  void run();

  Options options_;
  Participant participant_;
  std::int32_t reader_ = 0, waitset_ = 0;
  std::thread thread_;
  std::atomic<bool> running_{false}, heard_{false};
  Latest<input::StickReading> for_control_;

  // Reader thread.
  input::StickReading reading_;
  std::uint64_t pilot_writer_ = 0;
  std::int64_t last_taken_ns_ = 0;
  JoyCheck check_;
  WritersHeard writers_;

  std::atomic<std::uint64_t> accepted_{0};
  RejectionLog rejections_;
  std::atomic<std::uint32_t> publishers_{0};

  // Control thread: the latency histogram (0.1 ms bins up to 100 ms, sized once).
  std::uint64_t used_serial_ = 0;
  std::vector<std::uint32_t> latency_bins_ = std::vector<std::uint32_t>(1001, 0);
  std::atomic<std::uint64_t> latency_count_{0};
};

// A Joy writer (joy-publish, tests). write() takes any sizes and values, so tests can send
// malformed samples.
class JoyWriter {
 public:
  [[nodiscard]] bool open(std::uint32_t domain, const std::string& topic, std::string& error);
  // Readers currently matched.
  std::uint32_t matched() const;
  [[nodiscard]] bool write(const std::vector<float>& axes, const std::vector<std::int32_t>& buttons,
                           std::int64_t stamp_ns, const std::string& frame_id, std::string& error);

 private:
  Participant participant_;
  std::int32_t writer_ = 0;
};

}  // namespace mixpilot::net
