#pragma once
// The trainee's progress as the window shows it (SPEC §10): plain snapshot structs, filled by
// the app from the history off the UI thread (app/history_writer.hpp), and the Progress panel
// that draws one. ui/ never reads the history itself: a frame only draws what was loaded.
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <imgui.h>

#include "ui/requests.hpp"

namespace mixpilot::ui {

inline constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

// One flight of the trainee on the scenario, its texts formatted when loaded (a frame formats
// only numbers, into fixed buffers).
struct ProgressFlight {
  int attempt = 0;                 // 1, 2, ...: its place among the trainee's flights of it
  bool probe = false;              // unassisted: the pilot's own skill
  double skill = kNoValue;         // 0-100
  double dependence = kNoValue;    // D, the share of the flight the planner flew (0-1)
  double duration_s = 0.0;
  std::int64_t started_unix_ms = 0;  // when it started (finds a flight just flown in the history)
  std::string when;                // local time, "YYYY-MM-DD HH:MM"
  std::string ended;               // completed | interrupted | lost
  std::string recording;           // its recording ("" none, or no longer on this disk)
  std::string scenario_hash;       // SHA-256 of the scenario's text it flew (a file edited since
                                   // is another scenario to a ghost)
  // A branch (fly from here): flown on from this step of another flight (−1: none).
  std::int64_t from_step = -1;
  // Every score field of its row (the score card compares the mode's own score with them).
  std::vector<std::pair<std::string, double>> metrics;
};

// A least-squares line through the last `over` skills of one kind of flight.
struct Trend {
  int over = 0;                    // flights it was fitted to (< 3: no trend)
  double slope = kNoValue;         // skill per attempt
  std::string words;               // what it means, for a newcomer
};

struct ProgressView {
  std::string trainee, scenario;
  std::vector<ProgressFlight> flights;  // oldest first
  int assisted = 0, probes = 0;
  int best = -1;                   // index into flights: the highest skill
  bool has_dependence = false;     // some flight's row holds D
  Trend assisted_trend, probe_trend;
  std::string error;               // why the history could not be read ("" fine)
};

// A trainee's progress in a lesson (SPEC §10), read from the history.
struct LessonAttemptView {
  int step = 0;                    // 0-based
  bool passed = false;
  std::string detail;              // the verdict in words ("" when passed)
  double skill = kNoValue;
};
struct LessonProgressView {
  std::string trainee, lesson, lesson_hash;
  bool loaded = false;             // read from the history (or there was none to read)
  int step = 0;                    // the step the trainee is on, 0-based (= steps: every one passed)
  int failed_attempts = 0;         // at it, since they reached it
  std::vector<LessonAttemptView> attempts;  // oldest first
  std::string error;               // why the history could not be read ("" fine)
};

// What the app knows of the history: its trainees (the session panel's picker) and the progress
// of the chosen trainee on the chosen scenario. Immutable once published.
struct HistoryView {
  bool loaded = false;             // false until the first load finished
  std::vector<std::string> trainees;  // sorted
  ProgressView progress;
  LessonProgressView lesson;       // the lesson shown (HistoryWriter::show_lesson)
};

// The Progress panel (ui.show_progress, H): skill per attempt (assisted and probe flights), D,
// the best run, the trend, the last flights with a button that replays a recording
// (ReplayRecording). `open` is cleared when the user closes it.
void draw_progress_panel(const HistoryView& h, bool& open, ImVec2 display, Requests& out);

}  // namespace mixpilot::ui
