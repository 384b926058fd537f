#include "core/qp/qp_dense_active_set.hpp"

#include <algorithm>
#include <cmath>

// Sides are indexed s = k (lower side of row k) and s = nc + k (upper side). With a_k = ∇d_k,
// the multipliers enter the stationarity as  H u + g + Σ_k a_k (λ_u,k − λ_l,k) = 0,  and the
// violation of a side is v = d_k − ub_k (upper) or lb_k − d_k (lower). A general row in hold
// carries the signed multiplier ν = λ_u (upper) or −λ_l (lower), the coefficient of a_k.
// All loops run on raw pointers over the actual sizes (n ≈ 10: overhead would dominate).

namespace mixpilot {

namespace {
enum : int { kInactive = 0, kHold = 1, kPenalty = 2 };
}  // namespace

bool QpDenseActiveSet::setup(const OcpQpDims& dims, const Settings& settings) {
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
  const int n = w.n, ng = w.ng, nc = w.nc;
  w.D = nullptr;
  w.dl = Eigen::VectorXd::Zero(ng);
  w.box = Eigen::VectorXi::Zero(w.nb);
  w.soft_of = Eigen::VectorXi::Constant(nc, -1);
  w.bnd = w.Zs = w.zs = w.lam = Eigen::VectorXd::Zero(2 * nc);
  w.present = w.state = Eigen::VectorXi::Zero(2 * nc);
  w.d = Eigen::VectorXd::Zero(nc);
  w.H = w.L = Eigen::MatrixXd::Zero(n, n);
  w.g = w.u = w.y = w.grad = Eigen::VectorXd::Zero(n);
  w.fixed = w.freev = w.fixv = Eigen::VectorXi::Zero(n);
  w.hold = Eigen::VectorXi::Zero(nc);
  w.Y = Eigen::MatrixXd::Zero(n, ng);
  w.S = Eigen::MatrixXd::Zero(ng, ng);
  w.nu = Eigen::VectorXd::Zero(ng);
  return true;
}

bool QpDenseActiveSet::load(const OcpQpStage& st) {
  Workspace& w = ws_;
  const int nb = w.nb, nc = w.nc, ns = w.ns;
  const double big = settings_.inf_bound;
  w.D = st.D.data();
  for (int k = 0; k < nb; ++k) w.box[k] = st.idxbu[k];
  for (int k = 0; k < nc; ++k) {
    w.soft_of[k] = -1;
    const double lo = k < nb ? st.lbu[k] : st.lg[k - nb];
    const double hi = k < nb ? st.ubu[k] : st.ug[k - nb];
    const bool has_lo = std::isfinite(lo) && std::abs(lo) < big;
    const bool has_hi = std::isfinite(hi) && std::abs(hi) < big;
    w.present[k] = has_lo;
    w.present[nc + k] = has_hi;
    w.bnd[k] = has_lo ? lo : 0.0;
    w.bnd[nc + k] = has_hi ? hi : 0.0;
    w.Zs[k] = w.Zs[nc + k] = w.zs[k] = w.zs[nc + k] = 0.0;
  }
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    if (!(st.Zl[j] >= 0.0 && st.Zu[j] >= 0.0 && st.zl[j] >= 0.0 && st.zu[j] >= 0.0))
      return false;  // ψ is then not the convex penalty above
    w.soft_of[k] = j;
    w.Zs[k] = st.Zl[j];
    w.Zs[nc + k] = st.Zu[j];
    w.zs[k] = st.zl[j];
    w.zs[nc + k] = st.zu[j];
  }
  return true;
}

