#include "core/qp/qp_riccati_ipm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/qp/detail/qp_kernels.hpp"

// Notation (per stage i; see core/qp/ocp_qp.hpp for the problem).
//   v = [u; x] (nv = nu + nx),  d(v) = [u[idxbu]; x[idxbx]; C x + D u] (nc constraints),
//   inequalities, stacked per stage as [lb (nc); ub (nc); ls (ns); us (ns)] with slacks t ≥ 0:
//     t_lb = d − lb + J_l s_l,  t_ub = ub − d + J_u s_u,  t_ls = s_l,  t_us = s_u,
//   multipliers λ ≥ 0 of the same layout, complementarity t∘λ = μ.
// Residuals at the iterate:
//   r_v  = H v + g + [Bᵀ; Aᵀ] π_i − [0; π_{i−1}] + ∇dᵀ(λ_ub − λ_lb)
//   r_sl = Zl s_l + zl − J_lᵀλ_lb − λ_ls,   r_su = Zu s_u + zu − J_uᵀλ_ub − λ_us
//   r_π  = A x + B u + b − x_{i+1},          r_t = (constraint expression) − t
// Newton step with complementarity right-hand side r_c (λ∘t for the predictor, Mehrotra's
// λ∘t + Δλ_aff∘Δt_aff − σμ for the corrector): Δλ = −(r_c + λ∘Δt)/t. With W = λ/t and
// ρ = r_c/t + W∘r_t this gives Δλ = −W∘(∇Δt-part) − ρ. Eliminating Δs_l (Ψ_l = Zl + W_lb + W_ls):
//   Δs_l = Ψ_l⁻¹(−r_sl − ρ_lb − ρ_ls − W_lb ∇dΔv),   Δs_u = Ψ_u⁻¹(−r_su − ρ_ub − ρ_us + W_ub ∇dΔv)
// and the stage system becomes (H + ∇dᵀW̃∇d) Δv + [dynamics multipliers] = −(r_v + ∇dᵀ g̃) with
//   W̃ = W_lb + W_ub − W_lb²/Ψ_l − W_ub²/Ψ_u,
//   g̃ = ρ_lb − ρ_ub + W_lb Ψ_l⁻¹(−r_sl − ρ_lb − ρ_ls) − W_ub Ψ_u⁻¹(−r_su − ρ_ub − ρ_us)
// (soft terms only on softened constraints). Riccati, square-root form with P_{i+1} = Lx Lxᵀ:
//   Y_i = [Bᵀ; Aᵀ] Lx_{i+1},  L_i L_iᵀ = H̃_i + Y_i Y_iᵀ,  Lx_i = trailing nx block of L_i,
// backward gradient pass l_i = L_i⁻¹(g̃_i + Y_i (Lx_{i+1}ᵀ r_π,i + lx_{i+1})), and the forward pass
//   Δu_i = −Luu⁻ᵀ(LxuᵀΔx_i + lu_i),  Δx_{i+1} = AΔx_i + BΔu_i + r_π,i,
//   Δπ_i = Lx_{i+1}(Lx_{i+1}ᵀΔx_{i+1} + lx_{i+1}).
// x_0 is fixed (Δx_0 = 0), so stage 0 factorizes only its uu block.

