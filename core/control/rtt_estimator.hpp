#pragma once
// Online round-trip time estimation (SPEC §9; thesis ch. 8, future work), for the §5.2
// predictor when the vehicle is another process or machine.
//
// Each state the vehicle sends echoes the newest command in effect when it was measured: that
// command's send stamp T_j (the controller's clock) and how long it had acted, a (the vehicle's
// clock; a duration, so the two clocks need no synchronisation). Received at t_recv, the state
// gives one round-trip sample
//     τ = t_recv − T_j − a,
// the time from a command leaving to the state it produced arriving: the command delay τ_c, the
// measurement delay τ_m and the transport and scheduling jitter of both. The estimate is the
// median of the last kWindow samples: it follows a change of delay within kWindow/2 samples and
// ignores a lone late or early sample, which a mean would not.
//
// Allocates nothing.
#include <algorithm>
#include <array>
#include <cstddef>

namespace mixpilot {

class RttEstimator {
 public:
  static constexpr int kWindow = 31;  // samples (odd: the median is one of them)

  void reset() {
    count_ = 0;
    next_ = 0;
    last_ = estimate_ = 0.0;
  }
  // One sample [s]; non-finite or negative samples are ignored (false).
  bool add(double tau) {
    if (!(tau >= 0.0) || tau > 1e6) return false;
    window_[std::size_t(next_)] = tau;
    next_ = (next_ + 1) % kWindow;
    count_ = std::min(count_ + 1, kWindow);
    last_ = tau;
    std::array<double, kWindow> sorted;
    std::copy_n(window_.begin(), count_, sorted.begin());
    const auto mid = sorted.begin() + count_ / 2;
    std::nth_element(sorted.begin(), mid, sorted.begin() + count_);
    estimate_ = *mid;
    return true;
  }
  bool valid() const { return count_ > 0; }
  double estimate() const { return estimate_; }  // [s], 0 before the first sample
  double last_sample() const { return last_; }   // [s]
  int samples() const { return count_; }         // in the window

 private:
  std::array<double, kWindow> window_{};
  int count_ = 0, next_ = 0;
  double last_ = 0.0, estimate_ = 0.0;
};

}  // namespace mixpilot