void QpDenseActiveSet::initialize(const OcpQpStage& st, const OcpQpSolution& sol,
                                  QpWarmStart warm) {
  Workspace& w = ws_;
  const int nc = w.nc, nb = w.nb, n = w.n;
  const double tol_p = settings_.tol_ineq, tol_d = settings_.tol_stat;
  int* state = w.state.data();
  for (int s = 0; s < 2 * nc; ++s) state[s] = kInactive;
  if (warm == QpWarmStart::cold) return;
  // primal: the sides the given u violates or meets; primal_dual: the sides with a multiplier
  // (a soft side with a positive slack in penalty).
  const double* u = sol.u[0].data();
  for (int k = 0; k < nc; ++k) {
    double dk = 0.0;  // d_k(u), for the primal warm start
    if (warm == QpWarmStart::primal && k < nb) {
      dk = u[w.box[k]];
    } else if (warm == QpWarmStart::primal) {
      const double* a = w.D + (k - nb);  // row k − nb of D, stride ng
      for (int c = 0; c < n; ++c) dk += a[std::ptrdiff_t(c) * w.ng] * u[c];
    }
    const int j = w.soft_of[k];
    for (int side = 0; side < 2; ++side) {
      const int s = side * nc + k;
      if (!w.present[s]) continue;
      if (warm == QpWarmStart::primal_dual) {
        const double lam = side ? sol.lam_u[0][k] : sol.lam_l[0][k];
        const double slack = j < 0 ? 0.0 : side ? sol.su[0][j] : sol.sl[0][j];
        if (j >= 0 && slack > tol_p)
          state[s] = kPenalty;
        else if (lam > tol_d && (j < 0 || w.zs[s] > 0.0))
          state[s] = kHold;
      } else {
        const double v = side ? dk - w.bnd[s] : w.bnd[s] - dk;
        if (j >= 0 && v > tol_p)
          state[s] = kPenalty;
        else if (j < 0 && v > -tol_p)
          state[s] = kHold;
      }
    }
    if (state[k] == kHold && state[nc + k] == kHold) state[k] = kInactive;
  }
  (void)st;
}

namespace {

// x = L⁻¹ x for the nf x nf lower factor L (leading dimension ld).
void forward_solve(const double* L, int ld, int nf, double* x) {
  for (int p = 0; p < nf; ++p) {
    const double* lp = L + std::ptrdiff_t(p) * ld;
    const double xp = x[p] / lp[p];
    x[p] = xp;
    for (int r = p + 1; r < nf; ++r) x[r] -= lp[r] * xp;
  }
}

}  // namespace

// The equality-constrained QP of the current states: u, d(u) and every side's multiplier.
QpStatus QpDenseActiveSet::solve_states(const OcpQpStage& st) {
  assemble(st);
  if (const QpStatus s = factor_free(); s != QpStatus::success) return s;
  if (const QpStatus s = project_holds(); s != QpStatus::success) return s;
  return recover();
}

// H̃ = R + Σ_pen Z aaᵀ and g̃ = r + Σ_pen a(z − Z b) of the current penalty sides.
void QpDenseActiveSet::assemble(const OcpQpStage& st) {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, nc = w.nc;
  double* H = w.H.data();
  double* g = w.g.data();
  const int* state = w.state.data();
  const double* R = st.R.data();
  for (int i = 0; i < n * n; ++i) H[i] = R[i];
  for (int c = 0; c < n; ++c) g[c] = st.r[c];
  // Penalty sides: H += Z aaᵀ, g += a(z − Z ub) (upper) or −a(z + Z lb) (lower).
  for (int s = 0; s < 2 * nc; ++s) {
    if (state[s] != kPenalty) continue;
    const int k = s < nc ? s : s - nc;
    const double Z = w.Zs[s];
    const double gc = s < nc ? -(w.zs[s] + Z * w.bnd[s]) : w.zs[s] - Z * w.bnd[s];
    if (k < nb) {
      const int c = w.box[k];
      H[c + std::ptrdiff_t(c) * n] += Z;
      g[c] += gc;
    } else {
      const double* a = w.D + (k - nb);  // row k − nb of D, stride ng
      const int ng = w.ng;
      for (int c = 0; c < n; ++c) {
        const double ac = a[std::ptrdiff_t(c) * ng];
        if (ac == 0.0) continue;  // condensed state rows are causal: trailing zeros
        double* hc = H + std::ptrdiff_t(c) * n;
        for (int r = 0; r < n; ++r) hc[r] += Z * ac * a[std::ptrdiff_t(r) * ng];
        g[c] += gc * ac;
      }
    }
  }
}

