#pragma once
// The thesis's other controllers as headless modes (SPEC §5.1–§5.3, issue 6). The mixed-
// initiative mode (core/session.hpp) flies with a pilot; these fly a scenario on their own and
// report mode-appropriate metrics. `mixpilot fly --scenario FILE --headless` dispatches on the
// file's top-level `mode` key.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace mixpilot {

struct ModeOptions {
  std::optional<double> duration;  // [s] overrides the scenario's duration
};

struct ModeResult {
  bool ok = false;
  std::string error;    // why the run could not happen (file:line: key: ... for scenarios)
  std::string summary;  // a few human-readable lines for the terminal
  // Metrics in report order: name → value (written as a JSON object by `fly --report`).
  std::vector<std::pair<std::string, double>> metrics;
};

using ModeRunner = ModeResult (*)(const std::string& scenario_path, const ModeOptions& options);

// The runner of a mode, or nullptr for "mixed_initiative" and unknown modes.
ModeRunner find_mode_runner(const std::string& mode);
// Every mode name with a runner, for messages.
std::vector<std::string> mode_runner_names();

}  // namespace mixpilot
