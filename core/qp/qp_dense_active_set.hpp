#pragma once
// Dense primal-dual active-set method (semismooth Newton on the KKT conditions, Hintermüller–
// Ito–Kunisch) for the one-stage, state-free OcpQp that condensing produces
// (core/qp/qp_condensed_dense.hpp), the same problem as core/qp/qp_dense_ipm.hpp:
//
//   min ½uᵀRu + rᵀu + Σ_j ½Zl s_l² + zl s_l + ½Zu s_u² + zu s_u
//   s.t. lb − J_l s_l ≤ d(u) = [u[idxbu]; D u] ≤ ub + J_u s_u,   s ≥ 0.
//
// The slacks are eliminated exactly: for Z ≥ 0, z ≥ 0 the upper side of a soft row costs
// ψ(v) = ½Z v₊² + z v₊ in its violation v = d − ub, so its multiplier is λ = Z v + z for v > 0,
// any λ ∈ [0, z] at v = 0, and 0 for v < 0 (lower side likewise with v = lb − d). Every side of
// every row is therefore in one of three states:
//   inactive  λ = 0,                 row dropped;
//   hold      d = bound,             λ free (an equality; a hard row's only active state);
//   penalty   λ = z + Z v,           soft rows only: adds Z aaᵀ to the Hessian, a(z − Z b) to g.
// One iteration solves the equality-constrained QP of the current states — boxes in hold fix
// their variable, the free block H̃_FF = (R + Σ_pen Z aaᵀ)_FF is Cholesky-factored, general rows
// in hold enter through their Schur complement (A_h H̃_FF⁻¹ A_hᵀ) — then moves every side whose
// state the solution contradicts (violated inactive side → hold (penalty if z = 0); hold side
// with λ < 0 → inactive, with λ > z → penalty; penalty side with v < 0 → hold (inactive if
// z = 0)), with the tolerances tol_ineq on v and tol_stat on λ; violated general rows enter the
// hold set one per iteration (the most violated relative to ‖a‖), since the many rows a cold
// start violates are typically dependent. When no state moves, the
// iterate is the exact KKT point of the QP (residuals at rounding level), complementarity holds
// by construction. Warm start: the states are read from the solution passed in (multipliers and
// slacks), so in closed loop, where the active set rarely changes, one iteration — one
// factorization — confirms it.
//
// A hold row that is linearly dependent on the others (or a second bound fixing a variable) is
// dropped and the iteration repeated. The method is not globally convergent (it may cycle on
// adversarial QPs): it stops after max_iterations with max_iterations (min_step if the last
// iteration dropped a row: typically infeasible hard constraints), factorization_failed (H̃_FF
// not positive definite) or invalid_data (also for negative slack weights, which it does not
// support); the caller then falls back to QpDenseIpm (QpCondensedDense does). The solution
// argument then holds the last finite iterate, never NaN.
//
// setup() sizes every buffer; solve() allocates nothing, throws nothing, prints nothing.
#include <Eigen/Core>

#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_solver.hpp"

namespace mixpilot {

struct QpDenseActiveSetWorkspace {
  OcpQpDims dims;
  int n = 0, nb = 0, ng = 0, nc = 0, ns = 0;
  const double* D = nullptr;  // the QP's D (ng x n, column-major), during solve()
  Eigen::VectorXi box;      // nb: variable of each box
  Eigen::VectorXi soft_of;  // nc: slack j of row k, or −1
  Eigen::VectorXd bnd;      // 2 nc: [lb; ub], 0 where absent
  Eigen::VectorXi present;  // 2 nc: side present
  Eigen::VectorXd Zs, zs;   // 2 nc: slack weights per side (0 for hard rows)
  Eigen::VectorXi state;    // 2 nc: 0 inactive, 1 hold, 2 penalty
  Eigen::VectorXd lam;      // 2 nc: multipliers [λ_l; λ_u]
  Eigen::VectorXd d;        // nc: d(u)
  Eigen::MatrixXd H;        // n x n: H̃ = R + Σ_pen Z aaᵀ
  Eigen::VectorXd g;        // n: g̃ = r + Σ_pen a(z − Z b) (signs per side)
  Eigen::MatrixXd L;        // n x n: Cholesky factor of H̃_FF (nf x nf used)
  Eigen::VectorXi fixed;    // n: side index (0..2nc) of the box fixing variable c, or −1
  Eigen::VectorXi freev;    // n: free variables
  Eigen::VectorXi fixv;     // n: fixed variables
  Eigen::VectorXi hold;     // nc: sides of general rows in hold
  int nf = 0, nfix = 0, nh = 0;  // free variables, fixed variables, general rows in hold
  Eigen::MatrixXd Y;        // n x ng: L⁻¹ a_h (nf x nh used)
  Eigen::MatrixXd S;        // ng x ng: YᵀY, then its Cholesky factor
  Eigen::VectorXd u, y, nu, grad;  // n, n, ng, n
  Eigen::VectorXd dl;              // ng: λ_u − λ_l of the general rows
};

class QpDenseActiveSet final : public QpSolver {
 public:
  using Settings = QpSettings;
  using Workspace = QpDenseActiveSetWorkspace;

  QpDenseActiveSet() = default;
  explicit QpDenseActiveSet(const OcpQpDims& dims, const Settings& settings = {}) {
    setup(dims, settings);
  }

  // Accepts only one-stage dims without states (N = 0, nx[0] = 0); false otherwise.
  bool setup(const OcpQpDims& dims, const Settings& settings = {}) override;
  // max_iterations counts active-set iterations (factorizations).
  QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                 QpWarmStart warm = QpWarmStart::cold) override;

  Settings& settings() override { return settings_; }
  const Settings& settings() const override { return settings_; }
  const OcpQpDims& dims() const override { return ws_.dims; }

 private:
  bool load(const OcpQpStage& st);
  void initialize(const OcpQpStage& st, const OcpQpSolution& sol, QpWarmStart warm);
  QpStatus solve_states(const OcpQpStage& st);  // u, λ of the current states
  void assemble(const OcpQpStage& st);           // H̃, g̃ of the penalty sides
  QpStatus factor_free();                        // fixed boxes, chol(H̃_FF), y = L⁻¹(...)
  QpStatus project_holds();                      // general rows in hold (Schur complement)
  QpStatus recover();                            // u, d(u), multipliers
  bool update_states();                          // true when some state moved
  void write_solution(const OcpQpStage& st, OcpQpSolution& sol);

  Settings settings_{};
  Workspace ws_{};
  bool ready_ = false;
};

}  // namespace mixpilot
