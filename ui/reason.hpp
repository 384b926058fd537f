#pragma once
// Why λ fell, in words and on the arena (SPEC §10, from §5.4): which step's reason the screen
// shows, for how long, and the HUD's line for it. Functions of the telemetry alone, so a live
// flight, a replay and a headless screenshot say the same thing at the same step.
#include <cstddef>
#include <optional>
#include <string>

#include "ui/scene.hpp"

namespace mixpilot::ui {

// λ below this needs explaining (the pilot has lost a noticeable share).
inline constexpr double kReasonLambda = 0.9;
// [s] the words stay this long after they stop mattering, so they do not flicker.
inline constexpr double kReasonHoldS = 0.5;

// Whether step `s`'s λ needs explaining: a mixed-initiative step whose λ was held by a cap
// (before the first step too: READY says the instructor's ceiling, a probe), or a solved one
// whose λ is below kReasonLambda. The initial λ, before any prediction, does not (nothing
// decided it).
bool reason_matters(const Telemetry& s);

// The index in `h` of the step whose reason the screen shows: the newest step when it matters,
// else the newest one that mattered less than kReasonHoldS before it; nullopt when none did.
std::optional<std::size_t> shown_reason(const History& h);

// The prediction that step h[i]'s λ was computed from (SPEC §5.4: the previous step's): h[i − 1]
// when it is that step, else nullptr (a live flight's history may have dropped it).
const Telemetry* reason_prediction(const History& h, std::size_t i);

// The words for step `s` in a ball of radius `ball_radius`, short enough for a line of the HUD:
// "planner 72 %: you would leave the ball by 0.06 m in 0.12 s" (d_res − r at i*·Δt), inside
// the ball "planner 35 %: you would be 0.09 m off the reference in 0.075 s" (d_res), "... (too
// low)" where the gap points mostly down; "input lost: the planner flies", "probe flight: you
// fly alone" for the caps.
std::string reason_text(const Telemetry& s, double ball_radius);

}  // namespace mixpilot::ui
