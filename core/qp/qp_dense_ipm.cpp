#include "core/qp/qp_dense_ipm.hpp"

#include <algorithm>
#include <cmath>

// Notation of core/qp_riccati_ipm.cpp with v = u (no states, no dynamics):
//   d(u) = [u[idxbu]; D u] (nc),  inequalities [lb; ub; ls; us] with t ≥ 0:
//     t_lb = d − lb + J_l s_l,  t_ub = ub − d + J_u s_u,  t_ls = s_l,  t_us = s_u,
//   r_u = R u + r + ∇dᵀ(λ_ub − λ_lb),  r_s = Z s + z − Jᵀλ_b − λ_s,  r_t = (expression) − t.
// Newton step: W = λ/t, ρ = (r_c + λ∘r_t)/t, Ψ_l = Zl + W_lb + W_ls (likewise u);
//   (R + ∇dᵀ W̃ ∇d) Δu = −(r_u + ∇dᵀ g̃),  W̃ = W_lb (Zl + W_ls)/Ψ_l + W_ub (Zu + W_us)/Ψ_u,
//   Δs_l = Ψ_l⁻¹(−r_sl − ρ_lb − ρ_ls − W_lb ∇dΔu),  Δs_u = Ψ_u⁻¹(−r_su − ρ_ub − ρ_us + W_ub ∇dΔu),
//   Δt from the linearized inequalities, Δλ = −(r_c + λ∘Δt)/t.
// All loops run on raw pointers over the actual sizes: at n ≈ 10 the cost of an iteration is a
// few hundred flops, and any per-operation overhead would dominate it.