// Boxes in hold fix their variable; the free ones F get y = −(g_F + H_FX u_X), the Cholesky
// factor L of H̃_FF, and y ← L⁻¹ y.
QpStatus QpDenseActiveSet::factor_free() {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, nc = w.nc;
  const double* H = w.H.data();
  const double* g = w.g.data();
  double* u = w.u.data();
  const int* state = w.state.data();
  int* fixed = w.fixed.data();
  for (int c = 0; c < n; ++c) fixed[c] = -1;
  for (int s = 0; s < 2 * nc; ++s) {
    const int k = s < nc ? s : s - nc;
    if (k >= nb || state[s] != kHold) continue;
    const int c = w.box[k];
    if (fixed[c] >= 0) {  // two bounds on one variable: drop this one, as a dependent row
      w.state[s] = kInactive;
      return QpStatus::min_step;
    }
    fixed[c] = s;
    u[c] = w.bnd[s];
  }
  int* F = w.freev.data();
  int* X = w.fixv.data();
  int nf = 0, nx = 0;
  for (int c = 0; c < n; ++c) {
    if (fixed[c] < 0)
      F[nf++] = c;
    else
      X[nx++] = c;
  }
  // L = chol(H_FF) in place, column by column.
  double* y = w.y.data();
  double* L = w.L.data();
  for (int p = 0; p < nf; ++p) {
    const int c = F[p];
    double v = g[c];
    for (int q = 0; q < nx; ++q) v += H[c + std::ptrdiff_t(X[q]) * n] * u[X[q]];
    y[p] = -v;
    for (int q = p; q < nf; ++q) L[q + std::ptrdiff_t(p) * n] = H[F[q] + std::ptrdiff_t(c) * n];
  }
  for (int p = 0; p < nf; ++p) {
    double* lp = L + std::ptrdiff_t(p) * n;
    for (int q = 0; q < p; ++q) {  // lp[p..] −= L[p..,q] L[p,q]
      const double* lq = L + std::ptrdiff_t(q) * n;
      const double f = lq[p];
      for (int r = p; r < nf; ++r) lp[r] -= lq[r] * f;
    }
    const double piv = lp[p];
    if (!(piv > settings_.psd_tol * std::abs(H[F[p] + std::ptrdiff_t(F[p]) * n])) ||
        !std::isfinite(piv))
      return QpStatus::factorization_failed;
    const double d = std::sqrt(piv), inv = 1.0 / d;
    lp[p] = d;
    for (int r = p + 1; r < nf; ++r) lp[r] *= inv;
  }
  forward_solve(L, n, nf, y);
  w.nf = nf;
  w.nfix = nx;
  return QpStatus::success;
}