namespace mixpilot {

bool QpRiccatiIpm::setup(const OcpQpDims& dims, const Settings& settings) {
  settings_ = settings;
  ready_ = dims.valid();
  if (!ready_) return false;
  Workspace& w = ws_;
  w.dims = dims;
  const int N = dims.N;
  const std::size_t n1 = static_cast<std::size_t>(N) + 1;
  w.nv.assign(n1, 0);
  w.nc.assign(n1, 0);
  w.off_v.assign(n1, 0);
  w.off_pi.assign(n1, 0);
  w.off_s.assign(n1, 0);
  w.off_m.assign(n1, 0);
  w.off_c.assign(n1, 0);
  w.var_of_box.assign(n1, {});
  w.soft_of.assign(n1, {});
  w.BAt.assign(n1, {});
  w.DCt.assign(n1, {});
  w.L.assign(n1, {});
  w.Y.assign(n1, {});
  w.Hbase.assign(n1, {});
  w.inv_diag.assign(n1, {});
  w.Dinv.assign(n1, {});
  w.pivot_floor.assign(n1, 0.0);
  w.tmp.assign(n1, {});
  int ov = 0, op = 0, os = 0, om = 0, oc = 0;
  for (int i = 0; i <= N; ++i) {
    const int nx = dims.nx[i], nu = dims.nu[i], nx1 = i < N ? dims.nx[i + 1] : 0;
    const int nv = nx + nu, nc = dims.nc(i), ns = dims.ns[i];
    w.nv[i] = nv;
    w.nc[i] = nc;
    w.off_v[i] = ov;
    w.off_pi[i] = op;
    w.off_s[i] = os;
    w.off_m[i] = om;
    w.off_c[i] = oc;
    ov += nv;
    op += nx1;
    os += 2 * ns;
    om += 2 * nc + 2 * ns;
    oc += nc;
    w.var_of_box[i] = Eigen::VectorXi::Zero(dims.nbu[i] + dims.nbx[i]);
    w.soft_of[i] = Eigen::VectorXi::Constant(nc, -1);
    // Row counts padded to a multiple of 4 for the register-blocked kernels (padding rows zero).
    const int np = (nv + 3) & ~3;
    w.BAt[i] = Eigen::MatrixXd::Zero(np, nx1);
    w.DCt[i] = Eigen::MatrixXd::Zero(nv, dims.ng[i]);
    w.L[i] = Eigen::MatrixXd::Zero(np, nv);
    w.Y[i] = Eigen::MatrixXd::Zero(np, nx1 + dims.ng[i]);
    w.Hbase[i] = Eigen::MatrixXd::Zero(np, nv);
    w.inv_diag[i] = Eigen::VectorXd::Zero(nv);
    w.Dinv[i] = Eigen::MatrixXd::Zero(std::max(np, 4), 4);
    w.tmp[i] = Eigen::VectorXd::Zero(std::max({nv, nx1, nc, 1}));
  }
  for (Eigen::VectorXd* p : {&w.v, &w.dv, &w.res_v, &w.l, &w.gflat, &w.err_v, &w.cv})
    *p = Eigen::VectorXd::Zero(ov);
  for (Eigen::VectorXd* p : {&w.pi, &w.dpi, &w.res_pi, &w.bflat, &w.err_pi, &w.cpi})
    *p = Eigen::VectorXd::Zero(op);
  for (Eigen::VectorXd* p : {&w.s, &w.ds, &w.res_s, &w.zflat, &w.err_s, &w.cs, &w.slive, &w.sfix})
    *p = Eigen::VectorXd::Zero(os);
  for (Eigen::VectorXd* p : {&w.t, &w.dt, &w.lam, &w.dlam, &w.res_t, &w.mask, &w.w, &w.rc,
                             &w.rho, &w.dt_aff, &w.dlam_aff, &w.ct, &w.clam, &w.zero_m})
    *p = Eigen::VectorXd::Zero(om);
  w.inv_t = Eigen::VectorXd::Zero(om);
  for (Eigen::VectorXd* p : {&w.lbnd, &w.ubnd, &w.wc, &w.gc, &w.dd}) *p = Eigen::VectorXd::Zero(oc);
  w.psi_l = Eigen::VectorXd::Zero(os / 2);
  w.psi_u = Eigen::VectorXd::Zero(os / 2);
  return true;
}

// Copies the stage data into the solver's layout (indices and sizes were validated).
void QpRiccatiIpm::load(const OcpQp& qp) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const double big = settings_.inf_bound;
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nu = d.nu[i], nx = d.nx[i], nbu = d.nbu[i], nbx = d.nbx[i], ng = d.ng[i];
    const int nc = w.nc[i], ns = d.ns[i];
    if (i < d.N) {  // [Bᵀ; Aᵀ]
      const int nx1 = d.nx[i + 1], ldb = static_cast<int>(w.BAt[i].rows());
      kernels::transpose(nx1, nu, s.B.data(), nx1, w.BAt[i].data(), ldb);
      kernels::transpose(nx1, nx, s.A.data(), nx1, w.BAt[i].data() + nu, ldb);
      std::copy_n(s.b.data(), nx1, w.bflat.data() + w.off_pi[i]);
    }
    std::copy_n(s.r.data(), nu, w.gflat.data() + w.off_v[i]);
    std::copy_n(s.q.data(), nx, w.gflat.data() + w.off_v[i] + nu);
    std::copy_n(s.zl.data(), ns, w.zflat.data() + w.off_s[i]);
    std::copy_n(s.zu.data(), ns, w.zflat.data() + w.off_s[i] + ns);
    if (ng > 0) {  // [Dᵀ; Cᵀ]
      const int nv = nu + nx;
      kernels::transpose(ng, nu, s.D.data(), ng, w.DCt[i].data(), nv);
      kernels::transpose(ng, nx, s.C.data(), ng, w.DCt[i].data() + nu, nv);
    }
    // Stage Hessian [R S; Sᵀ Q] in (u, x) order, lower triangle (the strict upper stays zero),
    // for the factorization; the residuals read R, S and Q in place.
    {
      const int ldh = static_cast<int>(w.Hbase[i].rows());
      double* h = w.Hbase[i].data();
      double scale = 0.0;
      kernels::transpose(nu, nx, s.S.data(), nu, h + nu, ldh);
      for (int c = 0; c < nu; ++c) {
        const double* rc = s.R.data() + c * nu;
        for (int r = c; r < nu; ++r) h[r + c * ldh] = rc[r];
        scale = std::max(scale, std::abs(rc[c]));
      }
      for (int c = 0; c < nx; ++c) {
        const double* qc = s.Q.data() + c * nx;
        for (int r = c; r < nx; ++r) h[nu + r + (nu + c) * ldh] = qc[r];
        scale = std::max(scale, std::abs(qc[c]));
      }
      w.pivot_floor[i] = settings_.psd_tol * (scale > 0.0 ? scale : 1.0);
    }
    for (int k = 0; k < nbu; ++k) w.var_of_box[i][k] = s.idxbu[k];
    for (int k = 0; k < nbx; ++k) w.var_of_box[i][nbu + k] = nu + s.idxbx[k];
    w.soft_of[i].setConstant(-1);
    for (int j = 0; j < ns; ++j) w.soft_of[i][s.idxs[j]] = j;
    const int oc = w.off_c[i], om = w.off_m[i];
    for (int k = 0; k < nc; ++k) {
      double lo, hi;
      if (k < nbu) {
        lo = s.lbu[k];
        hi = s.ubu[k];
      } else if (k < nbu + nbx) {
        lo = s.lbx[k - nbu];
        hi = s.ubx[k - nbu];
      } else {
        lo = s.lg[k - nbu - nbx];
        hi = s.ug[k - nbu - nbx];
      }
      const bool has_lo = std::isfinite(lo) && std::abs(lo) < big;
      const bool has_hi = std::isfinite(hi) && std::abs(hi) < big;
      w.lbnd[oc + k] = has_lo ? lo : 0.0;
      w.ubnd[oc + k] = has_hi ? hi : 0.0;
      w.mask[om + k] = has_lo ? 1.0 : 0.0;
      w.mask[om + nc + k] = has_hi ? 1.0 : 0.0;
    }
    // s ≥ 0 is implied at the optimum when z = 0 < Z (stationarity gives s = λ/Z ≥ 0); imposing
    // it would make s·λ_s = 0 degenerate (both → 0 like √μ) for every inactive ℓ2²-soft side.
    // A slack whose bound side is absent is decoupled from everything else: min ½Z s² + z s over
    // s ≥ 0, solved in closed form (s = max(0, −z/Z), s = 0 for Z = 0) and kept out of the
    // iteration ("dead"). (Keeping them live had masked the μ collapse that the centring floor
    // of the solve loop now prevents.)
    const int os = w.off_s[i];
    for (int j = 0; j < ns; ++j) {
      const int k = s.idxs[j];
      const bool live_l = w.mask[om + k] != 0.0, live_u = w.mask[om + nc + k] != 0.0;
      w.slive[os + j] = live_l ? 1.0 : 0.0;
      w.slive[os + ns + j] = live_u ? 1.0 : 0.0;
      w.sfix[os + j] = live_l || s.Zl[j] <= 0.0 ? 0.0 : std::max(0.0, -s.zl[j] / s.Zl[j]);
      w.sfix[os + ns + j] = live_u || s.Zu[j] <= 0.0 ? 0.0 : std::max(0.0, -s.zu[j] / s.Zu[j]);
      w.mask[om + 2 * nc + j] = live_l && (s.zl[j] != 0.0 || s.Zl[j] <= 0.0) ? 1.0 : 0.0;
      w.mask[om + 2 * nc + ns + j] = live_u && (s.zu[j] != 0.0 || s.Zu[j] <= 0.0) ? 1.0 : 0.0;
    }
  }
  w.m_total = static_cast<int>(w.mask.sum() + 0.5);
}

// Constraint values d(v) of stage i into dd (flat per constraint).
static void eval_constraints(const QpRiccatiIpmWorkspace& w, int i, const Eigen::VectorXd& v,
                             Eigen::VectorXd& dd) {
  const int nb = w.dims.nbu[i] + w.dims.nbx[i], ng = w.dims.ng[i];
  const int ov = w.off_v[i], oc = w.off_c[i];
  for (int k = 0; k < nb; ++k) dd[oc + k] = v[ov + w.var_of_box[i][k]];
  if (ng > 0) {  // the kernels, not Eigen's generic GEMV: its call overhead dwarfs a 20 x 4 product
    dd.segment(oc + nb, ng).setZero();
    kernels::gemv_t(w.nv[i], ng, w.DCt[i].data(), w.nv[i], v.data() + ov, dd.data() + oc + nb);
  }
}

