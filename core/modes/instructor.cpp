#include "core/modes/instructor.hpp"

namespace mixpilot {

const char* to_string(InstructorCommandKind kind) {
  switch (kind) {
    case InstructorCommandKind::bounds: return "bounds";
    case InstructorCommandKind::gust: return "gust";
    case InstructorCommandKind::extra_delay: return "extra delay";
    case InstructorCommandKind::input_loss: return "input loss";
    case InstructorCommandKind::marker: return "marker";
    case InstructorCommandKind::pause: return "pause";
    case InstructorCommandKind::resume: return "resume";
    case InstructorCommandKind::end: return "end";
  }
  return "?";
}

std::optional<InstructorCommandKind> instructor_command_kind(std::uint8_t value) {
  if (value >= kInstructorCommandKindCount) return std::nullopt;
  return InstructorCommandKind(value);
}

}  // namespace mixpilot
