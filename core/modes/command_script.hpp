#pragma once
// A script of instructor's commands at flight times (`mixpilot fly --commands FILE.toml`), for
// researchers and tests: the same commands an instructor sends (SPEC §10,
// core/modes/instructor.hpp), applied through the flight's command inbox at the first control
// step at or after their time (core/modes/command_inbox.hpp). One [[command]] table each:
//
//   [[command]]
//   at = 2.0                  # [s] flight time, 0 .. 3600
//   kind = "gust"             # bounds, gust, extra_delay, input_loss, marker, end
//   force = [2.0, 0.0, 0.0]   # gust: [N], world frame (x north, y west, z up), |force| <= 20
//   duration = 0.5            # gust, input_loss: [s], (0, 10]
//
//   floor = 0.0, ceiling = 0.3   # bounds (either may be left out: 0 and 1)
//   delay = 0.1                  # extra_delay: [s], [0, 0.5]; 0 removes it
//   text = "watch the column"    # marker: 1 to 95 bytes
//
// pause and resume are live commands only: a script's times are flight times, which stand still
// while a flight is paused. Errors name file:line:col, the key and what was expected.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/modes/command_inbox.hpp"

namespace mixpilot {

// How many commands a script may hold.
inline constexpr std::size_t kMaxScriptCommands = 10000;

std::optional<std::vector<ScriptedCommand>> parse_command_script(std::string_view text,
                                                                 const std::string& source,
                                                                 std::string& error);
std::optional<std::vector<ScriptedCommand>> load_command_script(const std::string& path,
                                                                std::string& error);

}  // namespace mixpilot
