#include "core/modes/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/base/json.hpp"

namespace mixpilot {

std::string to_json(const Labels& labels, const Metrics& metrics, int indent) {
  const std::string pad(std::size_t(std::max(indent, 0)), ' ');
  std::string out = "{";
  const char* sep = "\n";
  for (const auto& [key, value] : labels) {
    out += sep + pad + json_quote(key) + ": " + json_quote(value);
    sep = ",\n";
  }
  char buf[64];
  for (const auto& [key, value] : metrics) {
    // JSON has no inf or nan: a value that is not finite (e.g. no obstacle to be near) is null.
    if (std::isfinite(value)) {
      std::snprintf(buf, sizeof buf, "%.17g", value);
    } else {
      std::snprintf(buf, sizeof buf, "null");
    }
    out += sep + pad + json_quote(key) + ": " + buf;
    sep = ",\n";
  }
  out += "\n}";
  return out;
}

Metrics with_lost_fields(Metrics metrics, const Mode& mode) {
  const auto has = [&](const char* name) {
    return std::any_of(metrics.begin(), metrics.end(),
                       [&](const auto& m) { return m.first == name; });
  };
  if (!has("lost")) metrics.emplace_back("lost", mode.lost() ? 1.0 : 0.0);
  if (!has("lost_at_s")) metrics.emplace_back("lost_at_s", mode.lost_at());
  return metrics;
}

}  // namespace mixpilot