namespace mixpilot {

namespace {

// Largest α ∈ (0, alpha] with z + α dz ≥ 0 componentwise (z > 0), from inv_z = 1/z:
// α = min(alpha, 1 / max_k(−dz_k/z_k)); four accumulators so the loop vectorizes.
double max_step(int m, const double* __restrict dz, const double* __restrict inv_z, double alpha) {
  double r[4] = {0.0, 0.0, 0.0, 0.0};
  int k = 0;
  for (; k + 4 <= m; k += 4)
    for (int l = 0; l < 4; ++l) r[l] = std::max(r[l], -dz[k + l] * inv_z[k + l]);
  for (; k < m; ++k) r[0] = std::max(r[0], -dz[k] * inv_z[k]);
  const double q = std::max(std::max(r[0], r[1]), std::max(r[2], r[3]));
  return q * alpha > 1.0 ? 1.0 / q : alpha;
}

double norm_inf(int n, const double* x) {
  double r[4] = {0.0, 0.0, 0.0, 0.0};
  int k = 0;
  for (; k + 4 <= n; k += 4)
    for (int l = 0; l < 4; ++l) r[l] = std::max(r[l], std::abs(x[k + l]));
  for (; k < n; ++k) r[0] = std::max(r[0], std::abs(x[k]));
  return std::max(std::max(r[0], r[1]), std::max(r[2], r[3]));
}

// Σ_k x_k y_k (y = nullptr: Σ_k x_k), four accumulators.
double dot(int n, const double* x, const double* y) {
  double r[4] = {0.0, 0.0, 0.0, 0.0};
  int k = 0;
  for (; k + 4 <= n; k += 4)
    for (int l = 0; l < 4; ++l) r[l] += x[k + l] * (y ? y[k + l] : 1.0);
  for (; k < n; ++k) r[0] += x[k] * (y ? y[k] : 1.0);
  return (r[0] + r[1]) + (r[2] + r[3]);
}

}  // namespace

bool QpDenseIpm::setup(const OcpQpDims& dims, const Settings& settings) {
  settings_ = settings;
  ready_ = dims.valid() && dims.N == 0 && dims.nx[0] == 0;
  if (!ready_) return false;
  Workspace& w = ws_;
  w.dims = dims;
  w.n = dims.nu[0];
  w.nb = dims.nbu[0];
  w.ng = dims.ng[0];
  w.nc = w.nb + w.ng;
  w.ns = dims.ns[0];
  w.m = 2 * w.nc + 2 * w.ns;
  w.Dt = Eigen::MatrixXd::Zero(w.n, w.ng);
  w.len = Eigen::VectorXi::Zero(w.ng);
  w.L = Eigen::MatrixXd::Zero(w.n, w.n);
  w.box = Eigen::VectorXi::Zero(w.nb);
  w.soft_of = Eigen::VectorXi::Constant(w.nc, -1);
  for (Eigen::VectorXd* p : {&w.u, &w.du, &w.res_u, &w.l, &w.err_u, &w.cu, &w.hdiag, &w.inv_diag})
    *p = Eigen::VectorXd::Zero(w.n);
  for (Eigen::VectorXd* p : {&w.s, &w.ds, &w.res_s, &w.err_s, &w.cs, &w.zflat})
    *p = Eigen::VectorXd::Zero(2 * w.ns);
  for (Eigen::VectorXd* p : {&w.t, &w.dt, &w.lam, &w.dlam, &w.res_t, &w.mask, &w.w, &w.rc,
                             &w.rho, &w.ct, &w.clam, &w.zero_m, &w.inv_t, &w.inv_lam})
    *p = Eigen::VectorXd::Zero(w.m);
  for (Eigen::VectorXd* p : {&w.lbnd, &w.ubnd, &w.wc, &w.gc, &w.dd})
    *p = Eigen::VectorXd::Zero(w.nc);
  w.psi_l = Eigen::VectorXd::Zero(w.ns);
  w.psi_u = Eigen::VectorXd::Zero(w.ns);
  return true;
}

void QpDenseIpm::load(const OcpQpStage& st) {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, ng = w.ng, nc = w.nc, ns = w.ns;
  const double big = settings_.inf_bound;
  for (int k = 0; k < ng; ++k) {
    double* col = w.Dt.data() + std::ptrdiff_t(k) * n;
    int len = 0;
    for (int c = 0; c < n; ++c) {
      col[c] = st.D(k, c);
      if (col[c] != 0.0) len = c + 1;
    }
    w.len[k] = len;
  }
  for (int k = 0; k < nb; ++k) w.box[k] = st.idxbu[k];
  for (int k = 0; k < nc; ++k) w.soft_of[k] = -1;
  for (int j = 0; j < ns; ++j) {
    w.soft_of[st.idxs[j]] = j;
    w.zflat[j] = st.zl[j];
    w.zflat[ns + j] = st.zu[j];
  }
  int present = 0;
  for (int k = 0; k < nc; ++k) {
    const double lo = k < nb ? st.lbu[k] : st.lg[k - nb];
    const double hi = k < nb ? st.ubu[k] : st.ug[k - nb];
    const bool has_lo = std::isfinite(lo) && std::abs(lo) < big;
    const bool has_hi = std::isfinite(hi) && std::abs(hi) < big;
    w.lbnd[k] = has_lo ? lo : 0.0;
    w.ubnd[k] = has_hi ? hi : 0.0;
    w.mask[k] = has_lo ? 1.0 : 0.0;
    w.mask[nc + k] = has_hi ? 1.0 : 0.0;
    present += has_lo + has_hi;
  }
  // s ≥ 0 only where it can bind: an ℓ1 term or no ℓ2² weight (as in the Riccati IPM).
  for (int j = 0; j < ns; ++j) {
    const bool l = st.zl[j] != 0.0 || st.Zl[j] <= 0.0, u = st.zu[j] != 0.0 || st.Zu[j] <= 0.0;
    w.mask[2 * nc + j] = l ? 1.0 : 0.0;
    w.mask[2 * nc + ns + j] = u ? 1.0 : 0.0;
    present += l + u;
  }
  w.m_total = present;
}

void QpDenseIpm::constraints(const OcpQpStage& st, const double* v, double* dd) const {
  const Workspace& w = ws_;
  const int n = w.n, nb = w.nb, ng = w.ng;
  for (int k = 0; k < nb; ++k) dd[k] = v[w.box[k]];
  double* dg = dd + nb;
  for (int k = 0; k < ng; ++k) dg[k] = 0.0;
  const double* D = st.D.data();  // ng x n, column-major: D u as axpys over its columns
  for (int c = 0; c < n; ++c) {
    const double vc = v[c];
    const double* col = D + std::ptrdiff_t(c) * ng;
    for (int k = 0; k < ng; ++k) dg[k] += vc * col[k];
  }
}

void QpDenseIpm::initialize(const OcpQpStage& st, const OcpQpSolution& sol, QpWarmStart warm) {
  Workspace& w = ws_;
  const int n = w.n, nc = w.nc, ns = w.ns, m = w.m;
  const bool primal = warm != QpWarmStart::cold;
  const bool dual = warm == QpWarmStart::primal_dual;
  // Warm: one floor for t and λ, warm_start_violated (1e-4): the dense IPM is the active set's
  // fallback on short horizons and was not measured with the Riccati IPM's smaller floors.
  const double thr = dual ? settings_.warm_start_violated : settings_.init_slack;
  double* s = w.s.data();
  double* t = w.t.data();
  double* lam = w.lam.data();
  for (int c = 0; c < n; ++c) w.u[c] = primal ? sol.u[0][c] : 0.0;
  for (int j = 0; j < ns; ++j) {
    s[j] = primal ? std::max(sol.sl[0][j], 0.0) : 0.0;
    s[ns + j] = primal ? std::max(sol.su[0][j], 0.0) : 0.0;
  }
  constraints(st, w.u.data(), w.dd.data());
  for (int k = 0; k < nc; ++k) {
    const int j = w.soft_of[k];
    const double sl = j >= 0 ? s[j] : 0.0, su = j >= 0 ? s[ns + j] : 0.0;
    t[k] = w.dd[k] - w.lbnd[k] + sl;
    t[nc + k] = w.ubnd[k] - w.dd[k] + su;
    if (dual) {
      lam[k] = sol.lam_l[0][k];
      lam[nc + k] = sol.lam_u[0][k];
    }
  }
  for (int j = 0; j < 2 * ns; ++j) t[2 * nc + j] = s[j];
  if (dual)
    for (int j = 0; j < ns; ++j) {
      lam[2 * nc + j] = sol.lam_sl[0][j];
      lam[2 * nc + ns + j] = sol.lam_su[0][j];
    }
  for (int k = 0; k < m; ++k) {
    if (w.mask[k] == 0.0) {
      t[k] = 1.0;
      lam[k] = 0.0;
      continue;
    }
    t[k] = std::max(t[k], thr);
    lam[k] = dual ? std::max(lam[k], thr) : settings_.init_mu / t[k];
  }
  if (dual) return;
  // Cold λ_s on the slack's stationarity (see QpRiccatiIpm::initialize): λ_s =
  // max(μ0/t_s, Z s + z − λ_b).
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    const int ml = 2 * nc + j, mu = 2 * nc + ns + j;
    if (w.mask[ml] != 0.0) lam[ml] = std::max(lam[ml], st.Zl[j] * s[j] + st.zl[j] - lam[k]);
    if (w.mask[mu] != 0.0)
      lam[mu] = std::max(lam[mu], st.Zu[j] * s[ns + j] + st.zu[j] - lam[nc + k]);
  }
}

