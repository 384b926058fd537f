#pragma once
// Common interface of the OCP-QP solvers (SPEC §4): the structure-exploiting Riccati IPM
// (core/qp/qp_riccati_ipm.hpp, the default, O(N) per iteration) and condensing + a dense IPM
// (core/qp/qp_condensed_dense.hpp, for short horizons, where the Riccati recursion's per-stage
// overhead dominates), and the Riccati IPM behind partial condensing of stage pairs
// (core/qp/qp_riccati_ipm_pairs.hpp, half the recursion's sequential steps). All solve the OcpQp of
// core/qp/ocp_qp.hpp to the same tolerances and return the same OcpQpSolution layout, so RtiSolver
// can use any of them (RtiSettings::qp_solver).
//
// Contract of every implementation: setup() sizes every buffer (may allocate); prepare() and
// solve() never allocate, throw or print; solve() returns a QpStatus and, on any status other
// than success, leaves the last finite iterate (or zeros for invalid_data) in the solution, never
// NaN.
#include "core/qp/ocp_qp.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

// Interior-point settings. Both variants run the same primal-dual Mehrotra IPM (the dense one on
// the condensed QP), so they share these settings and their defaults (core/numerics/types.hpp).
struct QpRiccatiIpmSettings {
  int max_iterations = qp_defaults::kMaxIterations;
  double tol_stat = qp_defaults::kTolStationarity;
  double tol_eq = qp_defaults::kTolEquality;
  double tol_ineq = qp_defaults::kTolInequality;
  double tol_comp = qp_defaults::kTolComplementarity;
  double step_fraction = qp_defaults::kStepFraction;
  double min_step = qp_defaults::kMinStep;
  double init_slack = qp_defaults::kInitSlack;
  double init_mu = qp_defaults::kInitMu;
  double warm_start_floor = qp_defaults::kWarmStartFloor;              // λ
  double warm_start_slack_floor = qp_defaults::kWarmStartSlackFloor;  // t
  double warm_start_violated = qp_defaults::kWarmStartViolated;       // t of a violated hard row
  double psd_tol = qp_defaults::kPsdTol;
  double inf_bound = qp_defaults::kInfBound;
  // Iterative refinement of each iteration's final Newton direction: at most refinement_steps,
  // while the linear-solve error (∞-norm) exceeds refine_ratio · min(tol_stat, tol_eq).
  int refinement_steps = qp_defaults::kRefinementSteps;
  double refine_ratio = qp_defaults::kRefineRatio;
  bool check_data = true;  // scan the QP data for NaN/Inf before solving
};
using QpSettings = QpRiccatiIpmSettings;

enum class QpWarmStart {
  cold,         // x = 0 (x_0 = x0), u = 0, slacks and multipliers from init_slack / init_mu
  primal,       // x, u, s_l, s_u taken from the solution argument; multipliers cold
  primal_dual,  // also π, λ taken from the solution argument (clipped to be interior)
};

class QpSolver {
 public:
  virtual ~QpSolver() = default;

  // Sizes every buffer for dims. Returns false (and solve() then returns invalid_data) when the
  // dims are not valid().
  virtual bool setup(const OcpQpDims& dims, const QpSettings& settings) = 0;

  // Optional preparation phase (RTI, SPEC §4): the work on qp that does not depend on x0. The
  // next solve() of the same qp — only x0 may have changed in between — reuses it; a solve()
  // without a preceding prepare() does all the work itself. The Riccati IPM takes the QP data
  // into its own layout here; partial condensing condenses.
  virtual void prepare(const OcpQp& qp) { (void)qp; }
  // The same, knowing the warm start of that next solve() (in RTI the shifted previous
  // solution, known before x̄_0): a solver may also do the x0-free part of its first iteration.
  // The Riccati IPM, warm-started primal-dual, factorizes the first Newton system of every stage
  // but stage 0 here (their W = λ/t and Hessians do not involve x0; x_0 only enters stage 0's
  // constraints) and computes those stages' residuals and the predictor's backward pass through
  // them (neither reads x_0), so the feedback phase starts its first iteration at stage 0. The
  // next solve() must be given the same start and warm.
  virtual void prepare(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) {
    (void)start;
    (void)warm;
    prepare(qp);
  }

  // Solves qp (dims equal to the setup dims) into sol (sized with the same dims; read as the
  // warm start when requested).
  virtual QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                         QpWarmStart warm = QpWarmStart::cold) = 0;

  virtual QpSettings& settings() = 0;
  virtual const QpSettings& settings() const = 0;
  virtual const OcpQpDims& dims() const = 0;
};

}  // namespace mixpilot
