#include "core/qp_condensed_dense.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace mixpilot {

bool QpCondensedDense::setup(const OcpQpDims& dims, const Settings& settings) {
  settings_ = settings;
  ready_ = false;
  prepared_ = false;
  if (!dims.valid()) return false;
  Workspace& w = ws_;
  w.dims = dims;
  const int N = dims.N;
  const std::size_t n1 = static_cast<std::size_t>(N) + 1;
  w.off_u.assign(n1, 0);
  w.off_bu.assign(n1, 0);
  w.off_g.assign(n1, 0);
  w.off_s.assign(n1, 0);
  w.off_x.assign(n1, 0);
  int nU = 0, nbu = 0, ng = 0, ns = 0, nxs = 0, nx_max = 0, nu_max = 0, nc_max = 0;
  for (int i = 0; i <= N; ++i) {
    w.off_u[i] = nU;
    w.off_bu[i] = nbu;
    w.off_g[i] = ng;
    w.off_s[i] = ns;
    w.off_x[i] = nxs;
    nU += dims.nu[i];
    nbu += dims.nbu[i];
    ng += dims.nbx[i] + dims.ng[i];
    ns += dims.ns[i];
    nxs += dims.nx[i];
    nx_max = std::max(nx_max, dims.nx[i]);
    nu_max = std::max(nu_max, dims.nu[i]);
    nc_max = std::max(nc_max, dims.nc(i));
  }
  OcpQpDims& c = w.cdims;
  c = OcpQpDims(0);
  c.nu[0] = nU;
  c.nbu[0] = nbu;
  c.ng[0] = ng;
  c.ns[0] = ns;
  w.Gam.assign(n1, {});
  for (int i = 0; i <= N; ++i) w.Gam[i] = Eigen::MatrixXd::Zero(dims.nx[i], nU);
  w.P = w.P1 = w.PA = Eigen::MatrixXd::Zero(nx_max, nx_max);
  w.PB = Eigen::MatrixXd::Zero(nx_max, nu_max);
  w.M = w.M1 = Eigen::MatrixXd::Zero(nU, nx_max);
  w.M0 = Eigen::MatrixXd::Zero(nU, dims.nx[0]);
  w.p = w.p1 = w.pb = w.gx = Eigen::VectorXd::Zero(nx_max);
  w.gu = Eigen::VectorXd::Zero(nu_max);
  w.h = Eigen::VectorXd::Zero(nU);
  w.xi = Eigen::VectorXd::Zero(nxs);
  w.dl = Eigen::VectorXd::Zero(nc_max);
  w.cqp.resize(c);
  w.csol.resize(c);
  Settings inner = settings;
  inner.check_data = false;  // the OCP-QP itself is checked before condensing
  if (!ipm_.setup(c, inner)) return false;
  ready_ = true;
  return true;
}