// General rows in hold: Y = L⁻¹ A_hFᵀ, S = YᵀY, ν = S⁻¹(Yᵀy − b'), y −= Y ν.
QpStatus QpDenseActiveSet::project_holds() {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, nc = w.nc, nf = w.nf, nx = w.nfix;
  const int* state = w.state.data();
  const int* F = w.freev.data();
  const int* X = w.fixv.data();
  const double* u = w.u.data();
  const double* L = w.L.data();
  double* y = w.y.data();
  int* hold = w.hold.data();
  int nh = 0;
  for (int s = 0; s < 2 * nc; ++s) {
    const int k = s < nc ? s : s - nc;
    if (k >= nb && state[s] == kHold) hold[nh++] = s;
  }
  double* nu = w.nu.data();
  if (nh > 0) {
    double* Y = w.Y.data();
    double* S = w.S.data();
    const int ldS = static_cast<int>(w.S.outerStride());
    for (int h = 0; h < nh; ++h) {
      const int s = hold[h], k = (s < nc ? s : s - nc) - nb;
      const double* a = w.D + k;  // row k of D, stride ng
      const std::ptrdiff_t ng = w.ng;
      double* yh = Y + std::ptrdiff_t(h) * n;
      double b = w.bnd[s];
      for (int q = 0; q < nx; ++q) b -= a[X[q] * ng] * u[X[q]];
      for (int p = 0; p < nf; ++p) yh[p] = a[F[p] * ng];
      forward_solve(L, n, nf, yh);
      double r = -b;
      for (int p = 0; p < nf; ++p) r += yh[p] * y[p];
      nu[h] = r;
      for (int h2 = 0; h2 <= h; ++h2) {
        const double* y2 = Y + std::ptrdiff_t(h2) * n;
        double v = 0.0;
        for (int p = 0; p < nf; ++p) v += yh[p] * y2[p];
        S[h + std::ptrdiff_t(h2) * ldS] = v;
      }
    }
    for (int p = 0; p < nh; ++p) {  // Cholesky of S (lower), then S ν = rhs
      double* sp = S + std::ptrdiff_t(p) * ldS;
      for (int q = 0; q < p; ++q) {
        const double* sq = S + std::ptrdiff_t(q) * ldS;
        for (int r = p; r < nh; ++r) sp[r] -= sq[r] * sq[p];
      }
      const double piv = sp[p];
      double scale = 0.0;
      for (int q = 0; q < nf; ++q) {
        const double yq = Y[q + std::ptrdiff_t(p) * n];
        scale += yq * yq;
      }
      if (!(piv > 1e-12 * scale) || !std::isfinite(piv)) {
        // Row p depends on the fixed variables and rows 0..p−1: drop it and solve again (if it
        // was consistent with them it is implied; if not, the states cycle to max_iterations).
        w.state[hold[p]] = kInactive;
        return QpStatus::min_step;
      }
      const double d = std::sqrt(piv), inv = 1.0 / d;
      sp[p] = d;
      for (int r = p + 1; r < nh; ++r) sp[r] *= inv;
    }
    for (int p = 0; p < nh; ++p) {
      const double* sp = S + std::ptrdiff_t(p) * ldS;
      nu[p] /= sp[p];
      for (int r = p + 1; r < nh; ++r) nu[r] -= sp[r] * nu[p];
    }
    for (int p = nh - 1; p >= 0; --p) {
      const double* sp = S + std::ptrdiff_t(p) * ldS;
      double v = nu[p];
      for (int r = p + 1; r < nh; ++r) v -= sp[r] * nu[r];
      nu[p] = v / sp[p];
    }
    for (int h = 0; h < nh; ++h) {
      const double* yh = Y + std::ptrdiff_t(h) * n;
      for (int p = 0; p < nf; ++p) y[p] -= yh[p] * nu[h];
    }
  }
  w.nh = nh;
  return QpStatus::success;
}

// u_F = L⁻ᵀ y, then d(u) and the multipliers of every side.
QpStatus QpDenseActiveSet::recover() {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, nc = w.nc, nf = w.nf, nx = w.nfix, nh = w.nh;
  const double* H = w.H.data();
  const double* g = w.g.data();
  const double* L = w.L.data();
  const int* state = w.state.data();
  const int* fixed = w.fixed.data();
  const int* F = w.freev.data();
  const int* X = w.fixv.data();
  const int* hold = w.hold.data();
  const double* nu = w.nu.data();
  double* u = w.u.data();
  double* y = w.y.data();
  // u_F = L⁻ᵀ y.
  for (int p = nf - 1; p >= 0; --p) {
    const double* lp = L + std::ptrdiff_t(p) * n;
    double v = y[p];
    for (int r = p + 1; r < nf; ++r) v -= lp[r] * y[r];
    y[p] = v / lp[p];
  }
  for (int p = 0; p < nf; ++p) u[F[p]] = y[p];
  // d(u) and the multipliers.
  double* dd = w.d.data();
  double* lam = w.lam.data();
  for (int k = 0; k < nb; ++k) dd[k] = u[w.box[k]];
  {
    const int ng = w.ng;
    double* dg = dd + nb;
    for (int k = 0; k < ng; ++k) dg[k] = 0.0;
    for (int c = 0; c < n; ++c) {  // D u as axpys over the columns of D
      const double uc = u[c];
      const double* col = w.D + std::ptrdiff_t(c) * ng;
      for (int k = 0; k < ng; ++k) dg[k] += col[k] * uc;
    }
  }
  for (int s = 0; s < 2 * nc; ++s) {
    const int k = s < nc ? s : s - nc;
    const double v = s < nc ? w.bnd[s] - dd[k] : dd[k] - w.bnd[s];
    lam[s] = state[s] == kPenalty ? w.zs[s] + w.Zs[s] * v : 0.0;
  }
  for (int h = 0; h < nh; ++h) lam[hold[h]] = hold[h] < nc ? -nu[h] : nu[h];
  // Fixed variables: the box multiplier closes the stationarity of their row,
  // ν_c = −(H̃ u + g̃ + Σ_h a_h ν_h)_c.
  for (int q = 0; q < nx; ++q) {
    const int c = X[q];
    double v = g[c];
    for (int r = 0; r < n; ++r) v += H[c + std::ptrdiff_t(r) * n] * u[r];  // H̃ symmetric
    for (int h = 0; h < nh; ++h) {
      const int k = (hold[h] < nc ? hold[h] : hold[h] - nc) - nb;
      v += w.D[k + std::ptrdiff_t(c) * w.ng] * nu[h];
    }
    lam[fixed[c]] = fixed[c] < nc ? v : -v;
  }
  for (int c = 0; c < n; ++c)
    if (!std::isfinite(u[c])) return QpStatus::nan_detected;
  return QpStatus::success;
}

