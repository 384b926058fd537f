#pragma once
// Predicted healthiness (PH) index of SPEC §5.4 (thesis ch. 7). From the previous solution's
// prediction over N_b intervals:
//   d_res = max_{i=0..N_b} ‖η_{i|k−1} − η^r_{i|k−1}‖,   d_max = min(d_res, r),
//   d_sat = μ1 r / (1 + ζ exp(−θ2 (d_max − μ2 r)))^{1/ζ},
//   λ     = √(r² − d_sat²) / r  ∈ (0, 1).
// ζ is tiny (1e-13), so the power is evaluated as exp(log1p(ζ e^a)/ζ): the naive form rounds
// 1 + ζ e^a to a few ulps above 1 and keeps only ~3 significant digits.
//
// Why λ fell (SPEC §10) is read from the same quantities: d_res, the node i* where the maximum
// is reached, the direction of η_{i*} − η^r_{i*}, or the cap that bound λ below the index.
#include <cstdint>

#include <Eigen/Core>

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

// What held the λ of a step below the PH index, if anything. (The instructor's bounds of
// SPEC §10 will be one more.)
enum class LambdaCap : std::uint8_t {
  none = 0,        // λ is the PH index of the previous step's prediction
  input_lost = 1,  // the pilot source's authority: its input is lost or not back yet (SPEC §6)
  probe = 2,       // a probe flight (SPEC §10): the PH index is computed but not applied
  safe_hold = 3,   // the safe controller flew the step (the MPC's plan was spent): λ = 0
};
const char* to_string(LambdaCap cap);  // "none", "input lost", "probe", "safe hold"
inline constexpr int kLambdaCapCount = 4;

// What decided the λ of a mixed-initiative step (SPEC §10 "Why λ fell"). A value of fixed
// size: telemetry carries it without allocating.
struct LambdaReason {
  double ph_index = ph_defaults::kInitialLambda;  // λ of the PH index, before any cap
  double d_res = 0.0;  // [m] max_{i=0..N_b} ‖η_{i|k−1} − η^r_{i|k−1}‖
  int node = -1;       // i*: the first node reaching d_res; −1: no prediction yet (λ initial)
  double ahead = 0.0;  // [s] i*·Δt: how far node i* lies ahead of t_{k−1}
  // (η_{i*} − η^r_{i*}) / d_res in the world frame; zero when d_res = 0.
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  LambdaCap cap = LambdaCap::none;

  bool operator==(const LambdaReason&) const = default;
};

// The PH index of one prediction and where it comes from: d_res over the nodes
// 0..min(N_b, N) of `predicted` and `reference` (3 x (N+1) each), i*, the direction there,
// i*·dt and ph_index = ph_lambda(d_res); cap none. Allocates nothing.
LambdaReason ph_reason(const Eigen::Matrix3Xd& predicted, const Eigen::Matrix3Xd& reference,
                       double dt, const PhIndexSettings& s);

// Before any prediction: the initial λ, no node.
LambdaReason ph_initial_reason(const PhIndexSettings& s);

}  // namespace mixpilot
