#pragma once
// The block-banded OCP-QP of SPEC §4 (the QP one RTI step solves), independent of the solver.
//
//   min  Σ_{i=0..N} ½ [x_i;u_i]ᵀ [Q_i S_iᵀ; S_i R_i] [x_i;u_i] + q_iᵀx_i + r_iᵀu_i
//        + Σ_i ½ s_l,iᵀ diag(Zl_i) s_l,i + zl_iᵀ s_l,i + ½ s_u,iᵀ diag(Zu_i) s_u,i + zu_iᵀ s_u,i
//   s.t. x_0 = x0                                      (initial-value embedding)
//        x_{i+1} = A_i x_i + B_i u_i + b_i             (i < N)
//        lb_i − J_l,i s_l,i ≤ d_i(x_i, u_i) ≤ ub_i + J_u,i s_u,i,   s_l,i ≥ 0, s_u,i ≥ 0
//
// with the stacked constraint vector (HPIPM's order)
//   d_i = [ u_i[idxbu] (nbu) ; x_i[idxbx] (nbx) ; C_i x_i + D_i u_i (ng) ]   (nc = nbu+nbx+ng)
// and bounds lb_i = [lbu; lbx; lg], ub_i = [ubu; ubx; ug]. Soft constraint k = idxs[j] of d_i gets
// the slack pair (s_l[j], s_u[j]) with ℓ2² weights Zl, Zu ≥ 0 and ℓ1 weights zl, zu (both sides of
// a softened constraint are softened; a huge Z or z makes a side effectively hard). A bound whose
// magnitude is ≥ 1e20 (or ±inf) is absent: one-sided constraints.
//
// x_0 is fixed to `x0` and eliminated inside the solver, so the RTI feedback phase (SPEC §4) only
// writes `x0` before solving. Bounds on x_0 are allowed but, x_0 being fixed, they constrain nothing
// except through their slacks; the normal use is nbx[0] = 0.
#include <vector>

#include <Eigen/Core>

namespace mixpilot {

struct OcpQpDims {
  int N = 0;             // number of intervals; stages 0..N
  std::vector<int> nx;   // N+1: state dimension per stage
  std::vector<int> nu;   // N+1: input dimension per stage (usually nu[N] = 0)
  std::vector<int> nbx;  // N+1: number of state box bounds
  std::vector<int> nbu;  // N+1: number of input box bounds
  std::vector<int> ng;   // N+1: number of general constraints
  std::vector<int> ns;   // N+1: number of softened constraints

  OcpQpDims() = default;
  explicit OcpQpDims(int horizon);  // all dims zero, N = horizon

  // Same nx, nu on every stage except nu[N] = 0; nbx state bounds on stages 1..N only,
  // nbu input bounds on 0..N-1, ng general and ns soft constraints on every stage.
  static OcpQpDims uniform(int N, int nx, int nu, int nbx = 0, int nbu = 0, int ng = 0,
                           int ns = 0);

  int nc(int i) const { return nbu[i] + nbx[i] + ng[i]; }
  // Sizes consistent, non-negative, index counts within the variables they index.
  bool valid() const;
};

struct OcpQpStage {
  // Dynamics (i < N; empty on stage N).
  Eigen::MatrixXd A;  // nx_{i+1} x nx_i
  Eigen::MatrixXd B;  // nx_{i+1} x nu_i
  Eigen::VectorXd b;  // nx_{i+1}
  // Cost; Q and R must be symmetric (the factorization reads their lower triangles, the
  // residuals the full matrices).
  Eigen::MatrixXd Q;  // nx x nx
  Eigen::MatrixXd S;  // nu x nx
  Eigen::MatrixXd R;  // nu x nu
  Eigen::VectorXd q;  // nx
  Eigen::VectorXd r;  // nu
  // Box bounds lbu ≤ u[idxbu] ≤ ubu, lbx ≤ x[idxbx] ≤ ubx.
  Eigen::VectorXi idxbu;  // nbu, entries in [0, nu)
  Eigen::VectorXd lbu;    // nbu
  Eigen::VectorXd ubu;    // nbu
  Eigen::VectorXi idxbx;  // nbx, entries in [0, nx)
  Eigen::VectorXd lbx;    // nbx
  Eigen::VectorXd ubx;    // nbx
  // General constraints lg ≤ C x + D u ≤ ug.
  Eigen::MatrixXd C;   // ng x nx
  Eigen::MatrixXd D;   // ng x nu
  Eigen::VectorXd lg;  // ng
  Eigen::VectorXd ug;  // ng
  // Soft constraints: idxs[j] ∈ [0, nc) indexes d_i; slack weights per side.
  Eigen::VectorXi idxs;  // ns, distinct
  Eigen::VectorXd Zl;    // ns, ≥ 0
  Eigen::VectorXd Zu;    // ns, ≥ 0
  Eigen::VectorXd zl;    // ns
  Eigen::VectorXd zu;    // ns
};

struct OcpQp {
  OcpQpDims dims;
  std::vector<OcpQpStage> stage;  // N+1
  Eigen::VectorXd x0;             // nx_0: the fixed initial state