void QpRiccatiIpm::initialize(const OcpQp& qp, const OcpQpSolution& sol, QpWarmStart warm) {
  for (int i = 0; i <= ws_.dims.N; ++i) initialize_stage(qp, sol, warm, i);
}

void QpRiccatiIpm::initialize_stage(const OcpQp& qp, const OcpQpSolution& sol, QpWarmStart warm,
                                    int i) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const bool primal = warm != QpWarmStart::cold;
  const bool dual = warm == QpWarmStart::primal_dual;
  const double thr = dual ? settings_.warm_start_slack_floor : settings_.init_slack;
  const double lam_floor = settings_.warm_start_floor;
  const int nu = d.nu[i], nx = d.nx[i], ns = d.ns[i], nc = w.nc[i];
  const int ov = w.off_v[i], os = w.off_s[i], om = w.off_m[i], oc = w.off_c[i];
  if (primal) {
    w.v.segment(ov, nu) = sol.u[i];
    w.v.segment(ov + nu, nx) = sol.x[i];
    w.s.segment(os, ns) = sol.sl[i].cwiseMax(0.0);
    w.s.segment(os + ns, ns) = sol.su[i].cwiseMax(0.0);
  } else {
    w.v.segment(ov, nu + nx).setZero();
    w.s.segment(os, 2 * ns).setZero();
  }
  for (int j = 0; j < 2 * ns; ++j)
    if (w.slive[os + j] == 0.0) w.s[os + j] = w.sfix[os + j];
  if (i == 0) w.v.segment(ov + nu, nx) = qp.x0;
  if (i < d.N) {
    if (dual)
      w.pi.segment(w.off_pi[i], d.nx[i + 1]) = sol.pi[i];
    else
      w.pi.segment(w.off_pi[i], d.nx[i + 1]).setZero();
  }
  eval_constraints(w, i, w.v, w.dd);
  for (int k = 0; k < nc; ++k) {
    const int j = w.soft_of[i][k];
    const double sl = j >= 0 ? w.s[os + j] : 0.0, su = j >= 0 ? w.s[os + ns + j] : 0.0;
    w.t[om + k] = w.dd[oc + k] - w.lbnd[oc + k] + sl;
    w.t[om + nc + k] = w.ubnd[oc + k] - w.dd[oc + k] + su;
    if (dual) {
      w.lam[om + k] = sol.lam_l[i][k];
      w.lam[om + nc + k] = sol.lam_u[i][k];
    }
  }
  w.t.segment(om + 2 * nc, 2 * ns) = w.s.segment(os, 2 * ns);
  if (dual) {
    w.lam.segment(om + 2 * nc, ns) = sol.lam_sl[i];
    w.lam.segment(om + 2 * nc + ns, ns) = sol.lam_su[i];
  }
  for (int k = om; k < om + 2 * nc + 2 * ns; ++k) {
    if (w.mask[k] == 0.0) {
      w.t[k] = 1.0;
      w.lam[k] = 0.0;
      continue;
    }
    // A warm start: a hard constraint the new data violate (t ≤ 0) starts with the violation's
    // size, at least warm_start_violated, so that the first step has room to restore it
    // (floored at the tiny warm_start_slack_floor it blocks the step, and the solve ends in
    // min_step and a cold restart); a soft one's slack absorbs its violation instead.
    const int kc = k - om;
    const bool hard = kc < 2 * nc && w.soft_of[i][kc < nc ? kc : kc - nc] < 0;
    if (dual && hard && w.t[k] <= 0.0)
      w.t[k] = std::max(-w.t[k], settings_.warm_start_violated);
    else
      w.t[k] = std::max(w.t[k], thr);
    w.lam[k] = dual ? std::max(w.lam[k], lam_floor) : settings_.init_mu / w.t[k];
  }
  if (dual) return;
  // Cold multipliers of s ≥ 0 on the slack's stationarity Z s + z − λ_b − λ_s = 0 (linear, and
  // the only equation λ_s enters): λ_s = max(μ0/t_s, Z s + z − λ_b). With the generic μ0/t_s ≪ z
  // instead (z = 1.45e4 in SPEC §5.3), the first step must create λ_s ≈ z from nothing: it asks
  // for Δs ≈ −z/W, only a tiny step fits, and Mehrotra's second-order term Δλ_aff∘Δt_aff ≈ −z²/W
  // then drives s and t_s up by orders of magnitude. With Z = 0 nothing pulls them back and the
  // solve ends in min_step (an ℓ2² weight Z > 0 had masked this).
  const OcpQpStage& st = qp.stage[i];
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    const int ml = om + 2 * nc + j, mu = om + 2 * nc + ns + j;
    if (w.mask[ml] != 0.0)
      w.lam[ml] = std::max(w.lam[ml], st.Zl[j] * w.s[os + j] + st.zl[j] - w.lam[om + k]);
    if (w.mask[mu] != 0.0)
      w.lam[mu] = std::max(w.lam[mu], st.Zu[j] * w.s[os + ns + j] + st.zu[j] - w.lam[om + nc + k]);
  }
}

// Stationarity and dynamics residuals of the point (v, π, s, λ) with the linear terms (g, z, b):
//   out_v  = H v + g + [Bᵀ; Aᵀ] π_i − [0; π_{i−1}] + ∇dᵀ(λ_ub − λ_lb),
//   out_s  = [Zl s_l + zl − J_lᵀλ_lb − λ_ls; Zu s_u + zu − J_uᵀλ_ub − λ_us],
//   out_pi = A x + B u + b − x_{i+1}.
// With (g, z, b) from the QP this is the KKT residual of an iterate; with (r_v, r_s, r_π) and a
// Newton direction it is the error of the linear solve (iterative refinement).
void QpRiccatiIpm::linear_residual(const OcpQp& qp, const Eigen::VectorXd& v,
                                   const Eigen::VectorXd& pi, const Eigen::VectorXd& s,
                                   const Eigen::VectorXd& lam, const Eigen::VectorXd& g,
                                   const Eigen::VectorXd& z, const Eigen::VectorXd& b,
                                   Eigen::VectorXd& out_v, Eigen::VectorXd& out_s,
                                   Eigen::VectorXd& out_pi, int first, int last) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  if (last < 0) last = d.N;
  for (int i = first; i <= last; ++i) {
    const OcpQpStage& st = qp.stage[i];
    const int nu = d.nu[i], nx = d.nx[i], ns = d.ns[i], nc = w.nc[i], ng = d.ng[i];
    const int nb = d.nbu[i] + d.nbx[i];
    const int ov = w.off_v[i], os = w.off_s[i], om = w.off_m[i];
    const int nv = nu + nx;
    auto rx = out_v.segment(ov + nu, nx);
    out_v.segment(ov, nv) = g.segment(ov, nv);
    // [R S; Sᵀ Q] v, read in place.
    if (nu > 0) {
      kernels::gemv_n(nu, nu, st.R.data(), nu, v.data() + ov, out_v.data() + ov);
      kernels::gemv_n(nu, nx, st.S.data(), nu, v.data() + ov + nu, out_v.data() + ov);
      kernels::gemv_t(nu, nx, st.S.data(), nu, v.data() + ov, out_v.data() + ov + nu);
    }
    kernels::gemv_n(nx, nx, st.Q.data(), nx, v.data() + ov + nu, out_v.data() + ov + nu);
    if (i < d.N)
      kernels::gemv_n(nv, d.nx[i + 1], w.BAt[i].data(), static_cast<int>(w.BAt[i].rows()),
                      pi.data() + w.off_pi[i], out_v.data() + ov);
    if (i > 0) rx -= pi.segment(w.off_pi[i - 1], nx);
    for (int k = 0; k < nb; ++k) out_v[ov + w.var_of_box[i][k]] += lam[om + nc + k] - lam[om + k];
    if (ng > 0) {
      auto tmp = w.tmp[i].head(ng);
      tmp = lam.segment(om + nc + nb, ng) - lam.segment(om + nb, ng);
      kernels::gemv_n(nv, ng, w.DCt[i].data(), nv, tmp.data(), out_v.data() + ov);
    }
    for (int j = 0; j < ns; ++j) {
      const int k = st.idxs[j];
      // A dead (decoupled) side sits at its closed-form optimum: no residual.
      out_s[os + j] = w.slive[os + j] *
                      (st.Zl[j] * s[os + j] + z[os + j] - lam[om + k] - lam[om + 2 * nc + j]);
      out_s[os + ns + j] = w.slive[os + ns + j] * (st.Zu[j] * s[os + ns + j] + z[os + ns + j] -
                                                   lam[om + nc + k] - lam[om + 2 * nc + ns + j]);
    }
    if (i < d.N) {
      const int nx1 = d.nx[i + 1], op = w.off_pi[i];
      auto rp = out_pi.segment(op, nx1);
      rp = b.segment(op, nx1) - v.segment(w.off_v[i + 1] + d.nu[i + 1], nx1);
      kernels::gemv_t(nv, nx1, w.BAt[i].data(), static_cast<int>(w.BAt[i].rows()), v.data() + ov,
                      rp.data());
    }
  }
}

