#pragma once
// The debrief of a flight (SPEC §10 "Debrief events"): what happened in it, as a short list of
// events read from its telemetry one step at a time. One builder serves every front end: the
// recorder writes each event into the recording as it closes (core/recording/
// session_recording.hpp, topic /rosout), a replay rebuilds the list from the replayed telemetry
// for its Debrief panel and timeline, and the tests read it. After setup() it allocates nothing:
// events are rare and their list is reserved.
//
// The events, over the steps k of a flight (t_k = k·Δt; an event runs from the step it starts
// at to the first step after it):
//   takeover    mixed initiative: λ_k below the threshold λ_T (default 0.5), until λ has been
//               at or above λ_T again for `hold_s` (0.5 s; a dip in between continues it); its
//               lowest λ and what decided λ there (the reason channel: d_res, node i*, the
//               direction or the cap). A step whose λ nothing decided (the initial λ before the
//               first prediction) opens none.
//   near miss   the clearance (Telemetry::clearance: the vehicle sphere's distance to an
//               obstacle, wall or floor) below the margin, 2 × the vehicle radius, without
//               contact, until it has been at or above it for `hold_s`; its least clearance. An
//               approach that touched is no near miss: its contact is a collision.
//   collision   contact (clearance < 0, or kEventCollision), from the step it starts to the
//               first step without it: one per contact, as the score counts them; the deepest
//               clearance.
//   fallback    steps that applied the previous solution's input (kEventFallback or
//               kEventOverrun), those less than `hold_s` apart as one run; how many.
//   input lost  the pilot's input lost (InputState::lost), until it is back.
//   lost        the vehicle was lost (kEventLost): the flight ended there.
//   safe hold   steps the safe controller flew (kEventSafeHold), a run as one.
//   marker      an instructor's marker with its text, at a step (mark(), or a marker command
//               in the step's telemetry, Telemetry::commands).
//   instructor  any other instructor's command at the step it took effect at, in words
//               (describe(InstructorCommand)): "instructor: ceiling 0.30".
// An event still open when the flight ends is closed at its end (until_end).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/modes/debrief_note.hpp"
#include "core/modes/mode.hpp"

namespace mixpilot {

enum class DebriefKind : std::uint8_t {
  takeover,
  near_miss,
  collision,
  fallback,
  input_lost,
  lost,
  safe_hold,
  marker,
  instructor,  // an instructor's command other than a marker (SPEC §10)
};
inline constexpr int kDebriefKindCount = 9;
// "takeover", "near miss", "collision", "fallback", "input lost", "vehicle lost", "safe hold",
// "marker", "instructor".
const char* to_string(DebriefKind kind);

// The severity of an event as ROS 2 logs it (rcl_interfaces/msg/Log's levels).
enum class LogLevel : std::uint8_t { debug = 10, info = 20, warn = 30, error = 40, fatal = 50 };
// takeover, near miss, fallback, input lost: warn; collision, vehicle lost, safe hold: error;
// marker, instructor: info.
LogLevel log_level(DebriefKind kind);

struct DebriefEvent {
  DebriefKind kind = DebriefKind::marker;
  std::int64_t start_step = 0;   // its first step
  std::int64_t end_step = 0;     // the first step after it (lost, marker: start_step)
  std::int64_t closed_step = 0;  // the step whose telemetry closed it (when it was known)
  double start = 0.0;            // [s] t of start_step
  double end = 0.0;              // [s] t of end_step
  bool until_end = false;        // it was still going when the flight ended
  // takeover: its lowest λ; near miss, collision: its least clearance [m]; otherwise 0.
  double extreme = 0.0;
  double extreme_t = 0.0;  // [s] when it was reached
  std::int64_t steps = 0;  // the steps it marked: fallback, safe hold (a run has gaps); others all
  // takeover: what decided λ at its lowest, and the pilot's input there.
  LambdaReason reason;
  InputState input = InputState::ok;
  DebriefNote note;  // marker: its text; instructor: the command in words

