#pragma once
// What an instructor (SPEC §10), or a lesson step, does to a flight. A command is a value of
// fixed size: a station receives it on any thread, hands it to the control thread through a
// ring, and the control thread applies it between two steps without allocating. Applied
// commands are recorded with the step they took effect at, so a replay repeats them bit for
// bit, and each one is a debrief event.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "core/control/ph_index.hpp"  // AuthorityBounds
#include "core/modes/debrief_note.hpp"

namespace mixpilot {

enum class InstructorCommandKind : std::uint8_t {
  bounds = 0,       // authority bounds from the next step on
  gust = 1,         // an external force [N, world frame] on the vehicle for `duration` [s]
  extra_delay = 2,  // `delay` [s] added to the round trip between controller and vehicle
  input_loss = 3,   // the pilot's input is lost for `duration` [s] (SPEC §6's loss)
  marker = 4,       // a marker with `text`: a debrief event
  pause = 5,
  resume = 6,
  end = 7,
};
inline constexpr int kInstructorCommandKindCount = 8;
// "bounds", "gust", "extra delay", "input loss", "marker", "pause", "resume", "end".
const char* to_string(InstructorCommandKind kind);
std::optional<InstructorCommandKind> instructor_command_kind(std::uint8_t value);

struct InstructorCommand {
  InstructorCommandKind kind = InstructorCommandKind::marker;
  AuthorityBounds bounds;                             // bounds
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   // gust [N], world frame
  double duration = 0.0;                              // [s] gust, input loss
  double delay = 0.0;                                 // [s] extra delay (0 removes it)
  DebriefNote text;                                   // marker

  bool operator==(const InstructorCommand&) const = default;
};

// The ranges of a command's values (docs/recording-format.md, `mixpilot fly --commands`); a
// station refuses a command outside them, and a replay a recording that holds one.
inline constexpr double kMaxGustForce = 20.0;        // [N] |F|: about twice the MikroKopter's weight
inline constexpr double kMaxCommandDuration = 10.0;  // [s] a gust, an input loss: 0 < duration ≤ it
inline constexpr double kMaxExtraDelay = 0.5;        // [s] the delay lines are sized for it

// What became of a command at a station: applied, or why not.
enum class InstructorStatus : std::uint8_t {
  applied = 0,
  bad_value,       // a number not finite or out of range, an unknown kind (invalid_reason())
  no_authority,    // bounds: this mode shares no authority λ with a pilot
  no_pilot,        // input loss: this mode has no pilot
  fixed_base,      // gust: the Pendubot is an arm on a fixed shoulder, there is no body to push
  no_link,         // extra delay: the Pendubot's controller is wired to its encoders
  remote_vehicle,  // gust, extra delay: the vehicle flies in another process (fly --vehicle dds)
  busy,            // a step takes kMaxCommandsPerStep commands: the rest wait for the next one
  over,            // the flight is over
};
inline constexpr int kInstructorStatusCount = 9;
// The reason in words ("applied", "the Pendubot is an arm on a fixed shoulder: no gust", ...).
const char* to_string(InstructorStatus status);

// nullptr when the command's values are in range for its kind (the kind known, every number
// finite, 0 ≤ floor ≤ ceiling ≤ 1, |force| ≤ kMaxGustForce, 0 < duration ≤ kMaxCommandDuration,
// 0 ≤ delay ≤ kMaxExtraDelay), else what is wrong, as a static text. Allocates nothing.
const char* invalid_reason(const InstructorCommand& c);

// The command in words, as the HUD, the debrief and the recording's /rosout say it:
//   "ceiling 0.30", "floor 0.20, ceiling 0.80", "bounds lifted", "gust 2.0 N for 0.50 s",
//   "extra delay 0.100 s", "extra delay removed", "input loss for 2.0 s", "marker: <text>",
//   "pause", "resume", "end".
// NUL-terminated into out[0 .. size); returns its length. Allocates nothing.
std::size_t describe(const InstructorCommand& c, char* out, std::size_t size);
std::string describe(const InstructorCommand& c);

// A command at the step it took effect at (a recording's, a replay's).
struct StepCommand {
  std::int64_t step = 0;
  InstructorCommand command;
  bool operator==(const StepCommand&) const = default;
};

// How many commands one control step takes; more wait for the next step.
inline constexpr int kMaxCommandsPerStep = 4;

// What the instructor's commands keep in force during a step (SPEC §10), for the HUD, the
// telemetry and the replay.
struct InstructorInForce {
  AuthorityBounds bounds;                             // mixed initiative; [0, 1]: none
  Eigen::Vector3d gust = Eigen::Vector3d::Zero();    // [N] world frame, while gust_left > 0
  double gust_left = 0.0;                             // [s] of the gust after t_k
  double extra_delay = 0.0;                           // [s]
  double input_loss_left = 0.0;                       // [s] of the commanded loss after t_k
  bool any() const {
    return bounds != AuthorityBounds{} || gust_left > 0.0 || extra_delay > 0.0 ||
           input_loss_left > 0.0;
  }
  bool operator==(const InstructorInForce&) const = default;
};

}  // namespace mixpilot