void QpDenseIpm::linear_residual(const OcpQpStage& st, const double* v, const double* s,
                                 const double* lam, const double* g, const double* z,
                                 double* out_u, double* out_s) const {
  const Workspace& w = ws_;
  const int n = w.n, nb = w.nb, ng = w.ng, nc = w.nc, ns = w.ns;
  const double* R = st.R.data();
  for (int r = 0; r < n; ++r) out_u[r] = g[r];
  for (int c = 0; c < n; ++c) {
    const double vc = v[c];
    const double* col = R + std::ptrdiff_t(c) * n;
    for (int r = 0; r < n; ++r) out_u[r] += vc * col[r];
  }
  for (int k = 0; k < nb; ++k) out_u[w.box[k]] += lam[nc + k] - lam[k];
  const double* Dt = w.Dt.data();
  for (int k = 0; k < ng; ++k) {
    const double a = lam[nc + nb + k] - lam[nb + k];
    const double* col = Dt + std::ptrdiff_t(k) * n;
    const int len = w.len[k];
    for (int r = 0; r < len; ++r) out_u[r] += a * col[r];
  }
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    out_s[j] = st.Zl[j] * s[j] + z[j] - lam[k] - lam[2 * nc + j];
    out_s[ns + j] = st.Zu[j] * s[ns + j] + z[ns + j] - lam[nc + k] - lam[2 * nc + ns + j];
  }
}

