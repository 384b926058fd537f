#pragma once
// Lessons in the app (SPEC §10, core/scenario/lesson.hpp): a step made into a flight's options
// (its scenario, a probe's assistance off, the ceiling as authority bounds, the lesson's tag for
// the recording and the history), and the words both front ends use for a step and a verdict.
// `mixpilot lesson` (app/lesson.cpp) and the window's lesson picker (app/live_controller.cpp)
// fly steps through these; FlightRig::judge_as judges them.
#include <string>

#include "app/flight.hpp"
#include "core/history/history.hpp"
#include "core/scenario/lesson.hpp"

namespace mixpilot::cli {

// The options of `lesson`'s step `step` on top of `base` (its pilot, headless, trainee,
// history): the step's scenario, the assistance (off for a probe), bounds [0, ceiling] and the
// lesson's tag.
FlyOptions lesson_flight(const Lesson& lesson, int step, FlyOptions base);

// "step 2 of 5: A slow climb".
std::string step_heading(const Lesson& lesson, int step);
// How the step is flown: "ceiling: λ at most 0.50 (the planner keeps 50 % or more)" or "a
// probe: you fly alone (no assistance, every constraint kept)".
std::string step_conditions(const LessonStep& step);
// The step in one short line (the window's): "λ ≤ 0.50 · pass: skill ≥ 72, no collision, in B
// ≥ 90 %", or "probe: no assistance · pass: ...".
std::string step_rule(const LessonStep& step);
// "attempts: 1 failed, 2 left" / "attempts: 1 failed (no limit)"; "" before any failed attempt
// of a step without a limit.
std::string attempts_text(const LessonStep& step, int failed_attempts);
// The step is closed: its attempts are all used and failed.
inline bool out_of_attempts(const LessonStep& step, int failed_attempts) {
  return step.attempts > 0 && failed_attempts >= step.attempts;
}
// The trainee's progress in `lesson` from the history (step 0 when none); false with the reason.
[[nodiscard]] bool read_progress(history::HistoryStore& store, const std::string& trainee,
                                 const Lesson& lesson, history::LessonProgress& out,
                                 std::string& error);

int lesson_command(int argc, char** argv);

}  // namespace mixpilot::cli
