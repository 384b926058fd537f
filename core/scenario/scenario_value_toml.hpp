#pragma once
// ScenarioValue read from a toml++ node (a sweep file's values, a key's value as text), and the
// number text they share: inside core/scenario only.
#include <string>

#include "core/base/toml_read.hpp"
#include "core/scenario/scenario_keys.hpp"

namespace mixpilot {

// `n` as a ScenarioValue; false with what was expected (a date or a table is no value here).
bool scenario_value_of(const toml::node& n, ScenarioValue& out, std::string& why);

// Shortest text that reads back as `v`: 0.012, 30, 1e-13, inf, -inf, nan.
std::string shortest(double v);

}  // namespace mixpilot
