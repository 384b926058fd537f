#include "core/qp/qp_condensed_dense.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
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
  w.uniform = N > 0 && dims.nu[N] == 0;
  for (int i = 0; i <= N; ++i)
    w.uniform = w.uniform && dims.nx[i] == dims.nx[0] && (i == N || dims.nu[i] == dims.nu[0]);
  Settings inner = settings;
  inner.check_data = false;  // the OCP-QP itself is checked before condensing
  if (!ipm_.setup(c, inner)) return false;
  if (method_ == CondensedQpMethod::active_set && !active_set_.setup(c, inner)) return false;
  ipm_fallbacks_ = 0;
  ready_ = true;
  return true;
}

namespace {

// Column-major kernels on the actual (tiny, stage-varying) sizes: C = [C +] A·B, C += AᵀB,
// y += A x, y += Aᵀx. Dynamic-size Eigen products cost more in dispatch than in flops here, and
// so do runtime-length loops of 1–8 elements; the length of each kernel's innermost loop is
// therefore dispatched to a compile-time constant for 1..8 (nx, nu of short-horizon OCPs), so
// the compiler unrolls it into a few vector instructions. Fixed<0> is the runtime-length loop.
template <int K>
using Fixed = std::integral_constant<int, K>;

template <class F>
void with_length(int len, F&& f) {
  switch (len) {
    case 1: f(Fixed<1>{}); break;
    case 2: f(Fixed<2>{}); break;
    case 3: f(Fixed<3>{}); break;
    case 4: f(Fixed<4>{}); break;
    case 5: f(Fixed<5>{}); break;
    case 6: f(Fixed<6>{}); break;
    case 7: f(Fixed<7>{}); break;
    case 8: f(Fixed<8>{}); break;
    default: f(Fixed<0>{}); break;
  }
}

// C (m x n) = A (m x k) · B (k x n), or C += A·B when acc.
void gemm_nn(int m, int n, int k, const double* A, int lda, const double* B, int ldb, double* C,
             int ldc, bool acc) {
  with_length(m, [&](auto M) {
    const int mm = M.value > 0 ? M.value : m;
    for (int j = 0; j < n; ++j) {
      double* c = C + std::ptrdiff_t(j) * ldc;
      const double* b = B + std::ptrdiff_t(j) * ldb;
      if (!acc)
        for (int i = 0; i < mm; ++i) c[i] = 0.0;
      for (int p = 0; p < k; ++p) {
        const double bp = b[p];
        const double* a = A + std::ptrdiff_t(p) * lda;
        for (int i = 0; i < mm; ++i) c[i] += a[i] * bp;
      }
    }
  });
}
// C (m x n) += Aᵀ · B with A (k x m), B (k x n).
void gemm_tn_acc(int m, int n, int k, const double* A, int lda, const double* B, int ldb,
                 double* C, int ldc) {
  with_length(k, [&](auto K) {
    const int kk = K.value > 0 ? K.value : k;
    for (int j = 0; j < n; ++j) {
      const double* b = B + std::ptrdiff_t(j) * ldb;
      double* c = C + std::ptrdiff_t(j) * ldc;
      for (int i = 0; i < m; ++i) {
        const double* a = A + std::ptrdiff_t(i) * lda;
        double v = 0.0;
        for (int p = 0; p < kk; ++p) v += a[p] * b[p];
        c[i] += v;
      }
    }
  });
}
// y (m) += A (m x n) · x.
void gemv_n_acc(int m, int n, const double* A, int lda, const double* x, double* y) {
  gemm_nn(m, 1, n, A, lda, x, n, y, m, true);
}
// y (n) += Aᵀ · x with A (m x n).
void gemv_t_acc(int m, int n, const double* A, int lda, const double* x, double* y) {
  gemm_tn_acc(n, 1, m, A, lda, x, m, y, n);
}
// dst (m x n, ldd) = src (m x n, lds).
void copy(int m, int n, const double* src, int lds, double* dst, int ldd) {
  with_length(m, [&](auto M) {
    const int mm = M.value > 0 ? M.value : m;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < mm; ++i)
        dst[i + std::ptrdiff_t(j) * ldd] = src[i + std::ptrdiff_t(j) * lds];
  });
}
int ld(const Eigen::MatrixXd& M) { return static_cast<int>(M.outerStride()); }

}  // namespace