void QpRiccatiIpm::stage_residuals(const OcpQp& qp, int first, int last) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  linear_residual(qp, w.v, w.pi, w.s, w.lam, w.gflat, w.zflat, w.bflat, w.res_v, w.res_s,
                  w.res_pi, first, last);
  for (int i = first; i <= last; ++i) {
    const int ns = d.ns[i], nc = w.nc[i];
    const int os = w.off_s[i], om = w.off_m[i], oc = w.off_c[i];
    eval_constraints(w, i, w.v, w.dd);
    for (int k = 0; k < nc; ++k) {
      const int j = w.soft_of[i][k];
      const double sl = j >= 0 ? w.s[os + j] : 0.0, su = j >= 0 ? w.s[os + ns + j] : 0.0;
      w.res_t[om + k] = w.mask[om + k] * (w.dd[oc + k] - w.lbnd[oc + k] + sl - w.t[om + k]);
      w.res_t[om + nc + k] =
          w.mask[om + nc + k] * (w.ubnd[oc + k] - w.dd[oc + k] + su - w.t[om + nc + k]);
    }
    for (int j = 0; j < ns; ++j) {
      w.res_t[om + 2 * nc + j] = w.mask[om + 2 * nc + j] * (w.s[os + j] - w.t[om + 2 * nc + j]);
      w.res_t[om + 2 * nc + ns + j] =
          w.mask[om + 2 * nc + ns + j] * (w.s[os + ns + j] - w.t[om + 2 * nc + ns + j]);
    }
  }
}

void QpRiccatiIpm::residual_norms() {
  const Workspace& w = ws_;
  res_stat_ = stationarity_norm(w.res_v, w.res_s);
  res_eq_ = w.res_pi.size() > 0 ? w.res_pi.lpNorm<Eigen::Infinity>() : 0.0;
  res_ineq_ = w.res_t.size() > 0 ? w.res_t.lpNorm<Eigen::Infinity>() : 0.0;
  mu_ = w.m_total > 0 ? w.lam.dot(w.t) / w.m_total : 0.0;
}

// ∞-norm of the stationarity residual, without stage 0's x-part (the x_0 multiplier).
double QpRiccatiIpm::stationarity_norm(const Eigen::VectorXd& rv, const Eigen::VectorXd& rs) const {
  const Workspace& w = ws_;
  double r = 0.0;
  const int nu0 = w.dims.nu[0], n0 = w.nv[0];
  if (nu0 > 0) r = rv.head(nu0).lpNorm<Eigen::Infinity>();
  if (rv.size() > n0) r = std::max(r, rv.tail(rv.size() - n0).lpNorm<Eigen::Infinity>());
  if (rs.size() > 0) r = std::max(r, rs.lpNorm<Eigen::Infinity>());
  return r;
}

bool QpRiccatiIpm::factorize(const OcpQp& qp, int first, int last) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  // 1/t once per iteration: the directions below then multiply instead of divide.
  const int m0 = w.off_m[first];
  const int m1 = last < d.N ? w.off_m[last + 1] : static_cast<int>(w.t.size());
  w.inv_t.segment(m0, m1 - m0) = w.mask.segment(m0, m1 - m0).cwiseQuotient(w.t.segment(m0, m1 - m0));
  w.w.segment(m0, m1 - m0) =
      w.lam.segment(m0, m1 - m0).cwiseProduct(w.inv_t.segment(m0, m1 - m0));
  for (int i = last; i >= first; --i) {
    const OcpQpStage& st = qp.stage[i];
    const int nu = d.nu[i], nx = d.nx[i], ns = d.ns[i], nc = w.nc[i], ng = d.ng[i];
    const int nb = d.nbu[i] + d.nbx[i];
    const int om = w.off_m[i], oc = w.off_c[i], os2 = w.off_s[i] / 2;
    // Effective constraint weights after eliminating the slacks.
    for (int k = 0; k < nc; ++k) w.wc[oc + k] = w.w[om + k] + w.w[om + nc + k];
    const int os = w.off_s[i];
    for (int j = 0; j < ns; ++j) {
      const int k = st.idxs[j];
      const double wl = w.w[om + k], wu = w.w[om + nc + k];
      const double cl = st.Zl[j] + w.w[om + 2 * nc + j], cu = st.Zu[j] + w.w[om + 2 * nc + ns + j];
      // Ψ⁻¹, 0 on a dead side (absent bound: W = 0 there and Δs = 0).
      const double pl = w.slive[os + j] != 0.0 ? 1.0 / (cl + wl) : 0.0;
      const double pu = w.slive[os + ns + j] != 0.0 ? 1.0 / (cu + wu) : 0.0;
      w.psi_l[os2 + j] = pl;
      w.psi_u[os2 + j] = pu;
      // W − W²/Ψ = W (Z + W_s)/Ψ without the cancellation: for an active pure-ℓ1 side (Z = 0,
      // W → ∞, W_s → 0) the difference form loses every digit of the O(W_s) result.
      // (A dead side's bound is absent, so its W is 0 and it contributes nothing.)
      w.wc[oc + k] = wl * cl * pl + wu * cu * pu;
    }
    // H̃ = [R S; Sᵀ Q] + ∇dᵀ W̃ ∇d (lower triangle).
    Eigen::MatrixXd& L = w.L[i];
    const int ld = static_cast<int>(L.rows());
    const int nf = i == 0 ? nu : nu + nx;  // stage 0: x_0 fixed, only the uu block
    L = w.Hbase[i];
    for (int k = 0; k < nb; ++k) {
      const int p = w.var_of_box[i][k];
      if (p < nf) L(p, p) += w.wc[oc + k];
    }
    // Y = [BAt · Lx_{i+1}, ∇gᵀ W̃_g^½];  L Lᵀ = H + (box terms) + Y Yᵀ: the general
    // constraints' ∇gᵀ W̃ ∇g joins the one register-blocked rank-(nx+ng) update.
    const int nx1 = i < d.N ? d.nx[i + 1] : 0;
    Eigen::MatrixXd& Y = w.Y[i];
    for (int k = 0; k < ng; ++k)
      Y.col(nx1 + k).head(nf) = std::sqrt(w.wc[oc + nb + k]) * w.DCt[i].col(k).head(nf);
    if (i < d.N) {
      const int nu1 = d.nu[i + 1];
      const Eigen::MatrixXd& L1 = w.L[i + 1];
      const int ld1 = static_cast<int>(L1.rows());
      kernels::trmm_rl_padded(nf, nx1, w.BAt[i].data(), static_cast<int>(w.BAt[i].rows()),
                              L1.data() + nu1 + static_cast<std::ptrdiff_t>(nu1) * ld1, ld1,
                              Y.data(), static_cast<int>(Y.rows()));
    }
    if (!kernels::syrk_potrf_ln_padded(nf, nx1 + ng, Y.data(), static_cast<int>(Y.rows()),
                                       L.data(), ld, nu, w.inv_diag[i].data(), settings_.psd_tol,
                                       w.pivot_floor[i],
                                       w.Dinv[i].data(), static_cast<int>(w.Dinv[i].rows())))
      return false;
  }
  return true;
}

