#pragma once
// Predicted healthiness (PH) index of SPEC §5.4 (thesis ch. 7). From the previous solution's
// prediction over N_b intervals:
//   d_res = max_{i=0..N_b} ‖η_{i|k−1} − η^r_{i|k−1}‖,   d_max = min(d_res, r),
//   d_sat = μ1 r / (1 + ζ exp(−θ2 (d_max − μ2 r)))^{1/ζ},
//   λ     = √(r² − d_sat²) / r  ∈ (0, 1).
// ζ is tiny (1e-13), so the power is evaluated as exp(log1p(ζ e^a)/ζ): the naive form rounds
// 1 + ζ e^a to a few ulps above 1 and keeps only ~3 significant digits.
#include "core/numerics/types.hpp"

namespace mixpilot {

struct PhIndexSettings {
  double r = ph_defaults::kRadius;      // working-condition ball radius [m]
  int N_b = ph_defaults::kHorizon;      // intervals of the prediction inspected
  double mu1 = ph_defaults::kMu1;
  double mu2 = ph_defaults::kMu2;
  double theta2 = ph_defaults::kTheta2;
  double zeta = ph_defaults::kZeta;
  double initial_lambda = ph_defaults::kInitialLambda;  // until a prediction exists
};

// λ(d_max) for a distance d_res (clipped to r).
double ph_lambda(double d_res, const PhIndexSettings& s);

}  // namespace mixpilot
