// libFuzzer target: any text as a scenario file. scenario_mode, every mode's parser in
// core/scenario and make_mode (text → a mode, set up and ready to step) must return a value or
// an error message; never crash, abort, hang or allocate without bound
// (tests/fuzz/run.sh runs it under ASan + UBSan with a time and memory limit per input).
//
// The source name puts the text in the shipped scenarios' folder, so the seeds' relative
// reference files (scenarios/references/) resolve as they do for the real files.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/modes/make_mode.hpp"
#include "core/scenario/obstacle_scenario.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/tracking_scenario.hpp"

namespace {

const std::string kSource = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/fuzz.toml";

void require(bool ok) {
  if (!ok) std::abort();
}

// Every failure says why (the scenario's file:line:col, or a reference file's name).
void require_message(const std::string& error) { require(!error.empty()); }

// make_mode sets the mode up: sizes follow from the scenario's values (horizon, steps, sample
// counts), which is where unchecked values turn into huge allocations or long loops. Off with
// MIXPILOT_FUZZ_PARSE_ONLY=1 to fuzz the parsers alone (faster).
bool with_setup() {
  static const bool on = [] {
    const char* v = std::getenv("MIXPILOT_FUZZ_PARSE_ONLY");
    return v == nullptr || std::string_view(v) != "1";
  }();
  return on;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::string error;
  const auto mode = mixpilot::scenario_mode(text, kSource, error);
  if (!mode) {
    require_message(error);
    return 0;
  }
  // Each parser on any text: a scenario of another mode is a clean error too.
  if (!mixpilot::parse_scenario(text, kSource, error)) require_message(error);
  if (!mixpilot::parse_obstacle_scenario(text, kSource, error)) require_message(error);
  if (!mixpilot::parse_tracking_scenario(text, kSource, error)) require_message(error);
  if (with_setup()) {
    mixpilot::ModeRequest request;
    if (!mixpilot::make_mode(text, kSource, std::move(request), error)) require_message(error);
  }
  return 0;
}