bool QpDenseActiveSet::update_states() {
  Workspace& w = ws_;
  const int nc = w.nc;
  const double tol_p = settings_.tol_ineq, tol_d = settings_.tol_stat;
  int* state = w.state.data();
  bool moved = false;
  int add = -1;  // the most violated inactive general side that would go to hold
  double add_v = 0.0;
  for (int s = 0; s < 2 * nc; ++s) {
    if (!w.present[s]) continue;
    const int k = s < nc ? s : s - nc;
    const bool soft = w.soft_of[k] >= 0;
    const double v = s < nc ? w.bnd[s] - w.d[k] : w.d[k] - w.bnd[s];
    const double lam = w.lam[s], z = w.zs[s];
    int next = state[s];
    if (state[s] == kInactive) {
      if (v > tol_p) {
        next = soft && z <= 0.0 ? kPenalty : kHold;
        if (next == kHold && k >= w.nb) {
          const double* a = w.D + (k - w.nb);
          double nrm = 0.0;
          for (int c = 0; c < w.n; ++c) {
            const double ac = a[std::ptrdiff_t(c) * w.ng];
            nrm += ac * ac;
          }
          const double scaled = nrm > 0.0 ? v / std::sqrt(nrm) : v;
          if (scaled > add_v) add_v = scaled, add = s;
          next = kInactive;
        }
      }
    } else if (state[s] == kHold) {
      if (lam < -tol_d)
        next = kInactive;
      else if (soft && lam > z + tol_d)
        next = kPenalty;
    } else if (w.Zs[s] * v < -tol_d || v < -tol_p) {
      next = z > 0.0 ? kHold : kInactive;
    }
    moved = moved || next != state[s];
    state[s] = next;
  }
  // General rows enter the hold set one at a time (most violated first, relative to ‖a‖): all at
  // once, the violated rows of a cold start are typically dependent.
  if (add >= 0) {
    state[add] = kHold;
    moved = true;
  }
  return moved;
}

