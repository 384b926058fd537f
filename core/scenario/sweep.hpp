#pragma once
// Sweep files (TOML, docs/sweeps.md; SPEC §11): a base scenario and what to vary in it — a
// grid (every combination), an explicit list of runs, pilot profiles and seeds — expanded into
// a plan of independent runs, each a scenario text and the flight options fly would take.
// The plan is a pure function of the sweep file and the base scenario's text: its SHA-256
// identifies it, so a folder of results can refuse a changed sweep.
//
// A run's scenario is the base file's own text with the run's values written over the values
// they replace (core/scenario/scenario_keys.hpp: comments and layout kept; a key the file leaves
// at its default is added to its table), under a first comment line naming the sweep and the run. Whether the scenario
// accepts the values is for its loader (make_mode) to say; explain_run_error() says its
// complaint against the sweep file's line.
//
// Errors: one line per problem, `<file>:<line>:<col>: <key path>: <what was expected>`, as the
// scenario loaders give them (docs/scenario-format.md).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/control/mi_settings.hpp"
#include "core/control/ph_index.hpp"
#include "core/scenario/scenario_keys.hpp"

namespace mixpilot {

// Largest plan a sweep file may expand to (each run keeps its scenario text in memory).
inline constexpr std::size_t kMaxSweepRuns = 10000;

// One key set to one value.
struct SweepSetting {
  // A scenario key path as in the scenario file ("plant.rtt", "controller.ph.r"), with [i]
  // for an element of an array ("arena.obstacles[2].radius", "plant.start[2]"); or a flight
  // option of `fly`: "assist" (on | off), "floor", "ceiling".
  std::string key;
  ScenarioValue value;
  std::uint32_t line = 1, column = 1;  // the value's position in the sweep file
};

struct SweepRun {
  std::size_t index = 0;  // k, 0-based, in plan order
  // "<k>-<key>=<value>-...": k zero-padded (names sort in plan order), then the parameters
  // by their last key part (the whole path where two would read alike), file-name safe.
  std::string id;
  std::vector<SweepSetting> parameters;  // what this run sets beyond [set], in column order
  std::string scenario_text;             // the base scenario with [set] and the parameters
  std::optional<double> duration;        // [s] fly --duration
  Assistance assist = Assistance::on;    // fly --assist
  AuthorityBounds bounds;                // fly --floor, --ceiling
};

struct SweepPlan {
  std::string file;           // the sweep file, as given
  std::string name;           // its stem: the default output folder's name
  std::string scenario_file;  // the base scenario, absolute (its folder: relative references)
  std::string scenario_sha256;                       // of its text as read
  std::uint32_t scenario_line = 1, scenario_column = 1;  // of `scenario` in the sweep file
  std::vector<SweepSetting> fixed;   // [set]: every run
  std::vector<std::string> columns;  // the parameters' keys, in column order
  std::optional<double> duration;    // [s] `duration`: every flight's length (fly --duration)
  bool record = false;               // `record`: keep each run's recording
  std::vector<SweepRun> runs;
  std::string sha256;                // of the plan: what every run flies, in order
  std::vector<std::string> notes;    // warnings that do not stop the sweep
};

// Reads the sweep file at `path` and its base scenario, and expands the plan; nullopt with the
// errors otherwise.
std::optional<SweepPlan> load_sweep(const std::string& path, std::string& error);
// The same from text; `source_name` names it in messages, and its folder is where a relative
// `scenario` path starts.
std::optional<SweepPlan> parse_sweep(std::string_view text, const std::string& source_name,
                                     std::string& error);

// The plan as JSON (plan.json of a sweep's folder): the sweep, its scenario, [set], the
// columns and every run's index, id and parameters, with `plan_sha256`. `version` is recorded
// for the reader, outside the hash.
std::string sweep_plan_json(const SweepPlan& plan, std::string_view version);

// The complaint of the scenario loader (or make_mode) about `run`, said against the sweep
// file: each line at the setting it concerns (`<sweep>:<line>:<col>: <key>: <what>`, the
// scenario's own key path and words), or at `scenario` with the run's settings named. The
// caller says which run (several runs often share one complaint).
std::vector<std::string> explain_run_error(const SweepPlan& plan, const SweepRun& run,
                                           const std::string& loader_error);

}  // namespace mixpilot