void QpRiccatiIpm::solve_direction(const OcpQp& qp, const Eigen::VectorXd& rv,
                                   const Eigen::VectorXd& rs, const Eigen::VectorXd& rpi,
                                   const Eigen::VectorXd& rt, const Eigen::VectorXd& rc,
                                   Eigen::VectorXd& dv, Eigen::VectorXd& dpi, Eigen::VectorXd& ds,
                                   Eigen::VectorXd& dt, Eigen::VectorXd& dlam, bool with_pi,
                                   int backward_from) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  backward_pass(qp, rv, rs, rpi, rt, rc, 0, backward_from < 0 ? d.N : backward_from);
  forward_pass(qp, rs, rpi, rt, rc, dv, dpi, ds, dt, dlam, with_pi);
}

// Reduced gradients g̃ and the backward pass l_i = L_i⁻¹(g̃_i + Y_i y), stages last down to first
// (stage last + 1's l is there already when last < N); ρ of those stages.
void QpRiccatiIpm::backward_pass(const OcpQp& qp, const Eigen::VectorXd& rv,
                                 const Eigen::VectorXd& rs, const Eigen::VectorXd& rpi,
                                 const Eigen::VectorXd& rt, const Eigen::VectorXd& rc, int first,
                                 int last) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const int m0 = w.off_m[first];
  const int m1 = last < d.N ? w.off_m[last + 1] : static_cast<int>(w.t.size());
  w.rho.segment(m0, m1 - m0) =
      (rc.segment(m0, m1 - m0) + w.lam.segment(m0, m1 - m0).cwiseProduct(rt.segment(m0, m1 - m0)))
          .cwiseProduct(w.inv_t.segment(m0, m1 - m0));
  for (int i = last; i >= first; --i) {
    const OcpQpStage& st = qp.stage[i];
    const int nu = d.nu[i], nx = d.nx[i], ns = d.ns[i], nc = w.nc[i], ng = d.ng[i];
    const int nb = d.nbu[i] + d.nbx[i];
    const int ov = w.off_v[i], om = w.off_m[i], oc = w.off_c[i], os = w.off_s[i];
    const int os2 = os / 2, n = nu + nx, nf = i == 0 ? nu : n;
    for (int k = 0; k < nc; ++k) w.gc[oc + k] = w.rho[om + k] - w.rho[om + nc + k];
    for (int j = 0; j < ns; ++j) {
      const int k = st.idxs[j];
      const double pl = w.psi_l[os2 + j], pu = w.psi_u[os2 + j];
      if (pl == 0.0 && pu == 0.0) continue;  // both sides dead
      // ρ_lb + W_lb Ψ_l⁻¹(−r_sl − ρ_lb − ρ_ls) = ρ_lb (Zl + W_ls) Ψ_l⁻¹ + W_lb Ψ_l⁻¹(−r_sl − ρ_ls)
      // (no cancellation of the O(W) terms), likewise for the upper side.
      const double wl = w.w[om + k], wu = w.w[om + nc + k];
      const double gl = pl == 0.0 ? w.rho[om + k]
                                  : (w.rho[om + k] * (st.Zl[j] + w.w[om + 2 * nc + j]) +
                                     wl * (-rs[os + j] - w.rho[om + 2 * nc + j])) *
                                        pl;
      const double gu = pu == 0.0 ? w.rho[om + nc + k]
                                  : (w.rho[om + nc + k] * (st.Zu[j] + w.w[om + 2 * nc + ns + j]) +
                                     wu * (-rs[os + ns + j] - w.rho[om + 2 * nc + ns + j])) *
                                        pu;
      w.gc[oc + k] = gl - gu;
    }
    auto g = w.l.segment(ov, n);
    g = rv.segment(ov, n);
    for (int k = 0; k < nb; ++k) g[w.var_of_box[i][k]] += w.gc[oc + k];
    if (ng > 0) kernels::gemv_n(n, ng, w.DCt[i].data(), n, w.gc.data() + oc + nb, g.data());
    if (i < d.N) {
      const int nx1 = d.nx[i + 1], nu1 = d.nu[i + 1];
      const Eigen::MatrixXd& L1 = w.L[i + 1];
      auto y = w.tmp[i].head(nx1);
      y = w.l.segment(w.off_v[i + 1] + nu1, nx1);
      const int ld1 = static_cast<int>(L1.rows());
      // Lx's strict upper triangle is zero, so the triangular products are plain gemv.
      kernels::gemv_t(nx1, nx1, L1.data() + nu1 + static_cast<std::ptrdiff_t>(nu1) * ld1, ld1,
                      rpi.data() + w.off_pi[i], y.data());
      kernels::gemv_n(nf, nx1, w.Y[i].data(), static_cast<int>(w.Y[i].rows()), y.data(), g.data());
    }
    kernels::trsv_ln(nf, w.L[i].data(), static_cast<int>(w.L[i].rows()), w.Dinv[i].data(),
                     static_cast<int>(w.Dinv[i].rows()), g.data());
  }
}

