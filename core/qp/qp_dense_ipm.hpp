#pragma once
// Dense primal-dual interior point for a QP in one block of variables u: the one-stage OcpQp
// (N = 0, nx = 0) that condensing produces (core/qp/qp_condensed_dense.hpp),
//
//   min ½uᵀRu + rᵀu + Σ_j ½Zl s_l² + zl s_l + ½Zu s_u² + zu s_u
//   s.t. lb − J_l s_l ≤ d(u) = [u[idxbu]; D u] ≤ ub + J_u s_u,   s ≥ 0 (where it matters).
//
// The algorithm is that of core/qp/qp_riccati_ipm.hpp on such a QP as of 0a53bf5 (Mehrotra
// predictor-corrector, the same slack elimination, starting points, warm starts, iterative
// refinement, tolerances and statuses; see the notation there) with the fixed step fraction;
// the Riccati IPM's later step-length heuristic and centring floor (1867f26) are not ported yet.
// Only the linear algebra differs: the reduced Hessian
//   H̃ = R + Σ_box W̃_k e_k e_kᵀ + Dᵀ diag(W̃_g) D
// is formed and Cholesky-factored in place with plain loops on the actual sizes (no padding,
// no per-stage bookkeeping, no Eigen temporaries), and the rank-one updates of the general rows
// skip each row's trailing zeros: the condensed state rows are causal (row of stage i has
// nonzeros only in the columns of u_0..u_{i−1}), which halves the work of forming H̃.
//
// setup() sizes every buffer; solve() allocates nothing, throws nothing, prints nothing.
#include <Eigen/Core>

#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_solver.hpp"

namespace mixpilot {

struct QpDenseIpmWorkspace {
  OcpQpDims dims;
  int n = 0, nb = 0, ng = 0, nc = 0, ns = 0, m = 0;  // m = 2 nc + 2 ns inequalities
  int m_total = 0;                                   // present inequalities
  Eigen::MatrixXd Dt;     // n x ng: Dᵀ (row k of D contiguous)
  Eigen::VectorXi len;    // ng: 1 + index of the last nonzero of row k of D (0 for a zero row)
  Eigen::MatrixXd L;      // n x n: H̃, then its lower Cholesky factor
  Eigen::VectorXd hdiag;     // n: diag(H̃) before the factorization (pivot rule)
  Eigen::VectorXd inv_diag;  // n: 1 / diag(L), 0 for a zeroed pivot
  Eigen::VectorXi box;    // nb: variable of each box
  Eigen::VectorXi soft_of;  // nc: slack j of constraint k, or −1
  // Iterate [s = (s_l; s_u)], [t, λ = (lb (nc); ub (nc); ls (ns); us (ns))] and directions.
  Eigen::VectorXd u, du, s, ds, t, dt, lam, dlam;
  Eigen::VectorXd res_u, res_s, res_t;  // stationarity in u and s; inequality residual d − t
  Eigen::VectorXd zflat;                // 2 ns: [zl; zu]
  Eigen::VectorXd lbnd, ubnd;           // nc: bounds, 0 where absent
  Eigen::VectorXd mask;                 // m: 1 present, 0 absent
  Eigen::VectorXd w, rc, rho;           // m: λ/t, complementarity rhs, r_c/t + W r_t
  Eigen::VectorXd inv_t, inv_lam;       // m: 1/t, 1/λ (0 where absent) of the iterate
  Eigen::VectorXd wc, gc, dd;           // nc: W̃, g̃, ∇d Δu (and d(u))
  Eigen::VectorXd psi_l, psi_u;         // ns: Ψ⁻¹
  Eigen::VectorXd l;                    // n: right-hand side / solution of the reduced system
  Eigen::VectorXd err_u, err_s, cu, cs, ct, clam, zero_m;  // iterative refinement
};

class QpDenseIpm final : public QpSolver {
 public:
  using Settings = QpSettings;
  using Workspace = QpDenseIpmWorkspace;

  QpDenseIpm() = default;
  explicit QpDenseIpm(const OcpQpDims& dims, const Settings& settings = {}) {
    setup(dims, settings);
  }

  // Accepts only one-stage dims without states (N = 0, nx[0] = 0); false otherwise.
  bool setup(const OcpQpDims& dims, const Settings& settings = {}) override;
  QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                 QpWarmStart warm = QpWarmStart::cold) override;

  Settings& settings() override { return settings_; }
  const Settings& settings() const override { return settings_; }
  const OcpQpDims& dims() const override { return ws_.dims; }

 private:
  void load(const OcpQpStage& st);
  void initialize(const OcpQpStage& st, const OcpQpSolution& sol, QpWarmStart warm);
  // out_u = R v + g + ∇dᵀ(λ_ub − λ_lb),  out_s = Z s + z − J λ_b − λ_s (both sides).
  void linear_residual(const OcpQpStage& st, const double* v, const double* s, const double* lam,
                       const double* g, const double* z, double* out_u, double* out_s) const;
  void constraints(const OcpQpStage& st, const double* v, double* dd) const;  // d(v), nc
  void residuals(const OcpQpStage& st);
  double stationarity_norm(const double* ru, const double* rs) const;
  bool factorize(const OcpQpStage& st);
  void solve_direction(const OcpQpStage& st, const double* ru, const double* rs,
                       const double* rt, const double* rc, double* du, double* ds, double* dt,
                       double* dlam);
  void newton_direction(const OcpQpStage& st, bool final, bool refine);
  void write_solution(const OcpQpStage& st, OcpQpSolution& sol);

  Settings settings_{};
  Workspace ws_{};
  bool ready_ = false;
  double res_stat_ = 0, res_ineq_ = 0, mu_ = 0;
};

}  // namespace mixpilot
