#pragma once
// What a receiver checks in every sample a DDS peer sends before anything of it reaches the
// controller or the plant (SPEC §9, docs/network.md): Joy at the trainer, vehicle states at the
// controller, rotor commands at the vehicle. No DDS here: the readers hand the fields over with
// the time the sample arrived on the receiver's clock, so tests check with any clock.
//
// Every field is checked against what the receiver knows:
//  - sizes as the message's type and the model say (bad size); every number finite and within
//    what the sender can physically mean (bad value);
//  - times against the receiver's clock: nothing from the future beyond a small clock
//    tolerance, no age longer than the time elapsed, steps no further than the time allows,
//    echoes only of what was sent (stale, unknown command);
//  - order ("after the last one taken") against the last sample taken with its time clamped to
//    what the receiver's clock allows, so one sample from the future cannot make the honest
//    samples after it look old.
// A rejection is counted by reason and the newest one kept in words (a printf format of at most
// three numbers, always %g-like, so no message grows with the value it quotes).
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "input/net/note_log.hpp"

namespace mixpilot::net {

enum class Rejection : std::uint8_t {
  none,
  bad_value,        // not finite, or not a value the sender can mean
  bad_size,         // a sequence of the wrong length
  unknown_command,  // echoes a command this controller did not send
  stale,            // its time is impossible (future, longer than elapsed) or not after the last
  other_publisher,  // a second writer
};
inline constexpr int kRejectionKinds = 6;
const char* to_string(Rejection r);

// Why one sample was rejected: `format` is a string literal taking a, b and c (doubles) in
// that order.
struct RejectionNote {
  Rejection why = Rejection::none;
  const char* format = "";
  double a = 0, b = 0, c = 0;
};

// "<reason>: <what>" into `out` (at most `size` bytes, always terminated). Allocates nothing.
void describe(const RejectionNote& note, char* out, std::size_t size);

// The rejections of one reader (input/net/note_log.hpp).
using RejectionLog = NoteLog<RejectionNote, kRejectionKinds>;

// --- sensor_msgs/Joy at the trainer --------------------------------------------------------

struct JoyFields {
  std::int32_t sec = 0;  // header.stamp, the publisher's system clock
  std::uint32_t nanosec = 0;
  std::uint32_t frame_id_length = 0;
  std::uint32_t num_axes = 0;
  const float* axes = nullptr;
  std::uint32_t num_buttons = 0;
  const std::int32_t* buttons = nullptr;
};

class JoyCheck {
 public:
  static constexpr std::uint32_t kMaxFrameId = 256;  // characters; ROS 2's joy_node sends "joy"
  struct Limits {
    double max_age_s = 0.5;           // older than this: stale
    double clock_tolerance_s = 0.05;  // ahead of this machine's clock by more: stale
  };
  void setup(const Limits& limits) {
    limits_ = limits;
    forget_order();
  }
  // Another writer takes over: its stamps start a new order.
  void forget_order() { last_ns_ = kNone; }
  // Checks a sample arrived at `now` (this machine's system clock [ns]); when it passes
  // (Rejection::none) it is taken: later samples must not be older. `stamp` is its stamp [ns].
  [[nodiscard]] Rejection check(const JoyFields& m, std::int64_t now, std::int64_t& stamp,
                                RejectionNote& note);

 private:
  static constexpr std::int64_t kNone = INT64_MIN;
  Limits limits_;
  std::int64_t last_ns_ = kNone;  // the last taken's stamp, never later than when it arrived
};

// --- Vehicle states at the controller --------------------------------------------------------

// The commands this controller sent, for the echo check: written by the control thread, read
// by the link's reader thread.
class SentCommands {
 public:
  static constexpr int kRing = 128;  // the newest commands an echo is checked against
  void reset() { sent_.store(0, std::memory_order_release); }
  // Command k left stamped `stamp_ns` (k = 0, 1, 2, ...).
  void note(std::int64_t k, std::int64_t stamp_ns) {
    stamps_[std::size_t(k % kRing)].store(stamp_ns, std::memory_order_relaxed);
    sent_.store(k + 1, std::memory_order_release);
  }
  std::int64_t sent() const { return sent_.load(std::memory_order_acquire); }
  // Whether step `step` was sent stamped `stamp_ns` (and is among the newest kRing).
  bool sent_as(std::int64_t step, std::int64_t stamp_ns) const;

 private:
  std::array<std::atomic<std::int64_t>, kRing> stamps_{};
  std::atomic<std::int64_t> sent_{0};
};

struct StateFields {
  std::int64_t stamp_ns = 0;  // the vehicle's clock
  std::int64_t command_step = -1;
  std::int64_t command_stamp_ns = 0;  // the controller's clock, echoed
  double command_age_s = 0;
  std::uint8_t status = 0;  // 0 flying, 1 left its world, 2 ended
  std::uint32_t nx = 0;
  const double* x = nullptr;
};

class StateCheck {
 public:
  static constexpr int kMaxState = 32;  // the IDL's bound
  // The vehicle's stamps against the controller's clock: the offset stamp − (T_j + a) is the
  // vehicle's clock offset plus the command's one-way delay; its median over this many samples
  // is what a new stamp is checked against, so no single sample moves it.
  static constexpr int kOffsetWindow = 15;
  struct Limits {
    int nx = 13;
    std::array<double, kMaxState> max_abs{};  // |x_i| beyond this is not a state [x's units]
    double max_delay_s = 0.5;       // the longest one-way delay a stamp may show
    double clock_tolerance_s = 1e-3;  // an age may exceed the elapsed time by this (clock rates)
  };
  void setup(const Limits& limits);
  // Checks a state arrived at `received_ns` (the controller's clock), given the commands sent;
  // when it passes it is taken (later states must be newer).
  [[nodiscard]] Rejection check(const StateFields& m, std::int64_t received_ns,
                                const SentCommands& sent, RejectionNote& note);

 private:
  Limits limits_;
  bool taken_ = false;
  std::int64_t last_step_ = -1;  // the last taken's command
  double last_age_s_ = 0;        // and its age
  std::array<double, kOffsetWindow> offsets_{};  // [ns]
  int offset_count_ = 0, offset_next_ = 0;
};

// --- Rotor commands at the vehicle -----------------------------------------------------------

struct CommandFields {
  std::int64_t step = 0;
  std::int64_t stamp_ns = 0;  // the controller's clock
  std::uint32_t nu = 0;
  const double* u = nullptr;
};

class CommandCheck {
 public:
  struct Limits {
    int nu = 4;
    double dt = 0.015;            // the controller's period [s]
    double u_min = 0, u_max = 0;  // where the rotors saturate
    double max_delay_s = 0.5;     // the longest one-way delay, and the controller's lateness
  };
  void setup(const Limits& limits);
  // Checks a command arrived at `now` (the vehicle's clock [ns]); when it passes it is taken.
  // Rotor values beyond the saturation limits but within one range of them are taken (the
  // rotors saturate); farther out they are not a rotor command.
  [[nodiscard]] Rejection check(const CommandFields& m, std::int64_t now, RejectionNote& note);
  // The steps a controller may start with (its first commands may be lost on the way).
  std::int64_t max_first_step() const;

 private:
  Limits limits_;
  bool taken_ = false;
  std::int64_t first_step_ = 0, first_stamp_ = 0, first_arrival_ = 0;
  std::int64_t last_step_ = -1;  // the last taken
  double last_due_ = -1.0;       // the step later ones must pass: the last taken, never beyond
                                 // the step due when it arrived
};

}  // namespace mixpilot::net
