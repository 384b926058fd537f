#pragma once
// A shipped scenario flown to its end the way `mixpilot fly --headless` flies it: through
// make_mode(), one step() at a time.
#include <optional>
#include <string>

#include "core/modes/make_mode.hpp"
#include "core/modes/mode.hpp"

namespace mixpilot {

struct Flown {
  bool ok = false;
  std::string error;
  std::string summary;
  Metrics metrics;
};

inline Flown fly_scenario(const std::string& path, std::optional<double> duration = {}) {
  Flown f;
  ModeRequest request;
  request.duration = duration;
  auto mode = load_mode(path, std::move(request), f.error);
  if (!mode) return f;
  while (mode->step()) {
  }
  f.ok = true;
  f.summary = mode->summary();
  f.metrics = mode->metrics();
  return f;
}

}  // namespace mixpilot
