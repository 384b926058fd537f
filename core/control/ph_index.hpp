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

// SPEC §10 "Instructor bounds": λ_applied = min(max(λ, floor), ceiling, the input's cap). A
// floor above 0 guarantees the pilot a share, a ceiling below 1 guarantees the planner one.
struct AuthorityBounds {
  double floor = 0.0;    // λ never below it (unless the input is lost)
  double ceiling = 1.0;  // λ never above it
  bool operator==(const AuthorityBounds&) const = default;
  // 0 ≤ floor ≤ ceiling ≤ 1, both finite.
  bool valid() const { return floor >= 0.0 && floor <= ceiling && ceiling <= 1.0; }
};

// What set the λ of a step other than the PH index, if anything.
enum class LambdaCap : std::uint8_t {
  none = 0,        // λ is the PH index of the previous step's prediction
  input_lost = 1,  // the pilot source's authority: its input is lost or not back yet (SPEC §6)
  probe = 2,       // a probe flight (SPEC §10): the PH index is computed but not applied
  safe_hold = 3,   // the safe controller flew the step (the MPC's plan was spent): λ = 0
  instructor_ceiling = 4,  // the instructor's (or lesson's) ceiling held λ down (SPEC §10)
  instructor_floor = 5,    // the instructor's floor held λ up (SPEC §10)
};
// "none", "input lost", "probe", "safe hold", "instructor ceiling", "instructor floor"
const char* to_string(LambdaCap cap);
inline constexpr int kLambdaCapCount = 6;

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
