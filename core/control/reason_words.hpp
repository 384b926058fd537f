#pragma once
// Why λ fell, in words (SPEC §10, read from §5.4): the part of the sentence that says where the
// previous prediction went, shared by the HUD (ui/reason.hpp, which puts the planner's share
// before it) and the debrief's takeovers (core/modes/debrief.hpp). Formats into a caller's
// buffer: no allocation.
#include <cstddef>

#include "core/control/ph_index.hpp"

namespace mixpilot {

// Where the prediction of `r` went against the ball of radius `ball_radius`, with d_res reached
// i*·Δt ahead (now when i* = 0):
//   outside the ball  "you would leave the ball by 0.06 m in 0.12 s"  (d_res − r)
//                     "you are out of the ball by 0.06 m"              (i* = 0)
//   on its edge       "you would reach the ball's edge in 0.15 s"      (|d_res − r| < 5 mm)
//   inside            "you would be 0.09 m off the reference in 0.075 s"  (d_res)
// and " (too low)" / " (too high)" where the gap points mostly down or up. Only what the PH
// index says: the caps have their own words where they are shown. Writes a NUL-terminated
// text into out[0 .. size) (cut if need be); returns its length.
std::size_t prediction_words(const LambdaReason& r, double ball_radius, char* out,
                             std::size_t size);

}  // namespace mixpilot
