#pragma once
// Reports: a mode's metrics as a JSON object (`mixpilot fly --report`, `mixpilot score --json`).
#include <string>
#include <utility>
#include <vector>

#include "core/modes/mode.hpp"

namespace mixpilot {

using Labels = std::vector<std::pair<std::string, std::string>>;

// {"label": "value", ..., "metric": number, ...}: string labels first, then the metrics with 17
// significant digits (an exact round trip), whole numbers without a fraction, and null for a
// value that is not finite (JSON has no inf or nan).
std::string to_json(const Labels& labels, const Metrics& metrics, int indent = 2);

// `metrics` of `mode` with `lost` (0/1) and `lost_at_s` (−1 when not lost) appended where the
// mode does not report them itself: every report carries them.
Metrics with_lost_fields(Metrics metrics, const Mode& mode);

}  // namespace mixpilot