// The backward recursion for stages k < N and the Γ recursion when every stage has nx = NX and
// nu = NU (nu_N = 0): the same formulas with compile-time sizes, so every product with A, B, P
// is an unrolled fixed-size product and only the M, H, Γ blocks have a runtime dimension.
template <int NX, int NU>
void condense_fixed(const OcpQp& qp, QpCondensedDenseWorkspace& w, double* H, int ldH) {
  using MX = Eigen::Matrix<double, NX, NX>;
  using MB = Eigen::Matrix<double, NX, NU>;
  using VX = Eigen::Matrix<double, NX, 1>;
  using VU = Eigen::Matrix<double, NU, 1>;
  using Stride = Eigen::OuterStride<>;
  using Rows = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, NX>, 0, Stride>;
  const int N = w.dims.N, nU = w.cdims.nu[0], ldM = ld(w.M);
  for (int k = N - 1; k >= 0; --k) {
    const OcpQpStage& s = qp.stage[k];
    const int r0 = w.off_u[k], r1 = w.off_u[k + 1], nr = nU - r1;
    const Eigen::Map<const MX> A(s.A.data());
    const Eigen::Map<const MB> B(s.B.data());
    const Eigen::Map<const VX> b(s.b.data());
    const Eigen::Map<const MX> P(w.P.data());  // nx_max = NX: P is NX x NX
    const Eigen::Map<const VX> p(w.p.data());
    const MX PA = P * A;
    const MB PB = P * B;
    const VX pb = p + P * b;
    const Rows Mn(w.M.data() + r1, nr, NX, Stride(ldM));
    Eigen::Map<Eigen::Matrix<double, NU, NU>, 0, Stride>(H + r0 + std::ptrdiff_t(r0) * ldH,
                                                         Stride(ldH)) =
        Eigen::Map<const Eigen::Matrix<double, NU, NU>>(s.R.data()) + B.transpose() * PB;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, NU>, 0, Stride>(
        H + r1 + std::ptrdiff_t(r0) * ldH, nr, NU, Stride(ldH))
        .noalias() = Mn.lazyProduct(B);
    Eigen::Map<VU>(w.h.data() + r0) = Eigen::Map<const VU>(s.r.data()) + B.transpose() * pb;
    Eigen::Map<Eigen::VectorXd>(w.h.data() + r1, nr).noalias() += Mn.lazyProduct(b);
    Eigen::Map<VX>(w.p1.data()) = Eigen::Map<const VX>(s.q.data()) + A.transpose() * pb;
    // (an NU x NX block with stride ldM; a 1 x NX Eigen matrix would be row-major, so by hand)
    const Eigen::Matrix<double, NU, NX> Mk =
        Eigen::Map<const Eigen::Matrix<double, NU, NX>>(s.S.data()) + PB.transpose() * A;
    for (int j = 0; j < NX; ++j)
      for (int i = 0; i < NU; ++i) w.M1.data()[r0 + i + std::ptrdiff_t(j) * ldM] = Mk(i, j);
    Rows(w.M1.data() + r1, nr, NX, Stride(ldM)).noalias() = Mn.lazyProduct(A);
    if (k > 0) Eigen::Map<MX>(w.P1.data()) = Eigen::Map<const MX>(s.Q.data()) + A.transpose() * PA;
    std::swap(w.P, w.P1);
    std::swap(w.M, w.M1);
    std::swap(w.p, w.p1);
  }
  for (int i = 0; i < N; ++i) {  // Γ_{i+1} = [A_i Γ_i, B_i, 0] (Γ_i is NX x nU, ld NX)
    const int c0 = w.off_u[i];
    const Eigen::Map<const MX> A(qp.stage[i].A.data());
    Eigen::Map<Eigen::Matrix<double, NX, Eigen::Dynamic>> G1(w.Gam[i + 1].data(), NX, nU);
    G1.leftCols(c0).noalias() =
        A.lazyProduct(Eigen::Map<const Eigen::Matrix<double, NX, Eigen::Dynamic>>(
            w.Gam[i].data(), NX, c0));
    G1.template middleCols<NU>(c0) = Eigen::Map<const MB>(qp.stage[i].B.data());
  }
}

