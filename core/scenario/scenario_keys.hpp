#pragma once
// A scenario with some of its keys set to other values: the variants a study flies of a shipped
// scenario (the thesis's figures fly the smooth step at several round-trip times, with and
// without the predictor; the obstacle scenarios with either constraint form).
//
// The edit is made in the scenario's text, so everything else stays as written (comments, the
// order, the line numbers of every other key), the loader checks the result as it checks any
// file, and a recording of the variant embeds exactly the text that flew.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot {

struct ScenarioKey {
  std::string key;    // dotted path of a key of a table: "plant.rtt", "controller.ph.N_b"
  std::string value;  // one TOML value as text: "0.012", "false", "\"squared\"", "[1.0, 2.0]"
};

// "KEY=VALUE" (spaces around '=' allowed); nullopt with the reason when malformed.
std::optional<ScenarioKey> parse_scenario_key(std::string_view text, std::string& error);

// `text` (the scenario read from `source_name`) with each key set, in order (a later setting of
// the same key wins). A key the file gives has its value replaced where it stands; a key the file
// leaves to its default is added on the line after its table's header (a top-level key at the
// top). Errors name the setting: the text is not TOML, the value is not one TOML value on one
// line, a table on the path is missing, has no header of its own to add under, or is an array
// of tables, or the key names a table. Whether the key and its value mean anything is the
// scenario loader's to say (unknown keys and bad values are refused there).
std::optional<std::string> set_scenario_keys(std::string_view text, const std::string& source_name,
                                             const std::vector<ScenarioKey>& keys,
                                             std::string& error);

// "plant.rtt = 0.012, controller.compensation = false", for messages and labels.
std::string describe_keys(const std::vector<ScenarioKey>& keys);

}  // namespace mixpilot
