#pragma once
// The one path from a scenario file to a mode: its `mode` key picks the class, whose own loader
// reads the rest (docs/scenario-format.md).
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "core/control/mi_settings.hpp"
#include "core/control/pilot.hpp"
#include "core/modes/mode.hpp"

namespace mixpilot {

struct ModeRequest {
  std::optional<double> duration;  // [s] overrides the scenario's duration
  // Mixed initiative only: the pilot. A source given here (a recording, a device) wins; else
  // the scenario's profile of this name; else the scenario's default pilot.
  std::unique_ptr<PilotSource> pilot_source;
  std::string pilot_name;
  // Mixed initiative only: off flies a probe (SPEC §10; core/control/mi_settings.hpp).
  Assistance assist = Assistance::on;
  // Mixed initiative only: the instructor's (a lesson's) bounds on λ from the first step on
  // (SPEC §10).
  AuthorityBounds bounds = {};
};

// The mode of a scenario's text (`source_name` for messages and relative paths), set up and
// ready to step; nullptr with the reason (file:line:col: key: ... for scenario problems).
std::unique_ptr<Mode> make_mode(std::string_view text, const std::string& source_name,
                                ModeRequest request, std::string& error);
// The same from a file.
std::unique_ptr<Mode> load_mode(const std::string& path, ModeRequest request, std::string& error);

}  // namespace mixpilot