double QpDenseIpm::stationarity_norm(const double* ru, const double* rs) const {
  return std::max(norm_inf(ws_.n, ru), norm_inf(2 * ws_.ns, rs));
}

void QpDenseIpm::residuals(const OcpQpStage& st) {
  Workspace& w = ws_;
  const int nc = w.nc, ns = w.ns, m = w.m;
  linear_residual(st, w.u.data(), w.s.data(), w.lam.data(), st.r.data(), w.zflat.data(),
                  w.res_u.data(), w.res_s.data());
  constraints(st, w.u.data(), w.dd.data());
  const double* s = w.s.data();
  const double* t = w.t.data();
  const double* mask = w.mask.data();
  double* rt = w.res_t.data();
  for (int k = 0; k < nc; ++k) {
    const int j = w.soft_of[k];
    const double sl = j >= 0 ? s[j] : 0.0, su = j >= 0 ? s[ns + j] : 0.0;
    rt[k] = mask[k] * (w.dd[k] - w.lbnd[k] + sl - t[k]);
    rt[nc + k] = mask[nc + k] * (w.ubnd[k] - w.dd[k] + su - t[nc + k]);
  }
  for (int j = 0; j < 2 * ns; ++j) rt[2 * nc + j] = mask[2 * nc + j] * (s[j] - t[2 * nc + j]);
  res_stat_ = stationarity_norm(w.res_u.data(), w.res_s.data());
  res_ineq_ = norm_inf(m, rt);
  mu_ = w.m_total > 0 ? dot(m, w.lam.data(), t) / w.m_total : 0.0;
}

bool QpDenseIpm::factorize(const OcpQpStage& st) {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, ng = w.ng, nc = w.nc, ns = w.ns, m = w.m;
  double* __restrict W = w.w.data();
  double* __restrict inv_t = w.inv_t.data();
  double* __restrict inv_lam = w.inv_lam.data();
  const double* __restrict mask = w.mask.data();
  const double* __restrict lam = w.lam.data();
  const double* __restrict t = w.t.data();
  for (int k = 0; k < m; ++k) {  // absent sides: t = 1, λ = 0, so W = 0 and 1/λ := 0
    inv_t[k] = 1.0 / t[k];
    inv_lam[k] = mask[k] / (lam[k] + (1.0 - mask[k]));
    W[k] = mask[k] * lam[k] * inv_t[k];
  }
  double* wc = w.wc.data();
  for (int k = 0; k < nc; ++k) wc[k] = W[k] + W[nc + k];
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    const double wl = W[k], wu = W[nc + k];
    const double cl = st.Zl[j] + W[2 * nc + j], cu = st.Zu[j] + W[2 * nc + ns + j];
    const double pl = 1.0 / (cl + wl), pu = 1.0 / (cu + wu);
    w.psi_l[j] = pl;
    w.psi_u[j] = pu;
    wc[k] = wl * cl * pl + wu * cu * pu;  // W − W²/Ψ without the cancellation
  }
  // H̃ (lower triangle) = R + boxes + Σ_k W̃_k D_kᵀ D_k over each row's leading nonzeros.
  double* L = w.L.data();
  const double* R = st.R.data();
  for (int c = 0; c < n; ++c)
    for (int r = c; r < n; ++r) L[r + std::ptrdiff_t(c) * n] = R[r + std::ptrdiff_t(c) * n];
  for (int k = 0; k < nb; ++k) L[w.box[k] * std::ptrdiff_t(n + 1)] += wc[k];
  const double* Dt = w.Dt.data();
  for (int k = 0; k < ng; ++k) {
    const double wk = wc[nb + k];
    if (wk == 0.0) continue;
    const double* __restrict y = Dt + std::ptrdiff_t(k) * n;
    const int len = w.len[k];
    for (int c = 0; c < len; ++c) {
      const double a = wk * y[c];
      double* __restrict col = L + std::ptrdiff_t(c) * n;
      for (int r = c; r < len; ++r) col[r] += a * y[r];
    }
  }
  // In-place right-looking Cholesky with the Riccati kernels' pivot rule for input columns: a
  // pivot p ≤ 0 is a vanished Schur complement (zeroed, pseudo-factor) if H̃_jj > 0 and
  // p ≥ −psd_tol·H̃_jj; otherwise the Hessian is singular or indefinite.
  double* inv_diag = w.inv_diag.data();
  for (int j = 0; j < n; ++j) w.hdiag[j] = L[j * std::ptrdiff_t(n + 1)];
  for (int j = 0; j < n; ++j) {
    double* cj = L + std::ptrdiff_t(j) * n;
    const double p = cj[j];
    double is;
    if (p > 0.0) {
      const double sq = std::sqrt(p);
      is = 1.0 / sq;
      cj[j] = sq;
    } else {
      const double d0 = w.hdiag[j];
      if (!(d0 > 0.0 && p >= -settings_.psd_tol * d0)) return false;
      is = 0.0;
      cj[j] = 0.0;
    }
    inv_diag[j] = is;
    for (int r = j + 1; r < n; ++r) cj[r] *= is;
    for (int c = j + 1; c < n; ++c) {
      const double a = cj[c];
      double* __restrict col = L + std::ptrdiff_t(c) * n;
      for (int r = c; r < n; ++r) col[r] -= a * cj[r];
    }
  }
  return true;
}