// Everything of the condensed QP that does not depend on x0: Hessian, x0-free gradient h, the
// x0 → gradient map M_0, the constraint rows, input bounds and slack data.
void QpCondensedDense::condense(const OcpQp& qp) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const int N = d.N, nU = w.cdims.nu[0], nbu_c = w.cdims.nbu[0];
  OcpQpStage& cs = w.cqp.stage[0];
  Eigen::MatrixXd& H = cs.R;
  // Backward recursion. Stage N: P = Q_N, p = q_N, M = S_N, h = r_N, H block R_N.
  {
    const OcpQpStage& s = qp.stage[N];
    const int nx = d.nx[N], nu = d.nu[N], r0 = w.off_u[N];
    w.P.topLeftCorner(nx, nx) = s.Q;
    w.p.head(nx) = s.q;
    if (nu > 0) {
      w.M.block(r0, 0, nu, nx) = s.S;
      w.h.segment(r0, nu) = s.r;
      H.block(r0, r0, nu, nu) = s.R;
    }
  }
  for (int k = N - 1; k >= 0; --k) {
    const OcpQpStage& s = qp.stage[k];
    const int nx = d.nx[k], nx1 = d.nx[k + 1], nu = d.nu[k];
    const int r0 = w.off_u[k], r1 = w.off_u[k + 1], nr = nU - r1;
    auto P = w.P.topLeftCorner(nx1, nx1);
    auto PA = w.PA.topLeftCorner(nx1, nx);
    auto PB = w.PB.topLeftCorner(nx1, nu);
    auto pb = w.pb.head(nx1);
    PA.noalias() = P * s.A;
    PB.noalias() = P * s.B;
    pb = w.p.head(nx1);
    pb.noalias() += P * s.b;
    auto Mn = w.M.block(r1, 0, nr, nx1);  // M_{k+1}
    // Hessian column block of u_k (lower part; mirrored at the end).
    H.block(r0, r0, nu, nu) = s.R;
    H.block(r0, r0, nu, nu).noalias() += s.B.transpose() * PB;
    H.block(r1, r0, nr, nu).noalias() = Mn * s.B;
    // Linear terms.
    w.h.segment(r0, nu) = s.r;
    w.h.segment(r0, nu).noalias() += s.B.transpose() * pb;
    w.h.segment(r1, nr).noalias() += Mn * s.b;
    w.p1.head(nx) = s.q;
    w.p1.head(nx).noalias() += s.A.transpose() * pb;
    // Cross terms M_k and P_k.
    w.M1.block(r0, 0, nu, nx) = s.S;
    w.M1.block(r0, 0, nu, nx).noalias() += PB.transpose() * s.A;
    w.M1.block(r1, 0, nr, nx).noalias() = Mn * s.A;
    if (k > 0) {
      w.P1.topLeftCorner(nx, nx) = s.Q;
      w.P1.topLeftCorner(nx, nx).noalias() += s.A.transpose() * PA;
    }
    std::swap(w.P, w.P1);
    std::swap(w.M, w.M1);
    std::swap(w.p, w.p1);
  }
  w.M0 = w.M.leftCols(d.nx[0]);
  H.triangularView<Eigen::StrictlyUpper>() = H.transpose();
  // Γ_{i+1} = A_i Γ_i + B_i E_i (columns of u_0..u_{i−1}, then B_i; the rest stays zero).
  for (int i = 0; i < N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int c0 = w.off_u[i];
    if (c0 > 0) w.Gam[i + 1].leftCols(c0).noalias() = s.A * w.Gam[i].leftCols(c0);
    w.Gam[i + 1].middleCols(c0, d.nu[i]) = s.B;
  }
  // Rows: state bounds Γ_i[idx, :], general rows C_i Γ_i + D_i E_i; input boxes; slacks.
  for (int i = 0; i <= N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nbu = d.nbu[i], nbx = d.nbx[i], ng = d.ng[i], ns = d.ns[i];
    const int c0 = w.off_u[i], g0 = w.off_g[i], b0 = w.off_bu[i], s0 = w.off_s[i];
    for (int k = 0; k < nbx; ++k) cs.D.row(g0 + k).head(c0) = w.Gam[i].row(s.idxbx[k]).head(c0);
    if (ng > 0) {
      if (c0 > 0) cs.D.block(g0 + nbx, 0, ng, c0).noalias() = s.C * w.Gam[i].leftCols(c0);
      cs.D.block(g0 + nbx, c0, ng, d.nu[i]) = s.D;
    }
    for (int k = 0; k < nbu; ++k) {
      cs.idxbu[b0 + k] = c0 + s.idxbu[k];
      cs.lbu[b0 + k] = s.lbu[k];
      cs.ubu[b0 + k] = s.ubu[k];
    }
    for (int j = 0; j < ns; ++j) {
      const int k = s.idxs[j];
      cs.idxs[s0 + j] = k < nbu ? b0 + k : nbu_c + g0 + (k - nbu);
      cs.Zl[s0 + j] = s.Zl[j];
      cs.Zu[s0 + j] = s.Zu[j];
      cs.zl[s0 + j] = s.zl[j];
      cs.zu[s0 + j] = s.zu[j];
    }
  }
}

