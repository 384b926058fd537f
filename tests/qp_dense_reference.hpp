#pragma once
// Dense reference for OCP-QPs (tests only). The OCP-QP is written as one dense QP
//   min ½zᵀHz + fᵀz + c   s.t.  E z = e,  G z ≤ h
// over z = (u_0, sl_0, su_0, u_1, x_1, sl_1, su_1, ..., x_N, ...), x_0 substituted. A textbook
// dense Mehrotra interior point (Eigen dense LU on the full KKT matrix) guesses the active set;
// an active-set loop then solves the equality-constrained KKT system exactly, adding violated
// and dropping negative-multiplier constraints until every KKT condition holds to 1e-10. The
// returned optimum is thereby certified, independently of how the active set was found.
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>

#include "core/qp/ocp_qp.hpp"

namespace mixpilot::testing_qp {

struct DenseQp {
  Eigen::MatrixXd H, E, G;
  Eigen::VectorXd f, e, h;
  double c = 0.0;
  std::vector<int> ou, ox, osl, osu;  // offsets per stage (ox[0] = -1)
};

inline DenseQp densify(const OcpQp& qp, double inf_bound = 1e20) {
  const OcpQpDims& d = qp.dims;
  DenseQp D;
  const int N = d.N;
  D.ou.resize(N + 1);
  D.ox.resize(N + 1);
  D.osl.resize(N + 1);
  D.osu.resize(N + 1);
  int nz = 0;
  for (int i = 0; i <= N; ++i) {
    D.ou[i] = nz;
    nz += d.nu[i];
    D.ox[i] = i == 0 ? -1 : nz;
    if (i > 0) nz += d.nx[i];
    D.osl[i] = nz;
    nz += d.ns[i];
    D.osu[i] = nz;
    nz += d.ns[i];
  }
  D.H = Eigen::MatrixXd::Zero(nz, nz);
  D.f = Eigen::VectorXd::Zero(nz);
  int ne = 0;
  for (int i = 1; i <= N; ++i) ne += d.nx[i];
  D.E = Eigen::MatrixXd::Zero(ne, nz);
  D.e = Eigen::VectorXd::Zero(ne);
  std::vector<Eigen::RowVectorXd> grows;
  std::vector<double> hv;
  const Eigen::VectorXd& x0 = qp.x0;
  int row = 0;
  for (int i = 0; i <= N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nu = d.nu[i], nx = d.nx[i], ns = d.ns[i];
    const int ou = D.ou[i], ox = D.ox[i];
    D.H.block(ou, ou, nu, nu) += s.R;
    D.f.segment(ou, nu) += s.r;
    if (i == 0) {
      D.f.segment(ou, nu) += s.S * x0;
      D.c += 0.5 * x0.dot(s.Q * x0) + s.q.dot(x0);
    } else {
      D.H.block(ox, ox, nx, nx) += s.Q;
      D.H.block(ou, ox, nu, nx) += s.S;
      D.H.block(ox, ou, nx, nu) += s.S.transpose();
      D.f.segment(ox, nx) += s.q;
    }
    for (int j = 0; j < ns; ++j) {
      D.H(D.osl[i] + j, D.osl[i] + j) += s.Zl[j];
      D.H(D.osu[i] + j, D.osu[i] + j) += s.Zu[j];
      D.f[D.osl[i] + j] += s.zl[j];
      D.f[D.osu[i] + j] += s.zu[j];
    }
    if (i < N) {
      const int nx1 = d.nx[i + 1];
      D.E.block(row, D.ox[i + 1], nx1, nx1) = Eigen::MatrixXd::Identity(nx1, nx1);
      D.E.block(row, ou, nx1, nu) = -s.B;
      D.e.segment(row, nx1) = s.b;
      if (i == 0)
        D.e.segment(row, nx1) += s.A * x0;
      else
        D.E.block(row, ox, nx1, nx) = -s.A;
      row += nx1;
    }
    // Constraint k as a row over z plus a constant (the x_0 part on stage 0).
    const int nbu = d.nbu[i], nbx = d.nbx[i], nc = d.nc(i);
    for (int k = 0; k < nc; ++k) {
      Eigen::RowVectorXd a = Eigen::RowVectorXd::Zero(nz);
      double a0 = 0.0, lo, hi;
      if (k < nbu) {
        a[ou + s.idxbu[k]] = 1.0;
        lo = s.lbu[k];
        hi = s.ubu[k];
      } else if (k < nbu + nbx) {
        const int p = s.idxbx[k - nbu];
        if (i == 0)
          a0 = x0[p];
        else
          a[ox + p] = 1.0;
        lo = s.lbx[k - nbu];
        hi = s.ubx[k - nbu];
      } else {
        const int g = k - nbu - nbx;
        // (An empty D or C is skipped: Eigen's row() of an empty matrix offsets a null pointer.)
        if (nu > 0) a.segment(ou, nu) = s.D.row(g);
        if (i == 0)
          a0 = nx > 0 ? s.C.row(g).dot(x0) : 0.0;
        else if (nx > 0)
          a.segment(ox, nx) = s.C.row(g);
        lo = s.lg[g];
        hi = s.ug[g];
      }
      int soft = -1;
      for (int j = 0; j < ns; ++j)
        if (s.idxs[j] == k) soft = j;
      if (std::isfinite(lo) && std::abs(lo) < inf_bound) {  // −d − s_l ≤ −lb
        Eigen::RowVectorXd r = -a;
        if (soft >= 0) r[D.osl[i] + soft] = -1.0;
        grows.push_back(r);
        hv.push_back(-lo + a0);
      }
      if (std::isfinite(hi) && std::abs(hi) < inf_bound) {  // d − s_u ≤ ub
        Eigen::RowVectorXd r = a;
        if (soft >= 0) r[D.osu[i] + soft] = -1.0;
        grows.push_back(r);
        hv.push_back(hi - a0);
      }
    }
    for (int j = 0; j < 2 * ns; ++j) {  // s ≥ 0
      Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(nz);
      r[D.osl[i] + j] = -1.0;
      grows.push_back(r);
      hv.push_back(0.0);
    }
  }
  D.G.resize(static_cast<Eigen::Index>(grows.size()), nz);
  D.h.resize(static_cast<Eigen::Index>(grows.size()));
  for (std::size_t k = 0; k < grows.size(); ++k) {
    D.G.row(static_cast<Eigen::Index>(k)) = grows[k];
    D.h[static_cast<Eigen::Index>(k)] = hv[k];
  }
  return D;
}

struct DenseSolution {
  Eigen::VectorXd z;
  double objective = 0.0;
  bool certified = false;
  int active_set_changes = 0;
};

// Textbook dense Mehrotra IPM: returns z and the multipliers λ, slack s of G z + s = h.
inline void dense_ipm(const DenseQp& D, Eigen::VectorXd& z, Eigen::VectorXd& lam,
                      Eigen::VectorXd& sl) {
  const Eigen::Index nz = D.H.rows(), ne = D.E.rows(), m = D.G.rows();
  z = Eigen::VectorXd::Zero(nz);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(ne);
  sl = Eigen::VectorXd::Ones(m);
  lam = Eigen::VectorXd::Ones(m);
  Eigen::MatrixXd K(nz + ne, nz + ne);
  Eigen::VectorXd rhs(nz + ne);
  for (int it = 0; it < 100; ++it) {
    const Eigen::VectorXd rd = D.H * z + D.f + D.E.transpose() * y + D.G.transpose() * lam;
    const Eigen::VectorXd rp = D.E * z - D.e;
    const Eigen::VectorXd ri = D.G * z + sl - D.h;
    const double mu = m > 0 ? lam.dot(sl) / m : 0.0;
    if (rd.lpNorm<Eigen::Infinity>() < 1e-12 && (ne == 0 || rp.lpNorm<Eigen::Infinity>() < 1e-12) &&
        (m == 0 || ri.lpNorm<Eigen::Infinity>() < 1e-12) && mu < 1e-14)
      break;
    const Eigen::VectorXd w = lam.cwiseQuotient(sl);
    K.setZero();
    K.topLeftCorner(nz, nz) = D.H + D.G.transpose() * w.asDiagonal() * D.G;
    K.block(0, nz, nz, ne) = D.E.transpose();
    K.block(nz, 0, ne, nz) = D.E;
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(K);
    auto direction = [&](const Eigen::VectorXd& rc, Eigen::VectorXd& dz, Eigen::VectorXd& ds,
                         Eigen::VectorXd& dl) {
      // Δs = −ri − GΔz;  Δλ = (−rc − λΔs)/s.
      rhs.head(nz) = -rd - D.G.transpose() * ((lam.cwiseProduct(ri) - rc).cwiseQuotient(sl));
      rhs.tail(ne) = -rp;
      const Eigen::VectorXd sol = lu.solve(rhs);
      dz = sol.head(nz);
      ds = -ri - D.G * dz;
      dl = (-rc - lam.cwiseProduct(ds)).cwiseQuotient(sl);
      return Eigen::VectorXd(sol.tail(ne));
    };
    auto step = [&](const Eigen::VectorXd& ds, const Eigen::VectorXd& dl) {
      double a = 1.0;
      for (Eigen::Index k = 0; k < m; ++k) {
        if (ds[k] < 0) a = std::min(a, -sl[k] / ds[k]);
        if (dl[k] < 0) a = std::min(a, -lam[k] / dl[k]);
      }
      return a;
    };
    Eigen::VectorXd dz, ds, dl;
    direction(lam.cwiseProduct(sl), dz, ds, dl);
    const double aa = step(ds, dl);
    const double mu_aff = m > 0 ? (lam + aa * dl).dot(sl + aa * ds) / m : 0.0;
    const double sigma = mu > 0 ? std::pow(mu_aff / mu, 3) : 0.0;
    const Eigen::VectorXd dy = direction(
        lam.cwiseProduct(sl) + dl.cwiseProduct(ds) - Eigen::VectorXd::Constant(m, sigma * mu), dz,
        ds, dl);
    const double a = std::min(1.0, 0.99 * step(ds, dl));
    z += a * dz;
    y += a * dy;
    sl += a * ds;
    lam += a * dl;
  }
}

// With z_guess, the active set is guessed from it (constraints within 1e-7 of their bound)
// instead of by the dense IPM; either way the result is certified by the KKT check below.
inline DenseSolution dense_reference(const OcpQp& qp, const Eigen::VectorXd* z_guess = nullptr) {
  const DenseQp D = densify(qp);
  const Eigen::Index nz = D.H.rows(), ne = D.E.rows(), m = D.G.rows();
  Eigen::VectorXd z, lam, sl;
  std::vector<bool> active(static_cast<std::size_t>(m));
  if (z_guess) {
    z = *z_guess;
    const Eigen::VectorXd g = D.G * z - D.h;
    for (Eigen::Index k = 0; k < m; ++k) active[k] = g[k] > -1e-7 * (1.0 + std::abs(D.h[k]));
  } else {
    dense_ipm(D, z, lam, sl);
    for (Eigen::Index k = 0; k < m; ++k) active[k] = lam[k] > sl[k];
  }
  DenseSolution out;
  for (int loop = 0; loop < 100; ++loop) {
    std::vector<Eigen::Index> act;
    for (Eigen::Index k = 0; k < m; ++k)
      if (active[k]) act.push_back(k);
    const Eigen::Index na = static_cast<Eigen::Index>(act.size());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nz + ne + na, nz + ne + na);
    Eigen::VectorXd rhs(nz + ne + na);
    K.topLeftCorner(nz, nz) = D.H;
    K.block(0, nz, nz, ne) = D.E.transpose();
    K.block(nz, 0, ne, nz) = D.E;
    rhs.head(nz) = -D.f;
    rhs.segment(nz, ne) = D.e;
    for (Eigen::Index a = 0; a < na; ++a) {
      K.block(0, nz + ne + a, nz, 1) = D.G.row(act[a]).transpose();
      K.block(nz + ne + a, 0, 1, nz) = D.G.row(act[a]);
      rhs[nz + ne + a] = D.h[act[a]];
    }
    const Eigen::VectorXd sol = K.partialPivLu().solve(rhs);
    const Eigen::VectorXd zc = sol.head(nz);
    const double kkt_res = (K * sol - rhs).lpNorm<Eigen::Infinity>();
    // Most violated inactive constraint and most negative active multiplier.
    const Eigen::VectorXd viol = D.G * zc - D.h;
    Eigen::Index worst_p = -1, worst_d = -1;
    double vp = 1e-10, vd = -1e-10;
    for (Eigen::Index k = 0; k < m; ++k)
      if (!active[k] && viol[k] > vp * (1.0 + std::abs(D.h[k]))) {
        vp = viol[k] / (1.0 + std::abs(D.h[k]));
        worst_p = k;
      }
    for (Eigen::Index a = 0; a < na; ++a)
      if (sol[nz + ne + a] < vd) {
        vd = sol[nz + ne + a];
        worst_d = act[a];
      }
    if (worst_p < 0 && worst_d < 0 && kkt_res < 1e-9) {
      out.z = zc;
      out.objective = 0.5 * zc.dot(D.H * zc) + D.f.dot(zc) + D.c;
      out.certified = true;
      return out;
    }
    ++out.active_set_changes;
    if (worst_p >= 0)
      active[worst_p] = true;
    else if (worst_d >= 0)
      active[worst_d] = false;
    else
      break;
  }
  out.z = z;
  out.objective = 0.5 * z.dot(D.H * z) + D.f.dot(z) + D.c;
  return out;
}

// The solver's primal solution in the dense layout.
inline Eigen::VectorXd to_dense(const DenseQp& D, const OcpQpDims& d, const OcpQpSolution& s) {
  Eigen::VectorXd z(D.H.rows());
  for (int i = 0; i <= d.N; ++i) {
    z.segment(D.ou[i], d.nu[i]) = s.u[i];
    if (i > 0) z.segment(D.ox[i], d.nx[i]) = s.x[i];
    z.segment(D.osl[i], d.ns[i]) = s.sl[i];
    z.segment(D.osu[i], d.ns[i]) = s.su[i];
  }
  return z;
}

}  // namespace mixpilot::testing_qp