void QpDenseIpm::solve_direction(const OcpQpStage& st, const double* ru, const double* rs,
                                 const double* rt, const double* rc, double* du, double* ds,
                                 double* dt, double* dlam) {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, ng = w.ng, nc = w.nc, ns = w.ns, m = w.m;
  const double* mask = w.mask.data();
  const double* lam = w.lam.data();
  const double* W = w.w.data();
  double* __restrict rho = w.rho.data();
  const double* __restrict inv_t = w.inv_t.data();
  for (int k = 0; k < m; ++k) rho[k] = mask[k] * (rc[k] + lam[k] * rt[k]) * inv_t[k];
  double* gc = w.gc.data();
  for (int k = 0; k < nc; ++k) gc[k] = rho[k] - rho[nc + k];
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    // ρ_lb + W_lb Ψ_l⁻¹(−r_sl − ρ_lb − ρ_ls) without cancelling O(W) terms; likewise upper.
    const double gl =
        (rho[k] * (st.Zl[j] + W[2 * nc + j]) + W[k] * (-rs[j] - rho[2 * nc + j])) * w.psi_l[j];
    const double gu = (rho[nc + k] * (st.Zu[j] + W[2 * nc + ns + j]) +
                       W[nc + k] * (-rs[ns + j] - rho[2 * nc + ns + j])) *
                      w.psi_u[j];
    gc[k] = gl - gu;
  }
  // Right-hand side r_u + ∇dᵀ g̃, then L Lᵀ x = it and Δu = −x.
  double* x = w.l.data();
  for (int r = 0; r < n; ++r) x[r] = ru[r];
  for (int k = 0; k < nb; ++k) x[w.box[k]] += gc[k];
  const double* Dt = w.Dt.data();
  for (int k = 0; k < ng; ++k) {
    const double a = gc[nb + k];
    const double* col = Dt + std::ptrdiff_t(k) * n;
    const int len = w.len[k];
    for (int r = 0; r < len; ++r) x[r] += a * col[r];
  }
  const double* L = w.L.data();
  const double* inv_diag = w.inv_diag.data();
  for (int j = 0; j < n; ++j) {  // L y = x (column axpys)
    const double yj = x[j] * inv_diag[j];
    x[j] = yj;
    const double* cj = L + std::ptrdiff_t(j) * n;
    for (int r = j + 1; r < n; ++r) x[r] -= yj * cj[r];
  }
  for (int j = n - 1; j >= 0; --j) {  // Lᵀ x = y (column dots)
    const double* cj = L + std::ptrdiff_t(j) * n;
    double v = x[j];
    for (int r = j + 1; r < n; ++r) v -= cj[r] * x[r];
    x[j] = v * inv_diag[j];
  }
  for (int r = 0; r < n; ++r) du[r] = -x[r];
  // Δt, Δs, Δλ.
  double* dd = w.dd.data();
  constraints(st, du, dd);
  for (int k = 0; k < nc; ++k) {
    dt[k] = dd[k] + rt[k];
    dt[nc + k] = -dd[k] + rt[nc + k];
  }
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    const double dsl = (-rs[j] - rho[k] - rho[2 * nc + j] - W[k] * dd[k]) * w.psi_l[j];
    const double dsu =
        (-rs[ns + j] - rho[nc + k] - rho[2 * nc + ns + j] + W[nc + k] * dd[k]) * w.psi_u[j];
    ds[j] = dsl;
    ds[ns + j] = dsu;
    dt[k] += dsl;
    dt[nc + k] += dsu;
    dt[2 * nc + j] = dsl + rt[2 * nc + j];
    dt[2 * nc + ns + j] = dsu + rt[2 * nc + ns + j];
  }
  for (int k = 0; k < m; ++k) {
    dt[k] *= mask[k];
    dlam[k] = -mask[k] * (rc[k] + lam[k] * dt[k]) * inv_t[k];
  }
}

