#include "core/control/ph_index.hpp"

#include <algorithm>
#include <cmath>

namespace mixpilot {

double ph_lambda(double d_res, const PhIndexSettings& s) {
  const double d_max = std::min(std::max(d_res, 0.0), s.r);
  const double a = -s.theta2 * (d_max - s.mu2 * s.r);
  // (1 + ζ e^a)^{1/ζ} = exp(log1p(ζ e^a) / ζ); log of it is log1p(ζ e^a)/ζ.
  const double log_den = std::log1p(s.zeta * std::exp(a)) / s.zeta;
  const double d_sat = s.mu1 * s.r * std::exp(-log_den);
  return std::sqrt(std::max(s.r * s.r - d_sat * d_sat, 0.0)) / s.r;
}

}  // namespace mixpilot
