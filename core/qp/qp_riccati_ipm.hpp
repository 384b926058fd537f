#pragma once
// Structure-exploiting OCP-QP solver (SPEC §4): primal-dual interior point with Mehrotra's
// predictor-corrector, one Riccati factorization per iteration (HPIPM-style square-root form,
// Frison & Diehl 2020), soft-constraint slacks eliminated stage-wise.
//
// Newton system of one iteration. With t the inequality slacks and λ their multipliers,
// W = λ/t, the inequality and slack directions are eliminated per stage (see the .cpp), leaving
// the equality-constrained QP in (Δx, Δu)
//   min Σ ½ Δvᵢᵀ H̃ᵢ Δvᵢ + g̃ᵢᵀΔvᵢ   s.t. Δx_{i+1} = AᵢΔxᵢ + BᵢΔuᵢ + r_dyn,ᵢ,  Δx_0 = 0,
// H̃ᵢ = Hᵢ + ∇dᵢᵀ W̃ᵢ ∇dᵢ, which the Riccati recursion solves in O(N (nx+nu)³) without ever forming
// the banded KKT matrix. The factorization is reused for predictor and corrector.
//
// setup() sizes every buffer; solve() allocates nothing.
#include <vector>

#include <Eigen/Core>

#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_solver.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

// Per-stage and flat buffers of the solver; sized by QpRiccatiIpm::setup(). Flat vectors hold
// all stages back to back at the offsets below.
struct QpRiccatiIpmWorkspace {
  OcpQpDims dims;
  // Per-stage sizes and offsets into the flat vectors.
  std::vector<int> nv;    // nu_i + nx_i (stage variable v_i = [u_i; x_i])
  std::vector<int> nc;    // nbu + nbx + ng
  std::vector<int> off_v;    // into v, dv, res_v, grad
  std::vector<int> off_pi;   // into pi, dpi, res_pi (stages 0..N-1)
  std::vector<int> off_s;    // into s, ds, res_s: [s_l (ns); s_u (ns)]
  std::vector<int> off_m;    // into t, lam, ...: [lb (nc); ub (nc); ls (ns); us (ns)]
  std::vector<int> off_c;    // into flat per-constraint vectors (nc)
  std::vector<Eigen::VectorXi> var_of_box;  // nbu+nbx: index into v_i of each box constraint
  std::vector<Eigen::VectorXi> soft_of;     // nc: slack index j of constraint k, or -1
  // Matrices used by the register-blocked kernels have their row count padded to a multiple of 4
  // (np = pad4(nu+nx)); padding rows are zero.
  std::vector<Eigen::MatrixXd> BAt;         // np x nx_{i+1}: [Bᵀ; Aᵀ]
  std::vector<Eigen::MatrixXd> Hbase;       // np x (nu+nx): [R S; Sᵀ Q], lower triangle only
  std::vector<Eigen::MatrixXd> DCt;         // (nu+nx) x ng: [Dᵀ; Cᵀ]
  std::vector<Eigen::MatrixXd> L;           // np x (nu+nx): H̃ + Y Yᵀ, then its lower Cholesky
                                            // factor, strict upper triangle zero (stage 0: uu
                                            // block only)
  std::vector<Eigen::MatrixXd> Y;           // np x (nx_{i+1} + ng): [BAt · Lx_{i+1}, ∇gᵀ W̃^½]
  std::vector<Eigen::VectorXd> inv_diag;    // nu+nx: 1 / diag(L)
  std::vector<double> pivot_floor;          // psd_tol · the largest |diagonal| of [R S; Sᵀ Q]
                                            // (1 if none): the pivot of a direction without
                                            // curvature
  std::vector<Eigen::MatrixXd> Dinv;        // max(np, 4) x 4: inverses of L's 4 x 4 diagonal
                                            // blocks (rows jb..jb+3 for block jb)
  std::vector<Eigen::VectorXd> tmp;         // max(nx_{i+1}, nc): scratch per stage

  // Iterate and direction (flat).
  Eigen::VectorXd v, dv, pi, dpi, s, ds, t, dt, lam, dlam;
  // Residuals: stationarity in v and s, dynamics, inequalities (constraint − t).
  Eigen::VectorXd res_v, res_s, res_pi, res_t;
  // Linear terms of the QP, flat: g = [r; q] per stage, z = [zl; zu], b.
  Eigen::VectorXd gflat, zflat, bflat;
  // Iterative refinement: error of a computed direction, the correction, zero right-hand sides.
  Eigen::VectorXd err_v, err_s, err_pi, cv, cpi, cs, ct, clam, zero_m;
  Eigen::VectorXd lbnd, ubnd;   // per constraint (flat nc): bound values, 0 where absent
  Eigen::VectorXd mask;         // per inequality (flat m): 1 present, 0 absent
  Eigen::VectorXd w;            // per inequality: λ/t (0 where absent)
  Eigen::VectorXd inv_t;        // per inequality: 1/t (0 where absent), set by factorize()
  Eigen::VectorXd rc;           // per inequality: complementarity right-hand side
  Eigen::VectorXd rho;          // per inequality: r_c/t + W r_t
  Eigen::VectorXd wc;           // per constraint: effective weight W̃ after slack elimination
  Eigen::VectorXd gc;           // per constraint: effective gradient term
  Eigen::VectorXd dd;           // per constraint: ∇d Δv (and d at the iterate)
  Eigen::VectorXd psi_l, psi_u;  // per slack: Zl + W_lb + W_ls etc. (inverted; 0 if dead)
  Eigen::VectorXd slive;        // per slack side (flat [s_l; s_u]): 1, or 0 when the side's
                                // bound is absent (the slack is decoupled: "dead")
  Eigen::VectorXd sfix;         // per slack side: a dead side's closed-form value max(0, −z/Z)
  Eigen::VectorXd l;            // per stage variable: L⁻¹(gradient) of the backward pass
  Eigen::VectorXd dt_aff, dlam_aff;
  int m_total = 0;  // number of present inequalities (for the mean complementarity)
};