void QpDenseActiveSet::write_solution(const OcpQpStage& st, OcpQpSolution& sol) {
  Workspace& w = ws_;
  const int n = w.n, nb = w.nb, nc = w.nc, ns = w.ns;
  const double* R = st.R.data();
  const double* u = w.u.data();
  double* grad = w.grad.data();
  double f = 0.0;
  for (int c = 0; c < n; ++c) {
    double rc = 0.0;
    for (int r = 0; r < n; ++r) rc += R[r + std::ptrdiff_t(c) * n] * u[r];
    f += u[c] * (0.5 * rc + st.r[c]);
    grad[c] = rc + st.r[c];
    sol.u[0][c] = u[c];
  }
  double res_ineq = 0.0, res_comp = 0.0;
  for (int k = 0; k < nc; ++k) {
    const double ll = w.lam[k], lu = w.lam[nc + k];
    sol.lam_l[0][k] = ll;
    sol.lam_u[0][k] = lu;
    if (k < nb)
      grad[w.box[k]] += lu - ll;
    else
      w.dl[k - nb] = lu - ll;
    const int j = w.soft_of[k];
    for (int side = 0; side < 2; ++side) {
      const int s = side * nc + k;
      if (!w.present[s]) continue;
      const double v = side ? w.d[k] - w.bnd[s] : w.bnd[s] - w.d[k];
      const double slack = j >= 0 && w.state[s] == kPenalty ? std::max(v, 0.0) : 0.0;
      res_ineq = std::max(res_ineq, v - slack);
      res_comp = std::max(res_comp, std::abs(w.lam[s] * (v - slack)));
    }
  }
  for (int j = 0; j < ns; ++j) {
    const int k = st.idxs[j];
    const int sl_ = k, su_ = nc + k;
    const double sl = w.present[sl_] && w.state[sl_] == kPenalty ? std::max(w.bnd[sl_] - w.d[k], 0.0)
                                                                   : 0.0;
    const double su = w.present[su_] && w.state[su_] == kPenalty ? std::max(w.d[k] - w.bnd[su_], 0.0)
                                                                   : 0.0;
    sol.sl[0][j] = sl;
    sol.su[0][j] = su;
    // Slack stationarity Z s + z − λ_b − λ_s = 0 (λ_s = 0 where s ≥ 0 is not a constraint:
    // z = 0 and Z > 0, then λ_b = Z s).
    const bool ml = st.zl[j] != 0.0 || st.Zl[j] <= 0.0, mu = st.zu[j] != 0.0 || st.Zu[j] <= 0.0;
    sol.lam_sl[0][j] = ml ? std::max(st.Zl[j] * sl + st.zl[j] - w.lam[k], 0.0) : 0.0;
    sol.lam_su[0][j] = mu ? std::max(st.Zu[j] * su + st.zu[j] - w.lam[nc + k], 0.0) : 0.0;
    f += (0.5 * st.Zl[j] * sl + st.zl[j]) * sl + (0.5 * st.Zu[j] * su + st.zu[j]) * su;
  }
  double res_stat = 0.0;
  for (int c = 0; c < n; ++c) {  // + Dᵀ(λ_u − λ_l) of the general rows
    const double* col = w.D + std::ptrdiff_t(c) * w.ng;
    double v = 0.0;
    for (int k = 0; k < w.ng; ++k) v += col[k] * w.dl[k];
    res_stat = std::max(res_stat, std::abs(grad[c] + v));
  }
  sol.objective = f;
  sol.res_stat = res_stat;
  sol.res_eq = 0.0;  // no equality constraints
  sol.res_ineq = res_ineq;
  sol.res_comp = res_comp;  // max |λ (v − s)|: zero up to rounding by construction
}

QpStatus QpDenseActiveSet::solve(const OcpQp& qp, OcpQpSolution& sol, QpWarmStart warm) {
  Workspace& w = ws_;
  if (!ready_ || !ocp_qp_valid_for(qp, w.dims, settings_.check_data))
    return sol.set_invalid_data();
  const OcpQpStage& st = qp.stage[0];
  if (!load(st)) return sol.set_invalid_data();
  initialize(st, sol, warm);

  QpStatus status = QpStatus::max_iterations;
  int it = 0;
  while (it < settings_.max_iterations) {
    ++it;
    status = solve_states(st);
    if (status == QpStatus::min_step && it < settings_.max_iterations) continue;  // row dropped
    if (status != QpStatus::success) break;
    if (!update_states()) break;  // no state moved: KKT point
    status = QpStatus::max_iterations;
  }
  sol.iterations = it;
  if (status == QpStatus::success || status == QpStatus::max_iterations) {
    write_solution(st, sol);
  } else {  // no finite iterate of these states: the warm start stays, multipliers cleared
    for (int k = 0; k < w.nc; ++k) sol.lam_l[0][k] = sol.lam_u[0][k] = 0.0;
    for (int c = 0; c < w.n; ++c)
      if (!std::isfinite(sol.u[0][c])) sol.u[0][c] = 0.0;
    sol.objective = 0.0;
  }
  sol.status = status;
  return status;
}

}  // namespace mixpilot
