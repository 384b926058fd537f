#pragma once
// One flight as the command line asks for it (`mixpilot fly`, `replay`, `demo`): the options,
// the scenario and recording they name, and the mode made from them. Shared by the headless
// path (app/fly.cpp) and the window (app/window.cpp).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/screenshot.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/report.hpp"
#include "core/recording/recording.hpp"
#include "core/runtime/realtime_runner.hpp"

namespace mixpilot::cli {

struct FlyOptions {
  std::string scenario_path;
  std::string pilot;
  bool headless = false;
  std::optional<double> duration;
  std::string record;
  std::string report;
  bool allow_mismatch = false;
  bool force = false;
  std::vector<ScreenshotRequest> screenshots;
  int width = 1280, height = 720;  // of the screenshots and the window
  bool realtime = false;           // headless, paced by the wall clock
  bool exit_at_end = false;        // window: start at once, close when the run is over
  bool replay = false;             // `mixpilot replay`: a recording of any mode flown again
  const char* command = "fly";     // for messages
};

// The flight of FlyOptions, set up: the scenario from --scenario or the recording given as
// --pilot, and the mode it names.
struct Flight {
  std::string scenario_text;
  std::string scenario_source;  // for messages and relative paths
  std::string scenario_file;    // the scenario's file, absolute (recorded as scenario_path)
  std::optional<RecordingContents> recording;  // --pilot REC.mcap
  std::unique_ptr<Mode> mode;
  std::string pilot;  // mixed initiative: the pilot source's name
};

// Reads the scenario (and the recording of a replay) and makes the mode; nullopt with the
// reason and the exit status (kExitError, or kExitReplayMismatch for a --scenario other than
// the recording's).
std::optional<Flight> prepare_flight(const FlyOptions& o, std::string& error, int& status);

// What a recording of the flight says about it (its metadata). `trainee` is the person flying,
// when the app knows.
SessionInfo session_info(const Flight& f, const std::string& trainee = "");
Labels report_labels(const Flight& f, bool was_interrupted);

// Output paths, checked before the flight: distinct, writable, and never over a special file,
// nor over an existing file without --force. False with the reason.
[[nodiscard]] bool check_outputs(const FlyOptions& o, std::string& error);

// The summary's real-time line: deadline misses, worst start lateness, p99 and longest step,
// and the control thread's scheduling.
void print_realtime(const RealtimeStats& st, double dt);

// The shortest text of `t` ("%g").
std::string seconds_text(double t);

}  // namespace mixpilot::cli
