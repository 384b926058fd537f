#pragma once
// Condensing + dense interior point for short horizons (SPEC §4: "Condensing (+ dense solver) is
// an optional alternative for short horizons"). The states are eliminated with the dynamics,
//   x_i = Γ_i U + ξ_i,   U = [u_0; …; u_N],   ξ_0 = x0, ξ_{i+1} = A_i ξ_i + b_i,
// leaving a dense QP in U alone (nU = Σ nu_i variables) with the input bounds as boxes, every
// state-dependent row (state bounds and C x + D u) as a dense general row, and the same soft
// constraints with the same slacks. That QP is posed as a one-stage OcpQp (N = 0, nx = 0) and
// solved by core/qp/qp_dense_ipm.hpp: the Mehrotra IPM of core/qp/qp_riccati_ipm.hpp (same
// soft-constraint handling, refinement, statuses and tolerances) with dense linear algebra on
// the actual sizes, a Cholesky of the condensed Hessian plus the barrier terms per iteration.
//
// Hessian condensing, O(N² nx² nu) (Frison's backward scheme): with the cost-to-go of the tail
// written as a quadratic in (x_k, U_k = [u_k; …; u_N]) with blocks P_k (x x), M_k (U_k x),
//   P_k = Q_k + A_kᵀP_{k+1}A_k,   M_k = [S_k + B_kᵀP_{k+1}A_k; M_{k+1}A_k],
//   H[u_k, u_k] = R_k + B_kᵀP_{k+1}B_k,   H[U_{k+1}, u_k] = M_{k+1}B_k,
// and the linear terms (for x0 = 0; b enters here) p_k, h_k likewise; the gradient is then
// h_0 + M_0 x0. x0 enters only that gradient and the state rows' bounds (via ξ), so prepare()
// condenses everything else before x0 is known (the RTI preparation phase), and solve() adds the
// O(N nx² + nU nx) x0 part. When every stage has (nx, nu) = (4, 1) (the Pendubot), the backward
// and Γ recursions run on compile-time-sized Eigen maps, whose small products the compiler
// unrolls. The multipliers are mapped back; the states are recovered by a forward
// simulation (dynamics exact) and π_i, λ_x0 by the backward pass of the x-stationarity
//   π_{i−1} = Q_i x_i + S_iᵀu_i + q_i + A_iᵀπ_i + ∇_x d_iᵀ(λ_u,i − λ_l,i),
// so the OcpQpSolution is complete and its KKT residuals equal those of the condensed QP.
//
// The dense QP is solved by the IPM, or (CondensedQpMethod::active_set) by the warm-started
// primal-dual active-set method of core/qp/qp_dense_active_set.hpp, which in closed loop confirms
// the previous active set with one or two factorizations; whenever it fails (iteration limit,
// dependent active rows, unsupported slack weights) the IPM solves the QP from the same warm
// start.
//
// setup() sizes every buffer; prepare() and solve() allocate nothing.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_dense_active_set.hpp"
#include "core/qp/qp_dense_ipm.hpp"
#include "core/qp/qp_solver.hpp"

namespace mixpilot {

struct QpCondensedDenseWorkspace {
  OcpQpDims dims;              // the OCP-QP's
  OcpQpDims cdims;             // condensed: N = 0, nx = 0, nu = nU, nbu = Σ nbu, ng = Σ (nbx + ng),
                               // ns = Σ ns
  std::vector<int> off_u;      // N+1: offset of u_i in U
  std::vector<int> off_bu;     // N+1: offset of stage i's input bounds among the condensed boxes
  std::vector<int> off_g;      // N+1: offset of stage i's rows (nbx, then ng) among the general rows
  std::vector<int> off_s;      // N+1: offset of stage i's slacks
  std::vector<int> off_x;      // N+1: offset of x_i in the flat xi
  std::vector<Eigen::MatrixXd> Gam;  // N+1 x (nx_i x nU): ∂x_i/∂U (columns ≥ off_u[i] zero)
  Eigen::MatrixXd P, P1;       // nx_max x nx_max: P_{k+1}, P_k (swapped per stage)
  Eigen::MatrixXd M, M1;       // nU x nx_max: M_{k+1}, M_k (rows off_u[k].. used)
  Eigen::MatrixXd M0;          // nU x nx_0: M_0, the x0 → gradient map
  Eigen::MatrixXd PA;          // nx_max x nx_max: P_{k+1} A_k
  Eigen::MatrixXd PB;          // nx_max x nu_max: P_{k+1} B_k
  Eigen::VectorXd p, p1;       // nx_max: linear terms in x_{k+1}, x_k
  Eigen::VectorXd pb;          // nx_max: p_{k+1} + P_{k+1} b_k
  Eigen::VectorXd h;           // nU: linear term in U for x0 = 0
  Eigen::VectorXd xi;          // Σ nx_i: free trajectory ξ (U = 0) for the current x0
  Eigen::VectorXd gx;          // nx_max: x-stationarity of one stage (π recovery)
  Eigen::VectorXd gu;          // nu_max: scratch of the objective
  Eigen::VectorXd dl;          // nc_max: λ_u − λ_l of one stage
  bool uniform = false;        // nx_i = nx_0, nu_i = nu_0 (i < N), nu_N = 0
  OcpQp cqp;                   // the condensed QP (dims cdims)
  OcpQpSolution csol;          // its solution (and warm start)
};

enum class CondensedQpMethod {
  ipm,         // QpDenseIpm
  active_set,  // QpDenseActiveSet, QpDenseIpm as fallback
};

class QpCondensedDense final : public QpSolver {
 public:
  using Settings = QpSettings;
  using Workspace = QpCondensedDenseWorkspace;

  QpCondensedDense() = default;
  explicit QpCondensedDense(const OcpQpDims& dims, const Settings& settings = {},
                            CondensedQpMethod method = CondensedQpMethod::ipm)
      : method_(method) {
    setup(dims, settings);
  }

  // Dense QP method of the following setup() calls.
  void set_method(CondensedQpMethod method) { method_ = method; }
  CondensedQpMethod method() const { return method_; }
  // Number of solves the active-set method handed over to the IPM since setup().
  std::int64_t ipm_fallbacks() const { return ipm_fallbacks_; }

  bool setup(const OcpQpDims& dims, const Settings& settings = {}) override;
  // Condenses the Hessian, the x0-free linear terms and the constraint rows of qp.
  using QpSolver::prepare;
  void prepare(const OcpQp& qp) override;
  QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                 QpWarmStart warm = QpWarmStart::cold) override;

  Settings& settings() override { return settings_; }
  const Settings& settings() const override { return settings_; }
  const OcpQpDims& dims() const override { return ws_.dims; }
  const OcpQp& condensed_qp() const { return ws_.cqp; }

 private:
  void condense(const OcpQp& qp);
  void embed_x0(const OcpQp& qp);
  void warm_start(const OcpQpSolution& sol, QpWarmStart warm);
  void recover(const OcpQp& qp, OcpQpSolution& sol);

  Settings settings_{};
  Workspace ws_{};
  QpDenseIpm ipm_;
  QpDenseActiveSet active_set_;
  CondensedQpMethod method_ = CondensedQpMethod::ipm;
  std::int64_t ipm_fallbacks_ = 0;
  bool ready_ = false;
  bool prepared_ = false;  // condense() done by prepare() for the next solve()
};

}  // namespace mixpilot
