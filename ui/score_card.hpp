#pragma once
// The score card at the end of a flight, live or replayed (SPEC §8, §10), as a trainee reads it:
// the score first and large; how it compares with their last and their best flight of the
// scenario (from the history); how much of the flight the planner flew (D); the two or three
// debrief events that cost the most, with what each cost; one suggestion chosen by the rules
// below; and every raw score field with its meaning one click away. score_card_of() makes it
// (no ImGui: the app makes it once when what it is made of changes, tests read it);
// draw_score_card() draws it each frame.
//
// What an event cost, in points of the mixed-initiative skill (core/modes/score.cpp:
// skill = 100 · progress · quality / (1 + collisions), quality = 0.4 · time in B + 0.4 · mean λ
// + 0.2 · exp(−override / 0.1)), from the debrief builder's data:
//   collision     skill / collisions: exactly what one contact fewer would have given back (the
//                 score is divided by 1 + collisions).
//   takeover      at most 100 · progress · 0.4 · min((1 − lowest λ) · duration, D · T) / T /
//                 (1 + collisions): its λ deficit, bounded by the lowest λ over its span and by
//                 the whole flight's (D · T), through mean λ's weight; "up to" (what it cost in
//                 time outside B, the debrief does not keep).
//   input lost,   100 · progress · 0.4 · min(duration, D · T) / T / (1 + collisions) at most: λ
//   safe hold     was held at 0 (the planner or the safe controller flew); "up to".
//   vehicle lost  skill · (1 − progress) / progress: the rest of the reference at this flight's
//                 quality, which the flight did not get to fly; "about".
//   near miss,    no point (the skill has no term for them): listed for what they were.
//   fallback
//   marker,       not costs: never listed.
//   instructor
// The other modes' scores are no sum of events: their events are listed by severity, no cost.
//
// The suggestion, the first rule that applies:
//   1. a lesson step was flown: its next step when passed, else the step again with the
//      criterion that failed;
//   2. the vehicle was lost: fly it again and keep it in the arena;
//   3. one kind of event cost at least half of what the events cost, and at least
//      kDominantCost points: practise against it (collisions: clearance; takeovers: staying in
//      B; input lost: the device; safe hold: the machine);
//   4. an assisted flight with a good skill (≥ kGoodSkill) that leans on the planner
//      (D ≥ kLeaning): a probe flight;
//   5. a skill below kGoodSkill: practise the quality term that lost the most (time in B, mean λ,
//      override), or the progress when it is the reference that was not flown;
//   6. otherwise: a probe flight when none of the scenario was flown yet, else the next
//      scenario.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <imgui.h>

#include "core/modes/debrief.hpp"
#include "core/modes/mode.hpp"
#include "ui/progress.hpp"
#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::ui {

inline constexpr double kGoodSkill = 65.0;    // the beginner course's first bar
inline constexpr double kLeaning = 0.25;      // the planner flew a quarter of the flight or more
inline constexpr double kDominantCost = 5.0;  // [skill points] below it, no kind dominates

// What a mode's card puts first: its score field and which way is better.
struct Headline {
  const char* key;        // the score field ("skill")
  const char* name;       // as the card names it
  const char* unit;       // after the number ("/ 100", "s", "cm")
  double scale;           // shown = value · scale (m → cm)
  bool higher_is_better;
  const char* format;     // printf format of the shown value
};
// The headline of `mode` when `metrics` has its field, else nullptr.
const Headline* headline_of(ModeKind mode, const Metrics& metrics);

// What the card is made of: the flight's score fields and debrief, whose it was, and the
// history's snapshot to compare it with.
struct FlightOutcome {
  ModeKind mode = ModeKind::mixed_initiative;
  Metrics metrics;
  bool probe = false;                // an unassisted probe flight (SPEC §10)
  bool replay = false;               // a replay's card: its events can be jumped to
  std::string trainee, scenario;     // the history's names of whose flight of what
  std::int64_t started_unix_ms = 0;  // a live flight's start: finds it in the history (0: none)
  std::string recording;             // a replay's recording: finds it in the history
  std::vector<DebriefRow> events;    // by start time (a replay's: ReplayInfo::events)
  bool events_ready = false;         // the debrief is complete
  const HistoryView* history = nullptr;  // nullptr: no history (--history off)
  // The lesson step the flight was an attempt at: the panel's view with its verdict (nullptr
  // or no verdict: none).
  const LessonChoice* lesson = nullptr;
};

// One of the events that cost the most.
struct CardEvent {
  int index = -1;                    // into FlightOutcome::events (what a click selects)
  DebriefKind kind = DebriefKind::takeover;
  double t = 0.0, end = 0.0;         // [s]
  std::string what;                  // the debrief's words
  double cost = std::numeric_limits<double>::quiet_NaN();  // [skill points] (NaN: no cost)
  std::string cost_text;             // "−12.3 skill", "up to −2.1 skill", "no points"
};

// How the flight compares with the trainee's flights before it.
enum class Comparison {
  no_history,  // there is no history (or it could not be read): note says why
  reading,     // the flight is being written or the history read: not yet
  first,       // the trainee's first flight of its kind of this scenario
  compared,    // last and best below
  none,        // nothing to compare (no score, another trainee's view, a recording not in it)
};

struct ScoreCard {
  bool has_score = false;
  std::string score_name;            // "skill"
  std::string score;                 // "63.4"
  std::string score_unit;            // "/ 100"
  std::string score_meaning;         // one line: what the score is
  Comparison comparison = Comparison::none;
  std::string note;                  // the comparison's words when there is none
  // Compared: the change since the last flight of its kind and against the best before it
  // (in the headline's shown unit; > 0 better whichever way the field points).
  double since_last = std::numeric_limits<double>::quiet_NaN();
  double against_best = std::numeric_limits<double>::quiet_NaN();
  bool new_best = false;
  std::string last_text, best_text;  // "+6.2 since your last assisted flight (57.2)"
  std::string dependence;            // D in words and number ("" for a mode without λ)
  std::vector<CardEvent> costly;     // at most kCostlyEvents, costliest first
  std::string events_note;           // why none is listed ("" when some are)
  std::string suggestion;            // what to do next
  std::string suggestion_why;        // the rule's reason, with the numbers
  Metrics raw;                       // every score field
};
inline constexpr std::size_t kCostlyEvents = 3;

// The card of `o`.
ScoreCard score_card_of(const FlightOutcome& o);

// What an event cost in skill points, and those words (see the top of this file); `metrics` of
// the flight it happened in.
double event_cost(const DebriefEvent& e, const Metrics& metrics);

// What a field of a mode's report means, with its unit ("" for a field it does not know).
const char* score_field_meaning(const std::string& key);

// The card as a window in the display's centre (`open` cleared when the user closes it). A
// replay's events jump there when clicked (SelectEvent).
void draw_score_card(const ScoreCard& card, bool replay, bool& open, ImVec2 display,
                     Requests& out);

}  // namespace mixpilot::ui
