#pragma once
// The last line of SPEC §4's failure policy. A failed or overrun RTI step applies the previous
// plan's next input (RtiSolver); that plan is only N steps long and ages with every further
// failure, so after `after` fallbacks in a row it is judged spent and the mode's safe
// controller flies instead (quadrotors: an LQR holding position or tracking the reference;
// Pendubot: its LQR near the top, no torque elsewhere). The MPC keeps being stepped meanwhile
// and takes over again once it has produced `after` good steps in a row. Every decision
// follows from the steps' RTI outcomes, which a replay reproduces (recorded overruns are
// forced), so a replay switches at the same steps.
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/numerics/types.hpp"

namespace mixpilot {

class SafetyNet {
 public:
  explicit SafetyNet(int after = rti_defaults::kSafeAfterFallbacks) { reset(after); }

  void reset(int after = rti_defaults::kSafeAfterFallbacks) {
    after_ = after < 1 ? 1 : after;
    failed_in_row_ = good_in_row_ = 0;
    engaged_ = switched_ = false;
    engagements_ = 0;
    steps_engaged_ = 0;
  }

  // This step's MPC outcome (fallback: its result was not applied). Returns whether the safe
  // controller flies this step.
  bool update(bool fallback) {
    failed_in_row_ = fallback ? failed_in_row_ + 1 : 0;
    good_in_row_ = fallback ? 0 : good_in_row_ + 1;
    const bool was = engaged_;
    if (!engaged_ && failed_in_row_ >= after_) engaged_ = true;
    else if (engaged_ && good_in_row_ >= after_) engaged_ = false;
    switched_ = engaged_ != was;
    if (switched_ && engaged_) ++engagements_;
    if (engaged_) ++steps_engaged_;
    return engaged_;
  }

  bool engaged() const { return engaged_; }
  bool switched() const { return switched_; }  // engaged or released in the last update
  int engagements() const { return engagements_; }
  std::int64_t steps_engaged() const { return steps_engaged_; }
  int after() const { return after_; }

 private:
  int after_ = rti_defaults::kSafeAfterFallbacks;
  int failed_in_row_ = 0, good_in_row_ = 0;
  bool engaged_ = false, switched_ = false;
  int engagements_ = 0;
  std::int64_t steps_engaged_ = 0;
};

// The summary's line about the safe controller ("" when it never flew): how long, and why.
inline std::string safe_hold_summary(const SafetyNet& net, double dt, const char* controller) {
  if (net.steps_engaged() == 0) return "";
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "  SAFE HOLD for %.2f s (%d time%s): the MPC fell behind %d steps in a row, so %s "
                "flew (this machine could not keep up)\n",
                double(net.steps_engaged()) * dt, net.engagements(),
                net.engagements() == 1 ? "" : "s", net.after(), controller);
  return buf;
}

}  // namespace mixpilot
