#include "core/modes/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mixpilot {

namespace {

std::string json_escape(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out;
}

}  // namespace

std::string to_json(const Labels& labels, const Metrics& metrics, int indent) {
  const std::string pad(std::size_t(std::max(indent, 0)), ' ');
  std::string out = "{";
  const char* sep = "\n";
  for (const auto& [key, value] : labels) {
    out += sep + pad + "\"" + json_escape(key) + "\": \"" + json_escape(value) + "\"";
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
    out += sep + pad + "\"" + json_escape(key) + "\": " + buf;
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
