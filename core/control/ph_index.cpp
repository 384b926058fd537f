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

const char* to_string(LambdaCap cap) {
  switch (cap) {
    case LambdaCap::none: return "none";
    case LambdaCap::input_lost: return "input lost";
    case LambdaCap::probe: return "probe";
    case LambdaCap::safe_hold: return "safe hold";
    case LambdaCap::instructor_ceiling: return "instructor ceiling";
    case LambdaCap::instructor_floor: return "instructor floor";
  }
  return "?";
}

LambdaReason ph_reason(const Eigen::Matrix3Xd& predicted, const Eigen::Matrix3Xd& reference,
                       double dt, const PhIndexSettings& s) {
  LambdaReason out;
  out.node = 0;
  const Eigen::Index last = std::min<Eigen::Index>(s.N_b, predicted.cols() - 1);
  double d_res = 0.0;
  for (Eigen::Index i = 0; i <= last; ++i) {
    const double d = (predicted.col(i) - reference.col(i)).norm();
    if (d > d_res) {  // the first node of the maximum; a NaN never wins (as std::max)
      d_res = d;
      out.node = int(i);
    }
  }
  out.d_res = d_res;
  out.ahead = out.node * dt;
  if (d_res > 0.0)
    out.direction = (predicted.col(out.node) - reference.col(out.node)) / d_res;
  out.ph_index = ph_lambda(d_res, s);
  return out;
}

LambdaReason ph_initial_reason(const PhIndexSettings& s) {
  LambdaReason out;
  out.ph_index = s.initial_lambda;
  return out;
}

}  // namespace mixpilot