// Everything of the condensed QP that does not depend on x0: Hessian, x0-free gradient h, the
// x0 → gradient map M_0, the constraint rows, input bounds and slack data.
void QpCondensedDense::condense(const OcpQp& qp) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const int N = d.N, nU = w.cdims.nu[0], nbu_c = w.cdims.nbu[0];
  OcpQpStage& cs = w.cqp.stage[0];
  double* H = cs.R.data();
  const int ldH = ld(cs.R);
  const int ldP = ld(w.P), ldM = ld(w.M), ldPA = ld(w.PA), ldPB = ld(w.PB);
  // Backward recursion. Stage N: P = Q_N, p = q_N, M = S_N, h = r_N, H block R_N.
  {
    const OcpQpStage& s = qp.stage[N];
    const int nx = d.nx[N], nu = d.nu[N], r0 = w.off_u[N];
    copy(nx, nx, s.Q.data(), nx, w.P.data(), ldP);
    for (int i = 0; i < nx; ++i) w.p[i] = s.q[i];
    if (nu > 0) {
      copy(nu, nx, s.S.data(), nu, w.M.data() + r0, ldM);
      for (int i = 0; i < nu; ++i) w.h[r0 + i] = s.r[i];
      copy(nu, nu, s.R.data(), nu, H + r0 + std::ptrdiff_t(r0) * ldH, ldH);
    }
  }
  // Uniform stage dims with a compile-time instance below: the fixed-size recursions.
  bool fixed = true;
  if (w.uniform && d.nx[0] == 4 && d.nu[0] == 1)  // the Pendubot (SPEC §5.1)
    condense_fixed<4, 1>(qp, w, H, ldH);
  else
    fixed = false;
  for (int k = fixed ? -1 : N - 1; k >= 0; --k) {
    const OcpQpStage& s = qp.stage[k];
    const int nx = d.nx[k], nx1 = d.nx[k + 1], nu = d.nu[k];
    const int r0 = w.off_u[k], r1 = w.off_u[k + 1], nr = nU - r1;
    const double* A = s.A.data();
    const double* B = s.B.data();
    const double* P = w.P.data();
    double* PA = w.PA.data();
    double* PB = w.PB.data();
    double* pb = w.pb.data();
    gemm_nn(nx1, nx, nx1, P, ldP, A, nx1, PA, ldPA, false);  // P_{k+1} A_k
    gemm_nn(nx1, nu, nx1, P, ldP, B, nx1, PB, ldPB, false);  // P_{k+1} B_k
    for (int i = 0; i < nx1; ++i) pb[i] = w.p[i];            // p_{k+1} + P_{k+1} b_k
    gemv_n_acc(nx1, nx1, P, ldP, s.b.data(), pb);
    const double* Mn = w.M.data() + r1;  // M_{k+1} (nr x nx1)
    // Hessian column block of u_k (lower part; mirrored at the end).
    double* Hkk = H + r0 + std::ptrdiff_t(r0) * ldH;
    copy(nu, nu, s.R.data(), nu, Hkk, ldH);
    gemm_tn_acc(nu, nu, nx1, B, nx1, PB, ldPB, Hkk, ldH);
    gemm_nn(nr, nu, nx1, Mn, ldM, B, nx1, H + r1 + std::ptrdiff_t(r0) * ldH, ldH, false);
    // Linear terms.
    for (int i = 0; i < nu; ++i) w.h[r0 + i] = s.r[i];
    gemv_t_acc(nx1, nu, B, nx1, pb, w.h.data() + r0);
    gemv_n_acc(nr, nx1, Mn, ldM, s.b.data(), w.h.data() + r1);
    for (int i = 0; i < nx; ++i) w.p1[i] = s.q[i];
    gemv_t_acc(nx1, nx, A, nx1, pb, w.p1.data());
    // Cross terms M_k = [S_k + PBᵀA; M_{k+1} A] and P_k = Q_k + AᵀPA.
    double* M1 = w.M1.data();
    copy(nu, nx, s.S.data(), nu, M1 + r0, ldM);
    gemm_tn_acc(nu, nx, nx1, PB, ldPB, A, nx1, M1 + r0, ldM);
    gemm_nn(nr, nx, nx1, Mn, ldM, A, nx1, M1 + r1, ldM, false);
    if (k > 0) {
      copy(nx, nx, s.Q.data(), nx, w.P1.data(), ldP);
      gemm_tn_acc(nx, nx, nx1, A, nx1, PA, ldPA, w.P1.data(), ldP);
    }
    std::swap(w.P, w.P1);
    std::swap(w.M, w.M1);
    std::swap(w.p, w.p1);
  }
  copy(nU, d.nx[0], w.M.data(), ldM, w.M0.data(), ld(w.M0));
  for (int c = 1; c < nU; ++c)
    for (int r = 0; r < c; ++r) H[r + std::ptrdiff_t(c) * ldH] = H[c + std::ptrdiff_t(r) * ldH];
  // Γ_{i+1} = A_i Γ_i + B_i E_i (columns of u_0..u_{i−1}, then B_i; the rest stays zero).
  for (int i = 0; i < (fixed ? 0 : N); ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int c0 = w.off_u[i], nx = d.nx[i], nx1 = d.nx[i + 1];
    Eigen::MatrixXd& G1 = w.Gam[i + 1];
    if (c0 > 0)
      gemm_nn(nx1, c0, nx, s.A.data(), nx1, w.Gam[i].data(), ld(w.Gam[i]), G1.data(), ld(G1),
              false);
    copy(nx1, d.nu[i], s.B.data(), nx1, G1.data() + std::ptrdiff_t(c0) * ld(G1), ld(G1));
  }
  // Rows: state bounds Γ_i[idx, :], general rows C_i Γ_i + D_i E_i; input boxes; slacks.
  double* D = cs.D.data();
  const int ldD = ld(cs.D);
  for (int i = 0; i <= N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nbu = d.nbu[i], nbx = d.nbx[i], ng = d.ng[i], ns = d.ns[i], nx = d.nx[i];
    const int c0 = w.off_u[i], g0 = w.off_g[i], b0 = w.off_bu[i], s0 = w.off_s[i];
    const Eigen::MatrixXd& G = w.Gam[i];
    for (int k = 0; k < nbx; ++k) {
      const int ix = s.idxbx[k];
      for (int c = 0; c < c0; ++c)
        D[g0 + k + std::ptrdiff_t(c) * ldD] = G.data()[ix + std::ptrdiff_t(c) * ld(G)];
    }
    if (ng > 0) {
      double* Dg = D + g0 + nbx;
      if (c0 > 0) gemm_nn(ng, c0, nx, s.C.data(), ng, G.data(), ld(G), Dg, ldD, false);
      copy(ng, d.nu[i], s.D.data(), ng, Dg + std::ptrdiff_t(c0) * ldD, ldD);
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
  const int nU = w.cdims.nu[0], nx0 = d.nx[0];
  for (int i = 0; i < nU; ++i) cs.r[i] = w.h[i];
  gemv_n_acc(nU, nx0, w.M0.data(), ld(w.M0), qp.x0.data(), cs.r.data());
  double* xi = w.xi.data();
  for (int i = 0; i < nx0; ++i) xi[i] = qp.x0[i];
  for (int i = 0; i < d.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nx1 = d.nx[i + 1];
    double* xn = xi + w.off_x[i + 1];
    for (int r = 0; r < nx1; ++r) xn[r] = s.b[r];
    gemv_n_acc(nx1, d.nx[i], s.A.data(), nx1, xi + w.off_x[i], xn);
  }
  auto shifted = [big](double b, double c) {
    return std::isfinite(b) && std::abs(b) < big ? b - c : b;  // absent sides stay absent
  };
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    const int nbx = d.nbx[i], ng = d.ng[i], g0 = w.off_g[i], nx = d.nx[i];
    const double* x = xi + w.off_x[i];
    for (int k = 0; k < nbx; ++k) {
      const double c = x[s.idxbx[k]];
      cs.lg[g0 + k] = shifted(s.lbx[k], c);
      cs.ug[g0 + k] = shifted(s.ubx[k], c);
    }
    for (int k = 0; k < ng; ++k) {
      double c = 0.0;
      for (int j = 0; j < nx; ++j) c += s.C(k, j) * x[j];
      cs.lg[g0 + nbx + k] = shifted(s.lg[k], c);
      cs.ug[g0 + nbx + k] = shifted(s.ug[k], c);
    }
  }
}

