#pragma once
// Scenario files (TOML, docs/scenario-format.md) → Scenario (core/scenario/scenario.hpp).
// TOML: human-edited, comments allowed, no indentation rules, and every value carries its
// line/column, so errors can point at the offending key.
//
// On failure both functions return nullopt and set `error` to one line per problem, sorted by
// position, each of the form `<file>:<line>:<col>: <key path>: <what was expected>`, e.g.
//   scenarios/x.toml:12:9: controller.ph.r: expected a positive number, got -0.1
// Unknown keys are errors (a typo must not silently fall back to a default). No exceptions
// escape.
#include <optional>
#include <string>
#include <string_view>

#include "core/scenario/scenario.hpp"

namespace mixpilot {

// Reads and validates the file at `path`; source_path = path, source_text = its contents.
std::optional<Scenario> load_scenario(const std::string& path, std::string& error);

// The same from text; `source_name` names it in messages and becomes source_path.
std::optional<Scenario> parse_scenario(std::string_view text, const std::string& source_name,
                                       std::string& error);

// Scenario and trajectory files are small; a larger input is refused before it is read.
inline constexpr long long kMaxTextFileBytes = 16ll << 20;

// The whole text of a regular file of at most kMaxTextFileBytes; false with
// "<path>: cannot open file (<system's reason>)", "<path>: expected a regular file, ..." or
// "<path>: N bytes, more than ..." otherwise.
bool read_text_file(const std::string& path, std::string& text, std::string& error);

// The top-level `mode` of a scenario (any mode), so callers can dispatch to its loader; an
// unknown one is an error at its line and column.
std::optional<std::string> scenario_mode(std::string_view text, const std::string& source_name,
                                         std::string& error);

// Where the helix reference first comes closer to the arena's walls, floor or ceiling than
// margin = controller.ph.r + controller.vehicle_radius: a pilot anywhere in the ball B around
// the reference would touch them there. The loader refuses such a file; a session length
// given apart (fly --duration) is checked with this too.
struct ReferenceBreach {
  double t = 0.0;           // [s] first time
  Eigen::Vector3d at;       // the reference there [m]
  const char* face = "";    // "walls", "floor" or "ceiling"
  double margin = 0.0;      // [m] the clearance needed
};
[[nodiscard]] std::optional<ReferenceBreach> reference_too_close_to_walls(const Scenario& sc,
                                                                         double duration);

}  // namespace mixpilot
