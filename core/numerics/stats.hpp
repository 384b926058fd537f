#pragma once
// Order statistics of per-step timings (RTI time, predictor time), one definition for every
// mode and report.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace mixpilot {

// The q-quantile (q ∈ [0, 1]) of `values` as the element of rank round(q·(n − 1)) in sorted
// order (no interpolation: a reported time is one that was measured); 0 for no values.
inline double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t n = values.size();
  const double rank = std::floor(std::clamp(q, 0.0, 1.0) * double(n - 1) + 0.5);
  const std::size_t i = std::min(n - 1, std::size_t(rank));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(i), values.end());
  return values[i];
}

}  // namespace mixpilot