  OcpQp() = default;
  explicit OcpQp(const OcpQpDims& d) { resize(d); }
  // Sizes every member from d and fills it with neutral values: zero matrices and vectors,
  // idxbu/idxbx = 0, 1, 2, ..., absent bounds (∓inf), idxs = 0, 1, 2, ..., zero slack weights.
  void resize(const OcpQpDims& d);
  // ½vᵀHv + gᵀv summed over stages plus slack costs, at the given primal point.
  double objective(const std::vector<Eigen::VectorXd>& x, const std::vector<Eigen::VectorXd>& u,
                   const std::vector<Eigen::VectorXd>& sl,
                   const std::vector<Eigen::VectorXd>& su) const;
};

// Validity checks shared by the solvers (qp's own dims): indices within the variables and
// constraints they index; no NaN/Inf in the data (bounds may be ±inf: absent sides, not NaN).
bool ocp_qp_indices_valid(const OcpQp& qp);
bool ocp_qp_data_finite(const OcpQp& qp);
// Same sizes everywhere (N, nx, nu, nbx, nbu, ng, ns).
bool ocp_qp_dims_equal(const OcpQpDims& a, const OcpQpDims& b);
// The input check every solver starts with: qp has the setup dims, valid indices and, when
// check_data, no NaN/Inf.
bool ocp_qp_valid_for(const OcpQp& qp, const OcpQpDims& dims, bool check_data);

enum class QpStatus {
  success,               // all residuals below their tolerances
  max_iterations,        // iteration limit reached; the last iterate is returned
  min_step,              // the step length fell below the minimum: no progress possible
                         // (typically infeasible hard constraints)
  nan_detected,          // a NaN/Inf appeared in an iterate's direction; the last finite
                         // iterate is returned
  factorization_failed,  // a Riccati block is not positive definite: the (reduced) Hessian is
                         // singular or indefinite on the inputs
  invalid_data,          // NaN/Inf in the QP data, or data not matching the solver's dims
};

const char* to_string(QpStatus status);

// Solution, and the warm-start input of the next solve. The Lagrangian is
//   L = f + Σ_i π_iᵀ(A_i x_i + B_i u_i + b_i − x_{i+1}) − λ_x0ᵀ(x_0 − x0)
//       − Σ_i [ λ_l,iᵀ(d_i − lb_i + J_l s_l) + λ_u,iᵀ(ub_i − d_i + J_u s_u)
//               + λ_sl,iᵀ s_l + λ_su,iᵀ s_u ],
// all λ ≥ 0 (HPIPM's signs). Absent bound sides have λ = 0.
struct OcpQpSolution {
  std::vector<Eigen::VectorXd> x;       // N+1 x nx_i (x[0] = x0)
  std::vector<Eigen::VectorXd> u;       // N+1 x nu_i
  std::vector<Eigen::VectorXd> pi;      // N   x nx_{i+1}: dynamics multipliers
  std::vector<Eigen::VectorXd> lam_l;   // N+1 x nc_i: lower sides of d_i = [bu; bx; g]
  std::vector<Eigen::VectorXd> lam_u;   // N+1 x nc_i: upper sides
  std::vector<Eigen::VectorXd> sl;      // N+1 x ns_i: lower slacks
  std::vector<Eigen::VectorXd> su;      // N+1 x ns_i: upper slacks
  std::vector<Eigen::VectorXd> lam_sl;  // N+1 x ns_i: multipliers of s_l ≥ 0
  std::vector<Eigen::VectorXd> lam_su;  // N+1 x ns_i: multipliers of s_u ≥ 0
  Eigen::VectorXd lam_x0;               // nx_0: multiplier of x_0 = x0; ∂(optimal value)/∂x0

  QpStatus status = QpStatus::invalid_data;
  int iterations = 0;
  double objective = 0.0;
  // Residuals of the returned iterate (∞-norms; comp is the mean complementarity tᵀλ/m).
  double res_stat = 0.0;
  double res_eq = 0.0;
  double res_ineq = 0.0;
  double res_comp = 0.0;

  OcpQpSolution() = default;
  explicit OcpQpSolution(const OcpQpDims& d) { resize(d); }
  void resize(const OcpQpDims& d);  // sizes and zeroes everything
  // A solver's answer to invalid input: every output zero, status invalid_data (returned).
  QpStatus set_invalid_data();
};

}  // namespace mixpilot
