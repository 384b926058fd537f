#pragma once
// What an instructor (SPEC §10), or a lesson step, does to a flight. A command is a value of
// fixed size: a station receives it on any thread, hands it to the control thread through a
// ring, and the control thread applies it between two steps without allocating. Applied
// commands are recorded with the step they took effect at, so a replay repeats them bit for
// bit, and each one is a debrief event.
#include <cstdint>
#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "core/control/ph_index.hpp"  // AuthorityBounds
#include "core/modes/debrief.hpp"

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

}  // namespace mixpilot