// The forward pass from the backward pass's l, then the slack, inequality-slack and multiplier
// directions.
void QpRiccatiIpm::forward_pass(const OcpQp& qp, const Eigen::VectorXd& rs,
                                const Eigen::VectorXd& rpi, const Eigen::VectorXd& rt,
                                const Eigen::VectorXd& rc, Eigen::VectorXd& dv,
                                Eigen::VectorXd& dpi, Eigen::VectorXd& ds, Eigen::VectorXd& dt,
                                Eigen::VectorXd& dlam, bool with_pi) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  for (int i = 0; i <= d.N; ++i) {
    const int nu = d.nu[i], nx = d.nx[i];
    const int ov = w.off_v[i];
    const Eigen::MatrixXd& L = w.L[i];
    auto du = dv.segment(ov, nu);
    auto dx = dv.segment(ov + nu, nx);
    if (i == 0) dx.setZero();
    if (nu > 0) {
      du = w.l.segment(ov, nu);
      if (i > 0)
        kernels::gemv_t(nx, nu, L.data() + nu, static_cast<int>(L.rows()), dx.data(), du.data());
      if (nu <= 4)  // the forward pass is a chain through the stages: no substitution chain
        kernels::trsv_lt_small(nu, w.Dinv[i].data(), static_cast<int>(w.Dinv[i].rows()),
                               du.data());
      else if (nu % 4 == 0)
        kernels::trsv_lt_blocked(nu, L.data(), static_cast<int>(L.rows()), w.Dinv[i].data(),
                                 static_cast<int>(w.Dinv[i].rows()), du.data());
      else
        kernels::trsv_lt(nu, L.data(), static_cast<int>(L.rows()), w.inv_diag[i].data(),
                         du.data());
      du = -du;
    }
    if (i < d.N) {
      const int nx1 = d.nx[i + 1], nu1 = d.nu[i + 1];
      auto dx1 = dv.segment(w.off_v[i + 1] + nu1, nx1);
      dx1 = rpi.segment(w.off_pi[i], nx1);
      kernels::gemv_t(nu + nx, nx1, w.BAt[i].data(), static_cast<int>(w.BAt[i].rows()),
                      dv.data() + ov, dx1.data());
      if (!with_pi) continue;  // the predictor needs no Δπ
      const Eigen::MatrixXd& L1 = w.L[i + 1];
      const int ld1 = static_cast<int>(L1.rows());
      const double* Lx = L1.data() + nu1 + static_cast<std::ptrdiff_t>(nu1) * ld1;
      auto y = w.tmp[i].head(nx1);
      y = w.l.segment(w.off_v[i + 1] + nu1, nx1);
      kernels::gemv_t(nx1, nx1, Lx, ld1, dx1.data(), y.data());
      dpi.segment(w.off_pi[i], nx1).setZero();
      kernels::gemv_n(nx1, nx1, Lx, ld1, y.data(), dpi.data() + w.off_pi[i]);
    }
  }
  // Slack, inequality-slack and multiplier directions.
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& st = qp.stage[i];
    const int ns = d.ns[i], nc = w.nc[i];
    const int om = w.off_m[i], oc = w.off_c[i], os = w.off_s[i], os2 = os / 2;
    eval_constraints(w, i, dv, w.dd);  // ∇d Δv
    for (int k = 0; k < nc; ++k) {
      dt[om + k] = w.dd[oc + k] + rt[om + k];
      dt[om + nc + k] = -w.dd[oc + k] + rt[om + nc + k];
    }
    for (int j = 0; j < ns; ++j) {
      const int k = st.idxs[j];
      const double dsl = (-rs[os + j] - w.rho[om + k] - w.rho[om + 2 * nc + j] -
                          w.w[om + k] * w.dd[oc + k]) *
                         w.psi_l[os2 + j];
      const double dsu = (-rs[os + ns + j] - w.rho[om + nc + k] -
                          w.rho[om + 2 * nc + ns + j] + w.w[om + nc + k] * w.dd[oc + k]) *
                         w.psi_u[os2 + j];
      ds[os + j] = dsl;
      ds[os + ns + j] = dsu;
      dt[om + k] += dsl;
      dt[om + nc + k] += dsu;
      dt[om + 2 * nc + j] = dsl + rt[om + 2 * nc + j];
      dt[om + 2 * nc + ns + j] = dsu + rt[om + 2 * nc + ns + j];
    }
  }
  dt = dt.cwiseProduct(w.mask);
  dlam = -(rc + w.lam.cwiseProduct(dt)).cwiseProduct(w.inv_t);
}

void QpRiccatiIpm::newton_direction(const OcpQp& qp, bool final, bool refine, int backward_from) {
  Workspace& w = ws_;
  solve_direction(qp, w.res_v, w.res_s, w.res_pi, w.res_t, w.rc, w.dv, w.dpi, w.ds, w.dt, w.dlam,
                  final, backward_from);
  int refinement_steps = final && refine ? settings_.refinement_steps : 0;
  // Iterative refinement: Δλ = −W ∇dΔv − ρ cancels to O(λ) from terms of O(W), so rounding in Δv
  // is amplified by W = λ/t → ∞; the error of the unreduced Newton equations is computed and
  // solved for with the same factorization. The t and λ equations hold exactly by construction.
  const double target = settings_.refine_ratio * std::min(settings_.tol_stat, settings_.tol_eq);
  // Measuring that error costs a residual evaluation; skip it when the first-order bound
  // ε‖W‖∞‖Δv‖∞ of the rounding (the backward error of the Cholesky solve, ε‖H̃‖‖Δv‖, with
  // ‖H̃‖ ≈ ‖W‖ once W dominates; ×kRefineBoundSafety) already lies below the target.
  if (refinement_steps > 0 && w.m_total > 0) {
    const double bound = qp_defaults::kRefineBoundSafety * std::numeric_limits<double>::epsilon() *
                         w.w.lpNorm<Eigen::Infinity>() * w.dv.lpNorm<Eigen::Infinity>();
    if (bound <= target) refinement_steps = 0;
  }
  for (int r = 0; r < refinement_steps; ++r) {
    linear_residual(qp, w.dv, w.dpi, w.ds, w.dlam, w.res_v, w.res_s, w.res_pi, w.err_v, w.err_s,
                    w.err_pi);
    const double e = std::max(stationarity_norm(w.err_v, w.err_s),
                              w.err_pi.size() > 0 ? w.err_pi.lpNorm<Eigen::Infinity>() : 0.0);
    if (!(e > target)) break;
    solve_direction(qp, w.err_v, w.err_s, w.err_pi, w.zero_m, w.zero_m, w.cv, w.cpi, w.cs, w.ct,
                    w.clam, true);
    w.dv += w.cv;
    w.dpi += w.cpi;
    w.ds += w.cs;
    w.dt += w.ct;
    w.dlam += w.clam;
  }
}