void QpCondensedDense::warm_start(const OcpQpSolution& sol, QpWarmStart warm) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const int nbu_c = w.cdims.nbu[0];
  OcpQpSolution& c = w.csol;
  const bool dual = warm == QpWarmStart::primal_dual;
  double* U = c.u[0].data();
  double *sl = c.sl[0].data(), *su = c.su[0].data();
  double *ll = c.lam_l[0].data(), *lu = c.lam_u[0].data();
  double *lsl = c.lam_sl[0].data(), *lsu = c.lam_su[0].data();
  for (int i = 0; i <= d.N; ++i) {
    const int nu = d.nu[i], nbu = d.nbu[i], nc = d.nc(i), ns = d.ns[i], s0 = w.off_s[i];
    for (int j = 0; j < nu; ++j) U[w.off_u[i] + j] = sol.u[i].data()[j];
    for (int j = 0; j < ns; ++j) {
      sl[s0 + j] = sol.sl[i].data()[j];
      su[s0 + j] = sol.su[i].data()[j];
    }
    if (!dual) continue;
    const double* li = sol.lam_l[i].data();
    const double* ui = sol.lam_u[i].data();
    const int b0 = w.off_bu[i], g0 = nbu_c + w.off_g[i] - nbu;
    for (int k = 0; k < nbu; ++k) {
      ll[b0 + k] = li[k];
      lu[b0 + k] = ui[k];
    }
    for (int k = nbu; k < nc; ++k) {
      ll[g0 + k] = li[k];
      lu[g0 + k] = ui[k];
    }
    for (int j = 0; j < ns; ++j) {
      lsl[s0 + j] = sol.lam_sl[i].data()[j];
      lsu[s0 + j] = sol.lam_su[i].data()[j];
    }
  }
}