void QpDenseIpm::newton_direction(const OcpQpStage& st, bool final, bool refine) {
  Workspace& w = ws_;
  solve_direction(st, w.res_u.data(), w.res_s.data(), w.res_t.data(), w.rc.data(), w.du.data(),
                  w.ds.data(), w.dt.data(), w.dlam.data());
  const int steps = final && refine ? settings_.refinement_steps : 0;
  // Iterative refinement (see QpRiccatiIpm::newton_direction): the error of the unreduced
  // equations, solved for with the same factorization.
  const double target = settings_.refine_ratio * std::min(settings_.tol_stat, settings_.tol_eq);
  for (int r = 0; r < steps; ++r) {
    linear_residual(st, w.du.data(), w.ds.data(), w.dlam.data(), w.res_u.data(), w.res_s.data(),
                    w.err_u.data(), w.err_s.data());
    const double e = stationarity_norm(w.err_u.data(), w.err_s.data());
    if (!(e > target)) break;
    solve_direction(st, w.err_u.data(), w.err_s.data(), w.zero_m.data(), w.zero_m.data(),
                    w.cu.data(), w.cs.data(), w.ct.data(), w.clam.data());
    w.du += w.cu;
    w.ds += w.cs;
    w.dt += w.ct;
    w.dlam += w.clam;
  }
}