// The x0-dependent part: gradient h + M_0 x0 and the state rows' bounds shifted by ξ.
void QpCondensedDense::embed_x0(const OcpQp& qp) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  OcpQpStage& cs = w.cqp.stage[0];
  const double big = settings_.inf_bound;
  cs.r = w.h;
  cs.r.noalias() += w.M0 * qp.x0;
  w.xi.head(d.nx[0]) = qp.x0;
  for (int i = 0; i < d.N; ++i) {
    auto xn = w.xi.segment(w.off_x[i + 1], d.nx[i + 1]);
    xn = qp.stage[i].b;
    xn.noalias() += qp.stage[i].A * w.xi.segment(w.off_x[i], d.nx[i]);
  }
  auto shifted = [big](double b, double c) {
    return std::isfinite(b) && std::abs(b) < big ? b - c : b;  // absent sides stay absent
  };
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nbx = d.nbx[i], ng = d.ng[i], g0 = w.off_g[i];
    const auto xi = w.xi.segment(w.off_x[i], d.nx[i]);
    for (int k = 0; k < nbx; ++k) {
      const double c = xi[s.idxbx[k]];
      cs.lg[g0 + k] = shifted(s.lbx[k], c);
      cs.ug[g0 + k] = shifted(s.ubx[k], c);
    }
    for (int k = 0; k < ng; ++k) {
      const double c = s.C.row(k).dot(xi);
      cs.lg[g0 + nbx + k] = shifted(s.lg[k], c);
      cs.ug[g0 + nbx + k] = shifted(s.ug[k], c);
    }
  }
}

void QpCondensedDense::warm_start(const OcpQpSolution& sol, QpWarmStart warm) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const int nbu_c = w.cdims.nbu[0], nc_c = w.cdims.nc(0);
  OcpQpSolution& c = w.csol;
  for (int i = 0; i <= d.N; ++i) {
    const int nbu = d.nbu[i], nc = d.nc(i), ns = d.ns[i], s0 = w.off_s[i];
    c.u[0].segment(w.off_u[i], d.nu[i]) = sol.u[i];
    c.sl[0].segment(s0, ns) = sol.sl[i];
    c.su[0].segment(s0, ns) = sol.su[i];
    if (warm != QpWarmStart::primal_dual) continue;
    for (int k = 0; k < nc; ++k) {
      const int kc = k < nbu ? w.off_bu[i] + k : nbu_c + w.off_g[i] + (k - nbu);
      c.lam_l[0][kc] = sol.lam_l[i][k];
      c.lam_u[0][kc] = sol.lam_u[i][k];
    }
    c.lam_sl[0].segment(s0, ns) = sol.lam_sl[i];
    c.lam_su[0].segment(s0, ns) = sol.lam_su[i];
  }
  (void)nc_c;
}