void QpCondensedDense::recover(const OcpQp& qp, OcpQpSolution& sol) {
  Workspace& w = ws_;
  const OcpQpDims& d = w.dims;
  const OcpQpSolution& c = w.csol;
  const int nbu_c = w.cdims.nbu[0];
  const double* U = c.u[0].data();
  // Inputs, slacks, multipliers; states by forward simulation.
  for (int i = 0; i < d.nx[0]; ++i) sol.x[0][i] = qp.x0[i];
  for (int i = 0; i <= d.N; ++i) {
    const int nu = d.nu[i], nbu = d.nbu[i], nc = d.nc(i), ns = d.ns[i], s0 = w.off_s[i];
    for (int j = 0; j < nu; ++j) sol.u[i][j] = U[w.off_u[i] + j];
    for (int k = 0; k < nc; ++k) {
      const int kc = k < nbu ? w.off_bu[i] + k : nbu_c + w.off_g[i] + (k - nbu);
      sol.lam_l[i][k] = c.lam_l[0][kc];
      sol.lam_u[i][k] = c.lam_u[0][kc];
    }
    for (int j = 0; j < ns; ++j) {
      sol.sl[i][j] = c.sl[0][s0 + j];
      sol.su[i][j] = c.su[0][s0 + j];
      sol.lam_sl[i][j] = c.lam_sl[0][s0 + j];
      sol.lam_su[i][j] = c.lam_su[0][s0 + j];
    }
    if (i < d.N) {
      const OcpQpStage& s = qp.stage[i];
      const int nx1 = d.nx[i + 1];
      double* xn = sol.x[i + 1].data();
      for (int r = 0; r < nx1; ++r) xn[r] = s.b[r];
      gemv_n_acc(nx1, d.nx[i], s.A.data(), nx1, sol.x[i].data(), xn);
      gemv_n_acc(nx1, nu, s.B.data(), nx1, sol.u[i].data(), xn);
    }
  }
  // π and λ_x0 from the x-stationarity, backwards; the objective on the way.
  double f = 0.0;
  for (int i = d.N; i >= 0; --i) {
    const OcpQpStage& s = qp.stage[i];
    const int nx = d.nx[i], nu = d.nu[i], nbu = d.nbu[i], nbx = d.nbx[i], ng = d.ng[i];
    const double* x = sol.x[i].data();
    const double* u = sol.u[i].data();
    double* gx = i > 0 ? sol.pi[i - 1].data() : sol.lam_x0.data();
    // gx = Q x (½xᵀQx + qᵀx into f), then + q + Sᵀu + Aᵀπ_i + ∇_x dᵀ(λ_u − λ_l).
    for (int r = 0; r < nx; ++r) gx[r] = 0.0;
    gemv_n_acc(nx, nx, s.Q.data(), nx, x, gx);
    for (int r = 0; r < nx; ++r) {
      f += (0.5 * gx[r] + s.q[r]) * x[r];
      gx[r] += s.q[r];
    }
    gemv_t_acc(nu, nx, s.S.data(), nu, u, gx);
    if (i < d.N) gemv_t_acc(d.nx[i + 1], nx, s.A.data(), d.nx[i + 1], sol.pi[i].data(), gx);
    const double* ll = sol.lam_l[i].data();
    const double* lu = sol.lam_u[i].data();
    for (int k = 0; k < nbx; ++k) gx[s.idxbx[k]] += lu[nbu + k] - ll[nbu + k];
    if (ng > 0) {
      double* dl = w.dl.data();
      for (int k = 0; k < ng; ++k) dl[k] = lu[nbu + nbx + k] - ll[nbu + nbx + k];
      gemv_t_acc(ng, nx, s.C.data(), ng, dl, gx);
    }
    if (nu > 0) {  // ½uᵀRu + uᵀS x + rᵀu
      double* gu = w.gu.data();
      for (int r = 0; r < nu; ++r) gu[r] = s.r[r];
      gemv_n_acc(nu, nx, s.S.data(), nu, x, gu);
      for (int j = 0; j < nu; ++j) {
        double ru = 0.0;
        for (int r = 0; r < nu; ++r) ru += s.R(j, r) * u[r];
        gu[j] += 0.5 * ru;
      }
      for (int r = 0; r < nu; ++r) f += u[r] * gu[r];
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
  if (!ready_ || !ocp_qp_valid_for(qp, w.dims, settings_.check_data))
    return sol.set_invalid_data();
  if (!prepared) condense(qp);
  embed_x0(qp);
  if (warm != QpWarmStart::cold) warm_start(sol, warm);
  if (method_ == CondensedQpMethod::active_set) {
    QpSettings& as = active_set_.settings();
    as = settings_;
    as.check_data = false;
    const QpStatus status = active_set_.solve(w.cqp, w.csol, warm);
    if (status == QpStatus::success) {
      recover(qp, sol);
      sol.status = status;
      return status;
    }
    ++ipm_fallbacks_;  // the IPM from the same warm start
    if (warm != QpWarmStart::cold) warm_start(sol, warm);
  }
  QpSettings& inner = ipm_.settings();
  inner = settings_;
  inner.check_data = false;
  const QpStatus status = ipm_.solve(w.cqp, w.csol, warm);
  if (status == QpStatus::invalid_data) return sol.set_invalid_data();
  recover(qp, sol);
  sol.status = status;
  return status;
}

}  // namespace mixpilot