namespace {
// Largest α ≤ alpha with z + α dz ≥ 0 componentwise (z > 0), and the blocking index (−1 if no
// component blocks before alpha).
double max_step_index(const Eigen::VectorXd& z, const Eigen::VectorXd& dz, double alpha,
                      Eigen::Index& block) {
  int k = -1;
  const double a = kernels::max_step(static_cast<int>(z.size()), z.data(), dz.data(), alpha, &k);
  block = k;
  return a;
}
double max_step(const Eigen::VectorXd& z, const Eigen::VectorXd& dz, double alpha) {
  Eigen::Index ignored;
  return max_step_index(z, dz, alpha, ignored);
}

// Step length along (Δt, Δλ), one for primal and dual (the stationarity couples Δv and Δλ), by
// Mehrotra's heuristic (Mehrotra 1992; Nocedal & Wright, Numerical Optimization, §14.2). With
// α_max the largest step keeping t, λ ≥ 0, p its blocking component, ᾱ = min(1, α_max) and
// μ⁺ = (t + ᾱΔt)ᵀ(λ + ᾱΔλ)/m the complementarity after it, the step stops where the blocking pair
// keeps γ_f μ⁺: t_p + αΔt_p = γ_f μ⁺ / (λ_p + ᾱΔλ_p) (likewise for a blocking λ_p), but never
// shorter than the fixed rule η α_max. Far from the solution this keeps t_p λ_p near γ_f times the
// mean, like the fixed fraction; near it μ⁺ → 0 and α → α_max: the fixed rule's (1 − η) leftover,
// which limits the decrease of μ to 1/(1 − η) = 200× per iteration, disappears (fast local
// convergence needs η_k → 1). μ⁺ is floored at the tolerance tol_comp: a complementarity below
// it is of no use, and pushing t_p far below it while stationarity still has to converge makes
// W = λ/t overflow the solve's accuracy (seen in SQP on an exact-penalty obstacle constraint).
double step_length(const QpRiccatiIpmWorkspace& w, double eta, double tol_comp) {
  if (w.m_total == 0) return 1.0;  // no inequalities: Δt = Δλ = 0
  constexpr double kBeyond = 1e3;  // α_max is searched up to here (beyond the full step)
  Eigen::Index pt, pl;
  const double at = max_step_index(w.t, w.dt, kBeyond, pt);
  const double al = max_step_index(w.lam, w.dlam, kBeyond, pl);
  const double abar = std::min({1.0, at, al});
  const double mu_plus = std::max(
      tol_comp, (w.lam + abar * w.dlam).dot(w.t + abar * w.dt) / static_cast<double>(w.m_total));
  const double gf = qp_defaults::kStepCentrality;
  double a_t = std::min(1.0, at), a_l = std::min(1.0, al);
  // std::max keeps η α_max when the target is not finite (0/0 at a degenerate pair).
  if (pt >= 0) {
    const double target = gf * mu_plus / (w.lam[pt] + abar * w.dlam[pt]);
    a_t = std::min(1.0, std::max(eta * at, (target - w.t[pt]) / w.dt[pt]));
  }
  if (pl >= 0) {
    const double target = gf * mu_plus / (w.t[pl] + abar * w.dt[pl]);
    a_l = std::min(1.0, std::max(eta * al, (target - w.lam[pl]) / w.dlam[pl]));
  }
  return std::min(a_t, a_l);
}
}  // namespace

void QpRiccatiIpm::prepare(const OcpQp& qp) {
  loaded_ = prefactored_ = false;
  if (!ready_ || !ocp_qp_valid_for(qp, ws_.dims, settings_.check_data)) return;
  load(qp);
  loaded_ = true;
}

void QpRiccatiIpm::prepare(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) {
  prepare(qp);
  if (!loaded_ || warm != QpWarmStart::primal_dual || ws_.dims.N == 0) return;
  // Stages 1..N start from `start` whatever x0 is; stage 0 (x_0 = x0) is initialized again in
  // solve(). Their factorization needs W = λ/t and the Hessian only.
  Workspace& w = ws_;
  const int N = w.dims.N;
  for (int i = 1; i <= N; ++i) initialize_stage(qp, start, warm, i);
  prefactored_ = factorize(qp, 1, N);
  if (!prefactored_) return;
  // ... and their share of the first iteration's residuals and of its predictor's backward pass
  // (stage 1's residual reads π_0, which stage 0's initialization sets to the same start).
  w.pi.segment(w.off_pi[0], w.dims.nx[1]) = start.pi[0];
  stage_residuals(qp, 1, N);
  const int m1 = w.off_m[1], m = static_cast<int>(w.t.size()) - m1;
  w.rc.segment(m1, m) =
      w.mask.segment(m1, m).cwiseProduct(w.lam.segment(m1, m).cwiseProduct(w.t.segment(m1, m)));
  backward_pass(qp, w.res_v, w.res_s, w.res_pi, w.res_t, w.rc, 1, N);
}

QpStatus QpRiccatiIpm::solve(const OcpQp& qp, OcpQpSolution& sol, QpWarmStart warm) {
  const bool loaded = loaded_;
  const bool prefactored = prefactored_ && warm == QpWarmStart::primal_dual;
  loaded_ = prefactored_ = false;
  if (!ready_ || (!loaded && !ocp_qp_valid_for(qp, ws_.dims, settings_.check_data)) ||
      (loaded && settings_.check_data && !qp.x0.allFinite()))  // prepare() checked the rest
    return sol.set_invalid_data();
  if (!loaded) load(qp);
  if (prefactored)
    initialize_stage(qp, sol, warm, 0);  // the rest is the prepared start
  else
    initialize(qp, sol, warm);
  int it = 0;
  QpStatus status = iterate(qp, settings_.max_iterations, it, prefactored);
  if (status == QpStatus::min_step && warm != QpWarmStart::cold) {
    int it_cold = 0;
    initialize(qp, sol, QpWarmStart::cold);
    status = iterate(qp, settings_.max_iterations - it, it_cold);
    it += it_cold;
  }
  sol.iterations = it;
  write_solution(qp, sol);
  sol.status = status;
  return status;
}

