#pragma once
// `mixpilot sweep` (docs/sweeps.md): a sweep file's plan flown into a folder of results, on
// this machine's cores or one shard of it at a time, and merged into one table.
#include <string>

#include "app/flight.hpp"
#include "app/sweep_folder.hpp"
#include "core/modes/mode.hpp"
#include "core/scenario/sweep.hpp"

namespace mixpilot::cli {

// The plan of a sweep as its folder knows it (plan.json, the hash, the ids).
FolderPlan folder_plan(const SweepPlan& plan);

// One run of the plan flown as `fly --headless` would fly it (history off), recorded into
// `dir`/recordings/<id>.mcap when the plan records: its run file's text, or why not.
RunOutcome fly_sweep_run(const SweepPlan& plan, const SweepRun& run, const std::string& dir);

// The run's flight options (what `fly` takes on its command line, and the run's text).
FlyOptions sweep_fly_options(const SweepPlan& plan, const SweepRun& run);

// A report's headline for a progress line: its mode's main metric ("skill 54.2",
// "tracking_rms_m 0.0213"), and LOST when the vehicle was.
std::string metrics_headline(const Metrics& metrics);

int sweep_command(int argc, char** argv);

}  // namespace mixpilot::cli