QpStatus QpDenseIpm::solve(const OcpQp& qp, OcpQpSolution& sol, QpWarmStart warm) {
  Workspace& w = ws_;
  if (!ready_ || !ocp_qp_valid_for(qp, w.dims, settings_.check_data))
    return sol.set_invalid_data();
  const OcpQpStage& st = qp.stage[0];
  load(st);
  initialize(st, sol, warm);

  const Settings& cfg = settings_;
  const int m = w.m;
  QpStatus status = QpStatus::max_iterations;
  int it = 0;
  for (;; ++it) {
    residuals(st);
    if (!(std::isfinite(res_stat_) && std::isfinite(res_ineq_) && std::isfinite(mu_))) {
      status = QpStatus::nan_detected;  // cannot happen from finite data; kept as a guard
      break;
    }
    if (res_stat_ <= cfg.tol_stat && res_ineq_ <= cfg.tol_ineq && mu_ <= cfg.tol_comp) {
      status = QpStatus::success;
      break;
    }
    if (it >= cfg.max_iterations) {
      status = QpStatus::max_iterations;
      break;
    }
    if (!factorize(st)) {
      status = QpStatus::factorization_failed;
      break;
    }
    double* t = w.t.data();
    double* lam = w.lam.data();
    double* dt = w.dt.data();
    double* dlam = w.dlam.data();
    double* rc = w.rc.data();
    const double* mask = w.mask.data();
    // Predictor (affine scaling), never refined; corrector with Mehrotra's second-order term
    // and centring σμ, same factorization.
    for (int k = 0; k < m; ++k) rc[k] = mask[k] * lam[k] * t[k];
    const bool refine = mu_ < qp_defaults::kRefineMuRatio * cfg.tol_comp;
    newton_direction(st, w.m_total == 0, refine);
    if (w.m_total > 0) {
      double a_aff = max_step(m, dt, w.inv_t.data(), 1.0);
      a_aff = max_step(m, dlam, w.inv_lam.data(), a_aff);
      double* aff = w.rho.data();  // λ + α Δλ (ρ is recomputed by the corrector)
      for (int k = 0; k < m; ++k) aff[k] = lam[k] + a_aff * dlam[k];
      double* aft = w.ct.data();  // t + α Δt (scratch of the refinement)
      for (int k = 0; k < m; ++k) aft[k] = t[k] + a_aff * dt[k];
      const double mu_aff = dot(m, aff, aft) / static_cast<double>(w.m_total);
      const double ratio = mu_ > 0.0 ? mu_aff / mu_ : 0.0;
      const double sigma = std::clamp(ratio * ratio * ratio, 0.0, 1.0);
      const double smu = sigma * mu_;
      for (int k = 0; k < m; ++k) rc[k] = mask[k] * (lam[k] * t[k] + dlam[k] * dt[k] - smu);
      newton_direction(st, true, refine);
    }
    const double check = dot(w.n, w.du.data(), nullptr) + dot(2 * w.ns, w.ds.data(), nullptr) +
                         dot(m, dt, nullptr) + dot(m, dlam, nullptr);
    if (!std::isfinite(check)) {
      status = QpStatus::nan_detected;
      break;
    }
    double alpha = max_step(m, dt, w.inv_t.data(), 1.0 / cfg.step_fraction);
    alpha = std::min(1.0, cfg.step_fraction * max_step(m, dlam, w.inv_lam.data(), alpha));
    if (alpha < cfg.min_step) {
      status = QpStatus::min_step;
      break;
    }
    for (int r = 0; r < w.n; ++r) w.u[r] += alpha * w.du[r];
    for (int j = 0; j < 2 * w.ns; ++j) w.s[j] += alpha * w.ds[j];
    for (int k = 0; k < m; ++k) {
      t[k] += alpha * dt[k];
      lam[k] += alpha * dlam[k];
    }
  }
  sol.iterations = it;
  write_solution(st, sol);
  sol.status = status;
  return status;
}

void QpDenseIpm::write_solution(const OcpQpStage& st, OcpQpSolution& sol) {
  Workspace& w = ws_;
  const int n = w.n, nc = w.nc, ns = w.ns;
  const double* R = st.R.data();
  double f = 0.0;
  for (int c = 0; c < n; ++c) {
    double rc = 0.0;
    for (int r = 0; r < n; ++r) rc += R[r + std::ptrdiff_t(c) * n] * w.u[r];
    f += w.u[c] * (0.5 * rc + st.r[c]);
    sol.u[0][c] = w.u[c];
  }
  for (int k = 0; k < nc; ++k) {
    sol.lam_l[0][k] = w.lam[k];
    sol.lam_u[0][k] = w.lam[nc + k];
  }
  for (int j = 0; j < ns; ++j) {
    const double sl = w.s[j], su = w.s[ns + j];
    sol.sl[0][j] = sl;
    sol.su[0][j] = su;
    sol.lam_sl[0][j] = w.lam[2 * nc + j];
    sol.lam_su[0][j] = w.lam[2 * nc + ns + j];
    f += (0.5 * st.Zl[j] * sl + st.zl[j]) * sl + (0.5 * st.Zu[j] * su + st.zu[j]) * su;
  }
  sol.objective = f;
  sol.res_stat = res_stat_;
  sol.res_eq = 0.0;  // no equality constraints
  sol.res_ineq = res_ineq_;
  sol.res_comp = mu_;
}

}  // namespace mixpilot