void QpCondensedDense::recover(const OcpQp& qp, OcpQpSolution& sol) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const OcpQpSolution& c = w.csol;
  const int nbu_c = w.cdims.nbu[0];
  // Inputs, slacks, multipliers; states by forward simulation.
  sol.x[0] = qp.x0;
  for (int i = 0; i <= d.N; ++i) {
    const int nbu = d.nbu[i], nc = d.nc(i), ns = d.ns[i], s0 = w.off_s[i];
    sol.u[i] = c.u[0].segment(w.off_u[i], d.nu[i]);
    for (int k = 0; k < nc; ++k) {
      const int kc = k < nbu ? w.off_bu[i] + k : nbu_c + w.off_g[i] + (k - nbu);
      sol.lam_l[i][k] = c.lam_l[0][kc];
      sol.lam_u[i][k] = c.lam_u[0][kc];
    }
    sol.sl[i] = c.sl[0].segment(s0, ns);
    sol.su[i] = c.su[0].segment(s0, ns);
    sol.lam_sl[i] = c.lam_sl[0].segment(s0, ns);
    sol.lam_su[i] = c.lam_su[0].segment(s0, ns);
    if (i < d.N) {
      const OcpQpStage& s = qp.stage[i];
      sol.x[i + 1] = s.b;
      sol.x[i + 1].noalias() += s.A * sol.x[i];
      sol.x[i + 1].noalias() += s.B * sol.u[i];
    }
  }
  // π and λ_x0 from the x-stationarity, backwards; the objective on the way.
  double f = 0.0;
  for (int i = d.N; i >= 0; --i) {
    const OcpQpStage& s = qp.stage[i];
    const int nx = d.nx[i], nbu = d.nbu[i], nbx = d.nbx[i], ng = d.ng[i], nc = d.nc(i);
    const auto& x = sol.x[i];
    const auto& u = sol.u[i];
    auto gx = w.gx.head(nx);
    auto dl = w.dl.head(nc);
    dl = sol.lam_u[i] - sol.lam_l[i];
    gx.noalias() = s.Q * x;
    f += 0.5 * x.dot(gx) + s.q.dot(x);
    gx += s.q;
    gx.noalias() += s.S.transpose() * u;
    if (i < d.N) gx.noalias() += s.A.transpose() * sol.pi[i];
    for (int k = 0; k < nbx; ++k) gx[s.idxbx[k]] += dl[nbu + k];
    if (ng > 0) gx.noalias() += s.C.transpose() * dl.tail(ng);
    if (i > 0)
      sol.pi[i - 1] = gx;
    else
      sol.lam_x0 = gx;
    if (d.nu[i] > 0) {  // ½uᵀRu + uᵀS x + rᵀu through a preallocated buffer
      auto gu = w.gu.head(d.nu[i]);
      gu.noalias() = s.S * x;
      gu.noalias() += 0.5 * s.R * u;
      f += u.dot(gu) + s.r.dot(u);
    }
    for (int j = 0; j < d.ns[i]; ++j) {
      f += (0.5 * s.Zl[j] * sol.sl[i][j] + s.zl[j]) * sol.sl[i][j];
      f += (0.5 * s.Zu[j] * sol.su[i][j] + s.zu[j]) * sol.su[i][j];
    }
  }
  sol.objective = f;
  sol.iterations = c.iterations;
  sol.res_stat = c.res_stat;
  sol.res_eq = 0.0;  // the dynamics hold exactly by construction
  sol.res_ineq = c.res_ineq;
  sol.res_comp = c.res_comp;
}

void QpCondensedDense::prepare(const OcpQp& qp) {
  prepared_ = false;
  if (!ready_ || qp.dims.N != ws_.dims.N || qp.dims.nx != ws_.dims.nx ||
      qp.dims.nu != ws_.dims.nu || qp.dims.nbx != ws_.dims.nbx || qp.dims.nbu != ws_.dims.nbu ||
      qp.dims.ng != ws_.dims.ng || qp.dims.ns != ws_.dims.ns || !ocp_qp_indices_valid(qp))
    return;
  condense(qp);
  prepared_ = true;
}

QpStatus QpCondensedDense::solve(const OcpQp& qp, OcpQpSolution& sol, QpWarmStart warm) {
  Workspace& w = ws_;
  const bool prepared = prepared_;
  prepared_ = false;
  auto fail_invalid = [&] {
    for (auto* vs : {&sol.x, &sol.u, &sol.pi, &sol.lam_l, &sol.lam_u, &sol.sl, &sol.su,
                     &sol.lam_sl, &sol.lam_su})
      for (auto& v : *vs) v.setZero();
    sol.lam_x0.setZero();
    sol.iterations = 0;
    sol.objective = sol.res_stat = sol.res_eq = sol.res_ineq = sol.res_comp = 0.0;
    sol.status = QpStatus::invalid_data;
    return sol.status;
  };
  if (!ready_ || qp.dims.N != w.dims.N || qp.dims.nx != w.dims.nx || qp.dims.nu != w.dims.nu ||
      qp.dims.nbx != w.dims.nbx || qp.dims.nbu != w.dims.nbu || qp.dims.ng != w.dims.ng ||
      qp.dims.ns != w.dims.ns || !ocp_qp_indices_valid(qp))
    return fail_invalid();
  if (settings_.check_data && !ocp_qp_data_finite(qp)) return fail_invalid();
  if (!prepared) condense(qp);
  embed_x0(qp);
  if (warm != QpWarmStart::cold) warm_start(sol, warm);
  QpSettings& inner = ipm_.settings();
  inner = settings_;
  inner.check_data = false;
  const QpStatus status = ipm_.solve(w.cqp, w.csol, warm);
  if (status == QpStatus::invalid_data) return fail_invalid();
  recover(qp, sol);
  sol.status = status;
  return status;
}

}  // namespace mixpilot
