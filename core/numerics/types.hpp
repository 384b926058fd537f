#pragma once
// Settings defaults shared across core/. One place for every tunable constant with a default;
// each component's Settings struct takes its defaults from here.
#include <limits>

namespace mixpilot {

// Defaults of the OCP-QP interior-point solver (core/qp/qp_riccati_ipm.hpp), SPEC §4.
namespace qp_defaults {
inline constexpr int kMaxIterations = 50;
// Termination: ‖stationarity‖∞ ≤ tol_stat, ‖equality residual‖∞ ≤ tol_eq,
// ‖inequality residual‖∞ ≤ tol_ineq, mean complementarity tᵀλ/m ≤ tol_comp.
inline constexpr double kTolStationarity = 1e-6;
inline constexpr double kTolEquality = 1e-8;
inline constexpr double kTolInequality = 1e-8;
inline constexpr double kTolComplementarity = 1e-8;
// Fraction-to-boundary factor: the step keeps t, λ > 0 by stopping at least at this fraction
// of the way (the Riccati IPM may go further, see kStepCentrality).
inline constexpr double kStepFraction = 0.995;
// Mehrotra's step-length heuristic (γ_f): the blocking t or λ of a step may go as far as
// kStepCentrality times the mean complementarity after the step (divided by its partner), but
// not less far than kStepFraction of the way to the boundary.
inline constexpr double kStepCentrality = 0.01;
// Mehrotra's centring target σμ is floored at kCentringFloor · tol_comp (see the solver).
inline constexpr double kCentringFloor = 0.1;
// A step that aims below tol_comp, is at least kFinalStepMin long (so the linear residuals
// shrink to (1 − α) of theirs and would pass) but leaves μ above tol_comp gets one more
// corrector with the corrector's own second-order term (Carpenter et al. 1993): one more
// solve instead of one more iteration.
inline constexpr double kFinalStepMin = 0.9;
// The solve stops with min_step when the step length falls below this.
inline constexpr double kMinStep = 1e-10;
// Cold start: inequality slacks start at ≥ kInitSlack, multipliers at kInitMu / t.
inline constexpr double kInitSlack = 1e-1;
inline constexpr double kInitMu = 1.0;
// Warm start from primal and dual: multipliers λ are clipped from below at kWarmStartFloor and
// inequality slacks t at kWarmStartSlackFloor, so the iterate is strictly interior. The
// complementarity t∘λ of the start, and with it the iterations, grows with these floors: on the
// closed-loop QP sets of mixpilot-bench (mean IPM iterations: mi novice, mi reckless, thrown
// balls, crazyflie tracking) 1e-4 for both gave 1.80, 7.48, 1.90, 1.25; 1e-6 for both 1.27, 6.16,
// 1.61, 1.20; t ≥ 1e-8 and λ ≥ 1e-6 1.04, 6.09, 1.51, 1.20, with kWarmStartViolated 1.04, 5.50,
// 1.56, 1.20 and no worst QP above the 1e-4 floors' (15, 21 against 15, 34).
inline constexpr double kWarmStartFloor = 1e-6;
inline constexpr double kWarmStartSlackFloor = 1e-8;
// ... except a hard constraint the new QP's data violate at the warm start's primal point: its
// slack starts at the violation's size, at least this (room for the first step to restore it).
inline constexpr double kWarmStartViolated = 1e-4;
// Riccati Cholesky: input pivots must be > 0; a state pivot in [−kPsdTol·|diagonal|, 0] is a
// zero eigenvalue of a positive semidefinite cost-to-go (allowed), anything below is indefinite.
inline constexpr double kPsdTol = 1e-10;
// Iterative refinement of the Newton direction (needed once λ/t spans many orders of magnitude
// near convergence): at most kRefinementSteps, while the linear-solve error exceeds
// kRefineRatio · min(tol_stat, tol_eq), i.e. while it could keep the iterate from converging.
inline constexpr int kRefinementSteps = 2;
inline constexpr double kRefineRatio = 0.1;
// ... and only while μ < kRefineMuRatio · tol_comp: W = λ/t ≈ λ²/μ is only then large enough for
// the rounding it amplifies to matter.
inline constexpr double kRefineMuRatio = 1e3;
// QpRiccatiIpmPairs: pair condensing applied this many times (blocks of 2^levels stages). For
// cold, many-iteration solves of the MI and Crazyflie QPs of tests/qp_problems.hpp, condensing
// included, blocks of 4 measured faster than pairs and than blocks of 8: each level halves the
// Riccati recursion's stages and grows the blocks it factors.
inline constexpr int kPairLevels = 2;
// ... and only while ε‖W‖∞‖Δv‖∞ · kRefineBoundSafety (an a-priori bound on the error, measured
// 1–3 orders of magnitude above the actual one on the test and controller QPs) exceeds the
// target; otherwise the error is not even measured.
inline constexpr double kRefineBoundSafety = 10.0;
// A bound whose magnitude is ≥ kInfBound is absent (one-sided constraints).
inline constexpr double kInfBound = 1e20;
}  // namespace qp_defaults

// Defaults of the offline Ipopt adapter (core/nlp/nlp_ipopt.hpp), SPEC §4: full NLPs to convergence.
namespace ipopt_defaults {
// Ipopt's `tol`: the scaled KKT error (stationarity, feasibility, complementarity) at exit.
inline constexpr double kTolerance = 1e-10;
inline constexpr int kMaxIterations = 1000;
// Ipopt's `print_level`: 0 prints nothing (the banner is suppressed too); 5 is Ipopt's usual log.
inline constexpr int kPrintLevel = 0;
// A bound whose magnitude is ≥ kInfBound is absent (the same convention as qp_defaults).
inline constexpr double kInfBound = 1e20;
// Central-difference step of the constraint-curvature Hessian, relative to max(1, |w_k|):
// ≈ ε^(1/3) balances the O(h²) truncation against the O(ε/h) rounding error.
inline constexpr double kCurvatureStep = 1e-5;
}  // namespace ipopt_defaults

// Defaults of the RTI solver (core/nlp/rti.hpp).
namespace rti_defaults {
// Warm-start each QP (primal-dual) from the previous, shifted QP solution: its active set and
// multipliers carry over between steps, so a step takes a few IPM iterations instead of a cold
// solve's many (measured on mi_helix, same trajectory).
inline constexpr bool kQpWarmStart = true;
}  // namespace rti_defaults

// OCP-QP solver variant of the RTI engine (core/qp/qp_solver.hpp, SPEC §4).
enum class QpSolverKind {
  riccati_ipm,      // structure-exploiting Riccati IPM: O(N) per iteration, any horizon
  riccati_ipm_pairs,  // the same behind partial condensing of stage pairs (condensing in
                      // prepare()): long horizons, cold or many-iteration solves
  condensed_dense,  // condensing + dense IPM: short horizons (≲ 10–20 stages, few inputs)
  condensed_active_set,  // condensing + warm-started dense active set (IPM fallback): short
                         // horizons in closed loop, where the active set rarely changes
};
namespace rti_defaults {
// Same iterates as riccati_ipm, and faster per step on every quadrotor mode (BM_Rti): half the
// Riccati stages, and the condensing moves into prepare(), out of the feedback phase.
inline constexpr QpSolverKind kQpSolver = QpSolverKind::riccati_ipm_pairs;
// One level of pairs in RTI: its warm-started QPs mostly take one or two iterations, too few to
// repay a second condensing level (BM_Rti/mi).
inline constexpr int kQpPairLevels = 1;
// SPEC §4's failure policy applies the previous plan's next input; after this many fallbacks in
// a row (QP failures or overruns: 75 ms of the quadrotor modes' 15 ms steps, half the
// Pendubot's 10-step plan) the plan is judged spent and the mode's safe controller flies, until
// the MPC has again solved this many steps in a row in time.
inline constexpr int kSafeAfterFallbacks = 5;
}  // namespace rti_defaults

// PH index of SPEC §5.4 (Table 7.1).
namespace ph_defaults {
inline constexpr double kRadius = 0.175;  // r [m]
inline constexpr int kHorizon = 10;       // N_b
inline constexpr double kMu1 = 0.99;
inline constexpr double kMu2 = 0.3;
inline constexpr double kTheta2 = 55.0;
inline constexpr double kZeta = 1e-13;
inline constexpr double kInitialLambda = 0.5;  // authority shared until a prediction exists
}  // namespace ph_defaults

// Mixed-initiative controller of SPEC §5.4.
namespace mi_defaults {
inline constexpr int kHorizon = 50;                 // N
inline constexpr double kDt = 0.015;                // [s], t_N = 0.75 s
inline constexpr int kMaxConstrainedObstacles = 4;  // nearest obstacles carried per step
inline constexpr double kVehicleRadius = 0.3;       // [m]
// Exact ℓ1 penalty above any multiplier the tracking cost can produce (SPEC §5.3 uses 14.5e3),
// plus a small ℓ2² term that keeps the slack Hessian positive.
inline constexpr double kSlackL1 = 1.45e4;
inline constexpr double kSlackL2 = 1e2;
// Back-off of the rotor-speed bounds: RTI meets them for the linearized prediction, and the
// C_D Ω² term adds up to C_D ΔΩ² Δt / J_m ≈ 1e-3 in one step, so the plant keeps its bounds.
inline constexpr double kRotorSpeedBackoff = 1e-3;
// A vehicle farther than this outside the arena's box is lost: the flight ends there [m].
inline constexpr double kLostMargin = 1.0;
// A probe flight (SPEC §10) pins λ = 1 for η and ν, which leaves e (ψ, v_b, ω → 0) and u with
// no weight either: the QP is then singular (measured on mi_helix: QP failures, the safe hold,
// the vehicle lost). It keeps them weighted as at λ = 1 − this (0.5: as at the initial λ).
// Measured on mi_helix, novice and experienced: 0.5 gives no fallback and no collision with the
// MPC following the pilot's attitude to 2e-3 rad rms; 0.05–0.3 and 1 still fail or touch.
inline constexpr double kProbeRegularization = 0.5;
}  // namespace mi_defaults

// Obstacle avoidance with the LCL constraint, SPEC §5.3 (thesis ch. 6).
namespace obstacle_defaults {
inline constexpr int kHorizon = 50;             // N
inline constexpr double kDt = 0.015;            // [s]
inline constexpr double kClearance = 0.2;       // d_C [m]
inline constexpr double kSlackL1Lower = 14.5e3;  // exact ℓ1 penalty, lower side (eq. 6.5)
inline constexpr double kSlackL1Upper = 14.2e3;  // upper side (inert: the upper side is absent)
// ℓ2² slack weight. SPEC §5.3 is pure ℓ1 (Z = 0): kept positive until the QP solver handles
// Z = 0 with an absent upper side. 100 as mi_defaults::kSlackL2: with Z = 1 the cold
// first QP of obstacles_thrown_balls (lcl) stops at min_step; the closed-loop minimum distances
// are the same to 0.01 mm for Z = 1, 10, 100 (the ℓ1 term keeps the slacks at zero).
inline constexpr double kSlackL2 = 100.0;
inline constexpr double kPlantRateHz = 1000.0;  // RK4 substeps per second of the plant
inline constexpr double kGravity = 9.81;        // [m/s²], thrown balls
inline constexpr double kViolationTolerance = 1e-3;  // a violation is ‖p − o‖ < d_C − 1 mm
}  // namespace obstacle_defaults

// Crazyflie tracking under delay, SPEC §5.2 (core/control/tracking.hpp).
namespace tracking_defaults {
inline constexpr int kHorizon = 50;                 // N
inline constexpr double kDt = 0.015;                // [s]
inline constexpr double kDuration = 8.0;            // [s]: the 6 s smooth step, then 2 s held
inline constexpr bool kCompensation = true;         // ERK4 predictor over the RTT
inline constexpr double kPlantRateHz = 1000.0;      // RK4 substeps per second of the plant
inline constexpr double kRtt = 0.0;                 // round-trip time τ_r [s]
inline constexpr double kMeasurementFraction = 0.5; // share of τ_r on the measurement side
// Helix of SPEC §5.2 (b): R 0.3 m, z0 0.38 m, +0.002 m per 15 ms, 15 s. The angular rate is not
// given (thesis §5.5.5): three turns in 15 s (0.38 m/s along the circle).
inline constexpr double kHelixRadius = 0.3;                  // [m]
inline constexpr double kHelixStartHeight = 0.38;            // [m]
inline constexpr double kHelixClimbRate = 0.002 / 0.015;     // [m/s]
inline constexpr double kHelixAngularRate = 1.2566370614359172;  // 2π/5 [rad/s]
inline constexpr double kHelixLength = 15.0;                 // [s] (1000 intervals of 15 ms)
// LQR baseline: R = 0.12·I4 (Q in TrackingLqr::q_diagonal()).
inline constexpr double kLqrR = 0.12;
// Settle time: ‖p − target‖ ≤ this for good [m].
inline constexpr double kSettleRadius = 0.05;
// A run is lost when the vehicle leaves this ball around its start [m].
inline constexpr double kLostRadius = 100.0;
}  // namespace tracking_defaults

// Pendubot swing-up of SPEC §5.1 (core/control/pendubot.hpp).
namespace pendubot_defaults {
inline constexpr int kHorizon = 10;             // N
inline constexpr double kDt = 0.002;            // [s]
inline constexpr double kInputBound = 0.4;      // |u| ≤ 0.4 N·m
inline constexpr double kVelocityBound1 = 7.8;  // |q̇1| ≤ 7.8 rad/s (soft)
inline constexpr double kVelocityBound2 = 5.0;  // |q̇2| ≤ 5 rad/s (soft)
inline constexpr double kSlackWeight = 40.0;    // ℓ2² slack weight ρ per bound side
// Plant: RK4 substeps (0.25 ms) with the input held over the control interval.
inline constexpr double kPlantRateHz = 4000.0;
// Success: ‖wrap(q1, q2)‖ ≤ kAngleTolerance [rad] from some time on, to the end of the run.
inline constexpr double kAngleTolerance = 0.05;
// LQR hand-over (core/modes/pendubot_mode.hpp, "switch rule"): enter when ‖wrap(q)‖ ≤ kLqrEnter
// and ‖q̇‖ ≤ kLqrEnterVelocity and |K x| ≤ u_max; leave when ‖wrap(q)‖ > kLqrExit.
inline constexpr double kLqrEnter = 0.25;          // [rad]
inline constexpr double kLqrEnterVelocity = 3.0;   // [rad/s]
inline constexpr double kLqrExit = 0.6;            // [rad]
// Encoders of the Quanser Pendubot (SPEC §5.1): counts per turn of q1 and q2.
inline constexpr int kEncoderCounts1 = 8192;
inline constexpr int kEncoderCounts2 = 4096;
// First-order low-pass on the differenced velocities when quantization is on [Hz] (0: none).
inline constexpr double kVelocityCutoffHz = 100.0;
// Model-based α-β observer on the encoder angles (sensor.estimator = "observer").
inline constexpr double kObserverAlpha = 0.2;
inline constexpr double kObserverBeta = 0.02;
}  // namespace pendubot_defaults

}  // namespace mixpilot
