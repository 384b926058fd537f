#pragma once
// A scenario with some of its keys set to other values: the variants a study flies of a
// shipped scenario (a sweep's runs; the thesis's figures fly the smooth step at several
// round-trip times, with and without the predictor; the obstacle scenarios with either
// constraint form).
//
// The edit is made in the scenario's text, so everything else stays as written (comments, the
// order, the line numbers of every other key), the loader checks the result as it checks any
// file, and a recording of the variant embeds exactly the text that flew. A value the file
// gives is replaced where it stands; a key the file leaves to its default is added on the line
// after its table's [header] (inside the braces of an inline table; a top-level key at the
// top); a table the file lacks is appended with its header. Whether a key and its value mean
// anything is the scenario loader's to say (unknown keys and bad values are refused there).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot {

// A value written into a scenario: a TOML scalar or an array of them (a scenario's vectors).
struct ScenarioValue {
  enum class Type { boolean, integer, number, string, array };
  Type type = Type::integer;
  bool boolean = false;
  std::int64_t integer = 0;
  double number = 0.0;
  std::string string;
  std::vector<ScenarioValue> items;

  std::string toml() const;  // as TOML source: 0.012, true, "novice", [0.0, 0.5]
  std::string text() const;  // for names and tables: 0.012, true, novice, [0, 0.5]
  std::string json() const;  // as JSON (a non-finite number: null)
};

// One TOML value written as text on one line ("0.012", "false", "\"squared\"", "[1.0, 2.0]");
// nullopt with what was expected otherwise.
std::optional<ScenarioValue> parse_scenario_value(std::string_view text, std::string& why);

// The last part of a key path as a short label: "rtt" for plant.rtt, "radius" for
// arena.obstacles[2].radius, "start2" for plant.start[2]; the key itself if it is no path.
std::string key_label(std::string_view key);

// A scenario's text, parsed once, and the values written over it. Keys are paths as in the
// scenario file ("plant.rtt", "controller.ph.N_b"), with [i] for an element of an array
// ("arena.obstacles[2].radius", "plant.start[2]"). Every edit is made against the text as
// given: a key is set once, and no key inside another ("plant.start" and "plant.start[2]").
// The reasons (`why`) say what was expected without naming the key; the caller names it.
class ScenarioEdit {
 public:
  // nullopt with the toml++ complaint when `text` is not TOML.
  static std::optional<ScenarioEdit> open(std::string_view text, const std::string& source_name,
                                          std::string& why);

  // Whether `key` names a value of the scenario `v` may replace (the same kind of value; any
  // number for a number's), or one it leaves out; false with why not.
  [[nodiscard]] bool check(std::string_view key, const ScenarioValue& v, std::string& why) const;
  // Writes `key` = `v` (check() first); false with why it cannot be written.
  [[nodiscard]] bool set(std::string_view key, const ScenarioValue& v, std::string& why);
  // Whether the text as given holds `v` at `key` (a written text read back).
  [[nodiscard]] bool holds(std::string_view key, const ScenarioValue& v) const;
  // The text with every set() made.
  std::string result() const;

  ScenarioEdit(const ScenarioEdit&);
  ScenarioEdit& operator=(const ScenarioEdit&);
  ScenarioEdit(ScenarioEdit&&) noexcept;
  ScenarioEdit& operator=(ScenarioEdit&&) noexcept;
  ~ScenarioEdit();

 private:
  struct State;
  explicit ScenarioEdit(std::unique_ptr<State> s);
  std::unique_ptr<State> s_;
};

// A key and its value as text, as a study names a variant.
struct ScenarioKey {
  std::string key;    // a key path as for ScenarioEdit: "plant.rtt", "arena.obstacles[0].radius"
  std::string value;  // one TOML value as text: "0.012", "false", "\"squared\"", "[1.0, 2.0]"
};

// "KEY=VALUE" (spaces around '=' allowed); nullopt with the reason when malformed.
std::optional<ScenarioKey> parse_scenario_key(std::string_view text, std::string& error);

// `text` (the scenario read from `source_name`) with each key set, in order: each setting is
// written into the text the settings before it made, so a later setting of a key wins. Errors
// name the setting and the file: the text is not TOML, the key is not a path, the value is not
// one TOML value on one line or not of the kind the file's value is, the path crosses a value
// that is no table, an element an array lacks, or names a table.
std::optional<std::string> set_scenario_keys(std::string_view text, const std::string& source_name,
                                             const std::vector<ScenarioKey>& keys,
                                             std::string& error);

// "plant.rtt = 0.012, controller.compensation = false", for messages and labels.
std::string describe_keys(const std::vector<ScenarioKey>& keys);

}  // namespace mixpilot