QpStatus QpRiccatiIpm::iterate(const OcpQp& qp, int max_iterations, int& it, bool prefactored) {
  Workspace& w = ws_;
  const Settings& cfg = settings_;
  QpStatus status = QpStatus::max_iterations;
  for (it = 0;; ++it) {
    const bool prepared = it == 0 && prefactored;  // stages N..1 of this iteration done
    stage_residuals(qp, 0, prepared ? 0 : w.dims.N);
    residual_norms();
    if (!(std::isfinite(res_stat_) && std::isfinite(res_eq_) && std::isfinite(res_ineq_) &&
          std::isfinite(mu_))) {
      status = QpStatus::nan_detected;  // cannot happen from finite data; kept as a guard
      break;
    }
    if (res_stat_ <= cfg.tol_stat && res_eq_ <= cfg.tol_eq && res_ineq_ <= cfg.tol_ineq &&
        mu_ <= cfg.tol_comp) {
      status = QpStatus::success;
      break;
    }
    if (it >= max_iterations) {
      status = QpStatus::max_iterations;
      break;
    }
    const bool factorized = prepared ? factorize(qp, 0, 0) : factorize(qp, 0, w.dims.N);
    if (!factorized) {
      status = QpStatus::factorization_failed;
      break;
    }
    // Predictor (affine scaling) direction.
    w.rc = w.mask.cwiseProduct(w.lam.cwiseProduct(w.t));
    // Refinement only pays once the barrier weights W = λ/t ≳ λ²/μ are large, i.e. near the
    // end; the predictor only sets σ and the second-order term and is never refined.
    const bool refine = mu_ < qp_defaults::kRefineMuRatio * cfg.tol_comp;
    newton_direction(qp, w.m_total == 0, refine, prepared ? 0 : w.dims.N);
    double target = 0.0;  // centring target of the corrector
    if (w.m_total > 0) {
      double a_aff = max_step(w.t, w.dt, 1.0);
      a_aff = max_step(w.lam, w.dlam, a_aff);
      const double mu_aff =
          (w.lam + a_aff * w.dlam).dot(w.t + a_aff * w.dt) / static_cast<double>(w.m_total);
      const double ratio = mu_ > 0.0 ? mu_aff / mu_ : 0.0;
      const double sigma = std::clamp(ratio * ratio * ratio, 0.0, 1.0);
      // Corrector: Mehrotra's second-order term and centring, same factorization. The centring
      // target is floored at kCentringFloor · tol_comp: a complementarity below the tolerance
      // buys nothing, and once μ is there while stationarity still converges (the solve's error
      // grows with W = λ/t ~ λ²/μ), driving μ on to 1e-20 and below ruins the Newton directions
      // (SQP on an exact-penalty obstacle constraint ended in factorization_failed).
      target = std::max(sigma * mu_, qp_defaults::kCentringFloor * cfg.tol_comp);
      w.rc = w.mask.cwiseProduct(w.lam.cwiseProduct(w.t) + w.dlam.cwiseProduct(w.dt) -
                                 Eigen::VectorXd::Constant(w.t.size(), target));
      newton_direction(qp, true, refine);
    }
    const double check = w.dv.sum() + w.dpi.sum() + w.ds.sum() + w.dt.sum() + w.dlam.sum();
    if (!std::isfinite(check)) {
      status = QpStatus::nan_detected;
      break;
    }
    double alpha = step_length(w, cfg.step_fraction, cfg.tol_comp);
    if (w.m_total > 0 && target <= cfg.tol_comp && alpha >= qp_defaults::kFinalStepMin) {
      // Would this step end the solve? Linear residuals shrink to (1 − α) of theirs.
      const double left = 1.0 - alpha;
      const double mu_plus =
          (w.lam + alpha * w.dlam).dot(w.t + alpha * w.dt) / static_cast<double>(w.m_total);
      if (mu_plus > cfg.tol_comp && left * res_stat_ <= cfg.tol_stat &&
          left * res_eq_ <= cfg.tol_eq && left * res_ineq_ <= cfg.tol_ineq) {
        // Only μ would miss: correct with the corrector's own second-order term Δλ∘Δt.
        w.rc = w.mask.cwiseProduct(w.lam.cwiseProduct(w.t) + w.dlam.cwiseProduct(w.dt) -
                                   Eigen::VectorXd::Constant(w.t.size(), target));
        newton_direction(qp, true, refine);
        if (!std::isfinite(w.dv.sum() + w.dpi.sum() + w.ds.sum() + w.dt.sum() + w.dlam.sum())) {
          status = QpStatus::nan_detected;
          break;
        }
        alpha = step_length(w, cfg.step_fraction, cfg.tol_comp);
      }
    }
    if (alpha < cfg.min_step) {
      status = QpStatus::min_step;
      break;
    }
    w.v += alpha * w.dv;
    w.pi += alpha * w.dpi;
    w.s += alpha * w.ds;
    w.t += alpha * w.dt;
    w.lam += alpha * w.dlam;
  }
  return status;
}

void QpRiccatiIpm::write_solution(const OcpQp& qp, OcpQpSolution& sol) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  double f = 0.0;
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& st = qp.stage[i];
    const int nu = d.nu[i], nx = d.nx[i], ns = d.ns[i], nc = w.nc[i];
    const int ov = w.off_v[i], os = w.off_s[i], om = w.off_m[i];
    sol.u[i] = w.v.segment(ov, nu);
    sol.x[i] = w.v.segment(ov + nu, nx);
    if (i < d.N) sol.pi[i] = w.pi.segment(w.off_pi[i], d.nx[i + 1]);
    sol.lam_l[i] = w.lam.segment(om, nc);
    sol.lam_u[i] = w.lam.segment(om + nc, nc);
    sol.sl[i] = w.s.segment(os, ns);
    sol.su[i] = w.s.segment(os + ns, ns);
    sol.lam_sl[i] = w.lam.segment(om + 2 * nc, ns);
    sol.lam_su[i] = w.lam.segment(om + 2 * nc + ns, ns);
    for (int j = 0; j < ns; ++j) {  // dead sides: λ_s from their stationarity Z s + z − λ_s = 0
      if (w.slive[os + j] == 0.0) sol.lam_sl[i][j] = st.Zl[j] * sol.sl[i][j] + st.zl[j];
      if (w.slive[os + ns + j] == 0.0) sol.lam_su[i][j] = st.Zu[j] * sol.su[i][j] + st.zu[j];
    }
    // ½vᵀHv + gᵀv = ½uᵀ(R u + 2 S x) + ½xᵀQ x + rᵀu + qᵀx (the kernels: Eigen's products
    // cost more in their set-up than in their arithmetic at these sizes).
    auto tmp = w.tmp[i].head(std::max(nu, nx));
    const double* u = w.v.data() + ov;
    const double* x = u + nu;
    if (nu > 0) {
      tmp.head(nu).setZero();
      kernels::gemv_n(nu, nx, st.S.data(), nu, x, tmp.data());
      tmp.head(nu) *= 2.0;
      kernels::gemv_n(nu, nu, st.R.data(), nu, u, tmp.data());
      f += 0.5 * sol.u[i].dot(tmp.head(nu)) + st.r.dot(sol.u[i]);
    }
    if (nx > 0) {
      tmp.head(nx).setZero();
      kernels::gemv_n(nx, nx, st.Q.data(), nx, x, tmp.data());
      f += 0.5 * sol.x[i].dot(tmp.head(nx)) + st.q.dot(sol.x[i]);
    }
    f += 0.5 * sol.sl[i].dot(st.Zl.cwiseProduct(sol.sl[i])) + st.zl.dot(sol.sl[i]);
    f += 0.5 * sol.su[i].dot(st.Zu.cwiseProduct(sol.su[i])) + st.zu.dot(sol.su[i]);
  }
  sol.lam_x0 = w.res_v.segment(d.nu[0], d.nx[0]);
  sol.objective = f;
  sol.res_stat = res_stat_;
  sol.res_eq = res_eq_;
  sol.res_ineq = res_ineq_;
  sol.res_comp = mu_;
}

}  // namespace mixpilot
