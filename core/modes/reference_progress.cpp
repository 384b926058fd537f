#include "core/modes/reference_progress.hpp"

#include <algorithm>
#include <cmath>

namespace mixpilot {

std::optional<double> reference_progress(const ReferencePath& reference, const Eigen::Vector3d& p,
                                         double t, const ProgressSearch& s) {
  if (!p.allFinite() || !std::isfinite(t) || !(s.step > 0.0) || !(s.window >= 0.0))
    return std::nullopt;
  const double lo = std::max(t - s.window, s.tau_min), hi = std::min(t + s.window, s.tau_max);
  if (!(lo <= hi) || !std::isfinite(hi - lo)) return std::nullopt;
  const auto f = [&](double tau) { return (reference(tau) - p).squaredNorm(); };

  // Coarse: the samples τ_j = lo + j h, the last one at hi.
  const auto n = static_cast<long>(std::ceil((hi - lo) / s.step));
  const auto tau_of = [&](long j) { return j >= n ? hi : lo + double(j) * s.step; };
  long best = 0;
  double f_best = f(lo);
  for (long j = 1; j <= n; ++j) {
    const double v = f(tau_of(j));
    if (v < f_best) {
      f_best = v;
      best = j;
    }
  }
  if (n == 0) return lo;

  // Refined: golden-section search on [τ_{j*−1}, τ_{j*+1}] ∩ I.
  double a = tau_of(std::max(best - 1, 0L)), b = tau_of(std::min(best + 1, n));
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);  // 1/φ
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  while (b - a > s.tolerance) {
    if (fc <= fd) {  // the minimum is in [a, d]
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {  // in [c, b]
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  const double tau = 0.5 * (a + b);
  // The bracket's ends were samples: never worse than the best of them.
  return f(tau) <= f_best ? tau : tau_of(best);
}

}  // namespace mixpilot