class QpRiccatiIpm final : public QpSolver {
 public:
  using Settings = QpRiccatiIpmSettings;
  using Workspace = QpRiccatiIpmWorkspace;

  QpRiccatiIpm() = default;
  explicit QpRiccatiIpm(const OcpQpDims& dims, const Settings& settings = {}) {
    setup(dims, settings);
  }

  // Sizes every buffer for dims. Returns false (and solve() then returns invalid_data) when the
  // dims are not valid().
  bool setup(const OcpQpDims& dims, const Settings& settings = {}) override;

  // Takes qp's data into the solver's layout (the x0-free part of a solve): the next solve()
  // of qp — only x0 may have changed — starts from it.
  void prepare(const OcpQp& qp) override;
  // ... and, for a primal-dual warm start, initializes from `start`, factorizes the first
  // Newton system of stages N..1 and does their part of its predictor (QpSolver::prepare).
  void prepare(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) override;

  // Solves qp (whose dims must equal the setup dims) into sol (sized with the same dims; read
  // as the warm start when requested). Never allocates, throws or prints. On any status other
  // than success, sol holds the last finite iterate (or zeros for invalid_data) and no NaN.
  // A warm start that ends in min_step (an iterate far from the new problem's central path: a
  // large λ on a constraint the new data violate, its t clipped to warm_start_slack_floor) is
  // restarted cold with the iterations left; sol.iterations counts both.
  QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                 QpWarmStart warm = QpWarmStart::cold) override;

  Settings& settings() override { return settings_; }
  const Settings& settings() const override { return settings_; }
  const OcpQpDims& dims() const override { return ws_.dims; }

 private:
  void load(const OcpQp& qp);
  void initialize(const OcpQp& qp, const OcpQpSolution& sol, QpWarmStart warm);
  void initialize_stage(const OcpQp& qp, const OcpQpSolution& sol, QpWarmStart warm, int i);
  // Mehrotra iterations from the initialized point until a status, at most max_iterations;
  // `it` receives the number taken. prefactored: the first iteration's stages N..1 are
  // factorized, their residuals computed and their predictor's backward pass done (prepare());
  // stage 0 is left.
  QpStatus iterate(const OcpQp& qp, int max_iterations, int& it, bool prefactored = false);
  void linear_residual(const OcpQp& qp, const Eigen::VectorXd& v, const Eigen::VectorXd& pi,
                       const Eigen::VectorXd& s, const Eigen::VectorXd& lam,
                       const Eigen::VectorXd& g, const Eigen::VectorXd& z,
                       const Eigen::VectorXd& b, Eigen::VectorXd& out_v, Eigen::VectorXd& out_s,
                       Eigen::VectorXd& out_pi, int first = 0, int last = -1);
  void stage_residuals(const OcpQp& qp, int first, int last);  // res_v, res_s, res_pi, res_t
  void residual_norms();  // res_stat_, res_eq_, res_ineq_, mu_ from the whole vectors
  double stationarity_norm(const Eigen::VectorXd& rv, const Eigen::VectorXd& rs) const;
  // The Riccati factorization of the Newton system, stages `last` down to `first` (stage last + 1
  // factorized already when last < N).
  bool factorize(const OcpQp& qp, int first, int last);
  // Newton direction for the right-hand side (r_v, r_s, r_π, r_t, r_c) into (dv, dπ, ds, dt, dλ).
  // backward_from < N: the backward pass of stages N..backward_from + 1 is done already, for
  // this right-hand side (−1: N).
  void solve_direction(const OcpQp& qp, const Eigen::VectorXd& rv, const Eigen::VectorXd& rs,
                       const Eigen::VectorXd& rpi, const Eigen::VectorXd& rt,
                       const Eigen::VectorXd& rc, Eigen::VectorXd& dv, Eigen::VectorXd& dpi,
                       Eigen::VectorXd& ds, Eigen::VectorXd& dt, Eigen::VectorXd& dlam,
                       bool with_pi, int backward_from = -1);
  void backward_pass(const OcpQp& qp, const Eigen::VectorXd& rv, const Eigen::VectorXd& rs,
                     const Eigen::VectorXd& rpi, const Eigen::VectorXd& rt,
                     const Eigen::VectorXd& rc, int first, int last);
  void forward_pass(const OcpQp& qp, const Eigen::VectorXd& rs, const Eigen::VectorXd& rpi,
                    const Eigen::VectorXd& rt, const Eigen::VectorXd& rc, Eigen::VectorXd& dv,
                    Eigen::VectorXd& dpi, Eigen::VectorXd& ds, Eigen::VectorXd& dt,
                    Eigen::VectorXd& dlam, bool with_pi);
  // Direction for the current residuals and w.rc (Δπ only if final), refined if final and
  // refine; backward_from as for solve_direction.
  void newton_direction(const OcpQp& qp, bool final, bool refine, int backward_from = -1);
  void write_solution(const OcpQp& qp, OcpQpSolution& sol);

  Settings settings_{};
  Workspace ws_{};
  bool ready_ = false;
  bool loaded_ = false;       // prepare() loaded the QP for the next solve()
  bool prefactored_ = false;  // ... and initialized it warm and factorized stages N..1
  double res_stat_ = 0, res_eq_ = 0, res_ineq_ = 0, mu_ = 0;
};

}  // namespace mixpilot