  double duration() const { return end - start; }
  bool operator==(const DebriefEvent&) const = default;
};

struct DebriefSettings {
  double dt = 0.01;                // [s] control period
  double takeover_lambda = 0.5;    // λ_T: λ below it means the planner took over
  double hold_s = 0.5;             // [s] what ends a takeover or near miss, what joins runs
  double near_miss_margin = 0.0;   // [m] clearance below it is a near miss (0: none)
  double ball_radius = 0.0;        // [m] r of the ball B, for the words
  std::size_t capacity = 1024;     // events kept (more are counted in dropped())
};

// The settings for a flight of `mode` (its Δt, its view's ball and vehicle radius), with the
// default thresholds. Allocates (it reads the mode's view): not for the loop.
DebriefSettings debrief_settings(const Mode& mode);

class DebriefBuilder {
 public:
  DebriefBuilder() = default;
  explicit DebriefBuilder(const DebriefSettings& s) { setup(s); }
  // Starts over with `s`: reserves the list (allocates).
  void setup(const DebriefSettings& s);
  // The next step of the flight (steps in increasing order; a gap, such as steps a recorder
  // dropped, counts as time passing). The events it closes are appended to events(). Allocates
  // nothing.
  void add(const Telemetry& s);
  // The flight ended after the last step added: every open event closes there. Allocates
  // nothing; add() may not follow without a new setup().
  void finish();
  // An instructor's marker at the last step added (at step 0 before any). Allocates nothing.
  void mark(std::string_view text);

  // In the order they closed (which is the order a recorder writes them).
  const std::vector<DebriefEvent>& events() const { return events_; }
  // Events that closed with the list full: not kept.
  std::int64_t dropped() const { return dropped_; }
  const DebriefSettings& settings() const { return settings_; }

 private:
  // An event being built, and the last step its condition held.
  struct Open {
    bool open = false;
    std::int64_t last_on = 0;
    bool touched = false;  // near miss: contact within it (so it is none)
    DebriefEvent e;
  };
  void start(Open& o, DebriefKind kind, const Telemetry& s);
  // Closes `o` as of step `closed` (its condition last held at o.last_on).
  void close(Open& o, std::int64_t closed, bool until_end);
  void keep(const DebriefEvent& e);
  double time_of(std::int64_t step) const { return double(step) * settings_.dt; }

  DebriefSettings settings_;
  std::int64_t hold_steps_ = 1;
  std::vector<DebriefEvent> events_;
  std::int64_t dropped_ = 0;
  std::int64_t last_step_ = -1;  // the last step added
  Open takeover_, near_miss_, collision_, fallback_, input_lost_, safe_hold_;
};

// The events of a whole flight: its steps through one builder, finished.
std::vector<DebriefEvent> debrief_of(const std::vector<Telemetry>& steps, std::size_t count,
                                     const DebriefSettings& s);

// What an event says, in words (the Debrief panel, the recording's /rosout):
//   "planner took over for 1.8 s (lowest λ 0.21): you would leave the ball by 0.08 m in 0.3 s"
//   "near miss for 0.40 s: 0.123 m of clearance at the closest"
//   "collision: in contact for 0.30 s, 0.052 m deep"
//   "3 fallbacks in 0.20 s: the MPC applied its previous plan"
//   "input lost for 2.0 s: the planner flew until it came back"
//   "vehicle lost: the flight ended"
//   "safe hold for 1.2 s: the MPC fell behind, the safe controller flew"
//   "marker: <its text>"
//   "instructor: gust 2.0 N for 0.50 s"
// ("... for the last 1.8 s ..." when it lasted to the end). Writes a NUL-terminated text into
// out[0 .. size) (cut at a character if need be); returns its length. Allocates nothing.
std::size_t describe(const DebriefEvent& e, double ball_radius, char* out, std::size_t size);
std::string describe(const DebriefEvent& e, double ball_radius);

}  // namespace mixpilot
