#include "core/qp/qp_riccati_ipm_pairs.hpp"

#include <algorithm>
#include <array>
#include <tuple>

#include "core/numerics/matrix_checks.hpp"
#include "core/qp/detail/qp_kernels.hpp"

namespace mixpilot {

namespace {

// C += A B and C = A B with the register-blocked kernel (Eigen's general GEMM packs its
// operands first, which costs more than the product at these 4..24 sizes). Column-major
// operands (matrices or blocks).
template <class MA, class MB, class MC>
void add_ab(const MA& A, const MB& B, MC&& C) {
  kernels::gemm_nn(int(A.rows()), int(B.cols()), int(A.cols()), A.data(), int(A.outerStride()),
                   B.data(), int(B.outerStride()), C.data(), int(C.outerStride()));
}
template <class MA, class MB, class MC>
void set_ab(const MA& A, const MB& B, MC&& C) {
  kernels::gemm_nn(int(A.rows()), int(B.cols()), int(A.cols()), A.data(), int(A.outerStride()),
                   B.data(), int(B.outerStride()), C.data(), int(C.outerStride()), true);
}
// y += A x and y += Aᵀ x.
template <class MA, class VX, class VY>
void add_ax(const MA& A, const VX& x, VY&& y) {
  kernels::gemv_n(int(A.rows()), int(A.cols()), A.data(), int(A.outerStride()), x.data(), y.data());
}
template <class MA, class VX, class VY>
void add_atx(const MA& A, const VX& x, VY&& y) {
  kernels::gemv_t(int(A.rows()), int(A.cols()), A.data(), int(A.outerStride()), x.data(), y.data());
}

// Blocks: pairs (k, k+1) while k + 1 < N, then a lone last dynamic stage (odd N) and the
// terminal stage N, each alone.
void blocks_of(const OcpQpDims& d, std::vector<int>& first, std::vector<int>& count) {
  first.clear();
  count.clear();
  int k = 0;
  for (; k + 1 < d.N; k += 2) {
    first.push_back(k);
    count.push_back(2);
  }
  for (; k <= d.N; ++k) {
    first.push_back(k);
    count.push_back(1);
  }
}

// Stage i of `from` into stage j of `to` (a lone stage: the same sizes in both).
void copy_stage(const OcpQpSolution& from, int i, OcpQpSolution& to, int j, bool dynamics) {
  to.x[j] = from.x[i];
  to.u[j] = from.u[i];
  if (dynamics) to.pi[j] = from.pi[i];
  to.lam_l[j] = from.lam_l[i];
  to.lam_u[j] = from.lam_u[i];
  to.sl[j] = from.sl[i];
  to.su[j] = from.su[i];
  to.lam_sl[j] = from.lam_sl[i];
  to.lam_su[j] = from.lam_su[i];
}

// Where the constraints of stages k (stage 0) and k+1 (stage 1) sit in their pair's block.
struct Segment {
  int block, stage, offset, size;  // block offset; stage 0/1 and offset there; length
};
std::array<Segment, 6> pair_segments(const OcpQpDims& d, int k) {
  const int nbu0 = d.nbu[k], nbu1 = d.nbu[k + 1], nbx0 = d.nbx[k], nbx1 = d.nbx[k + 1];
  const int ng0 = d.ng[k], ng1 = d.ng[k + 1], nbu = nbu0 + nbu1;
  return {Segment{0, 0, 0, nbu0},                                  // bu_k
          Segment{nbu0, 1, 0, nbu1},                               // bu_{k+1}
          Segment{nbu, 0, nbu0, nbx0},                             // bx_k
          Segment{nbu + nbx0, 0, nbu0 + nbx0, ng0},                // g_k
          Segment{nbu + nbx0 + ng0, 1, nbu1, nbx1},                // bx_{k+1} as rows
          Segment{nbu + nbx0 + ng0 + nbx1, 1, nbu1 + nbx1, ng1}};  // g_{k+1}
}

}  // namespace

OcpQpDims ocp_qp_pair_dims(const OcpQpDims& d) {
  std::vector<int> first, count;
  blocks_of(d, first, count);
  OcpQpDims c(static_cast<int>(first.size()) - 1);
  for (std::size_t j = 0; j < first.size(); ++j) {
    const int k = first[j];
    c.nx[j] = d.nx[k];
    c.nu[j] = d.nu[k];
    c.nbu[j] = d.nbu[k];
    c.nbx[j] = d.nbx[k];
    c.ng[j] = d.ng[k];
    c.ns[j] = d.ns[k];
    if (count[j] == 2) {
      c.nu[j] += d.nu[k + 1];
      c.nbu[j] += d.nbu[k + 1];
      c.ng[j] += d.nbx[k + 1] + d.ng[k + 1];
      c.ns[j] += d.ns[k + 1];
    }
  }
  return c;
}

bool QpRiccatiIpmPairs::setup(const OcpQpDims& dims, const Settings& settings) {
  ready_ = false;
  prepared_ = false;
  settings_ = settings;
  if (!dims.valid()) return false;
  dims_ = dims;
  blocks_of(dims, first_, count_);
  const OcpQpDims dc = ocp_qp_pair_dims(dims);
  qpc_.resize(dc);
  solc_.resize(dc);
  if (levels_ > 1)
    inner_ = std::make_unique<QpRiccatiIpmPairs>(levels_ - 1);
  else
    inner_ = std::make_unique<QpRiccatiIpm>();
  Settings inner = settings;
  inner.check_data = false;  // solve() checks the original data
  if (!inner_->setup(dc, inner)) return false;
  int nx = 0, nu = 0;
  for (int i = 0; i <= dims.N; ++i) {
    nx = std::max(nx, dims.nx[i]);
    nu = std::max(nu, dims.nu[i]);
  }
  Q1A0_.setZero(nx, nx);
  Q1B0_.setZero(nx, nu);
  BA0t_.setZero(nu + nx, nx);
  g1_.resize(nx);
  x1_.resize(nx);
  constant_.assign(first_.size(), 0.0);
  ready_ = true;
  return true;
}

namespace {
// M (rows x cols, ld ldm) = diag(q) X (ld ldx).
void scale_rows(int rows, int cols, const double* q, const double* X, int ldx, double* M,
                int ldm) {
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r)
      M[r + static_cast<std::ptrdiff_t>(c) * ldm] = q[r] * X[r + static_cast<std::ptrdiff_t>(c) * ldx];
}
}  // namespace

void QpRiccatiIpmPairs::condense_pair(const OcpQp& qp, int j) {
  const int k = first_[j];
  const OcpQpDims& d = dims_;
  const OcpQpStage& s0 = qp.stage[k];
  const OcpQpStage& s1 = qp.stage[k + 1];
  OcpQpStage& t = qpc_.stage[j];
  const int nx0 = d.nx[k], nu0 = d.nu[k], nx1 = d.nx[k + 1], nu1 = d.nu[k + 1];
  const int nx2 = d.nx[k + 2];
  const int nbu0 = d.nbu[k], nbu1 = d.nbu[k + 1], nbx1 = d.nbx[k + 1];
  const int ng0 = d.ng[k], ng1 = d.ng[k + 1], ns0 = d.ns[k], ns1 = d.ns[k + 1];
  const int nu = nu0 + nu1;
  const Eigen::MatrixXd &A0 = s0.A, &B0 = s0.B;
  // Q1 A0 and Q1 B0 (a row scaling for a diagonal Q1: the Gauss-Newton Hessian of a selection
  // output with diagonal weights, what the controllers have).
  double* QA = Q1A0_.data();
  double* QB = Q1B0_.data();
  const int ldq = static_cast<int>(Q1A0_.rows());
  if (is_diagonal(s1.Q)) {
    for (int r = 0; r < nx1; ++r) g1_[r] = s1.Q(r, r);
    scale_rows(nx1, nx0, g1_.data(), A0.data(), nx1, QA, ldq);
    scale_rows(nx1, nu0, g1_.data(), B0.data(), nx1, QB, ldq);
  } else {
    kernels::gemm_nn(nx1, nx0, nx1, s1.Q.data(), nx1, A0.data(), nx1, QA, ldq, true);
    kernels::gemm_nn(nx1, nu0, nx1, s1.Q.data(), nx1, B0.data(), nx1, QB, ldq, true);
  }
  auto g1 = g1_.head(nx1);  // Q1 b0 + q1
  auto Q1b0 = x1_.head(nx1);
  Q1b0.setZero();
  add_ax(s1.Q, s0.b, Q1b0);
  g1 = Q1b0 + s1.q;
  constant_[j] = s0.b.dot(g1) - 0.5 * s0.b.dot(Q1b0);  // ½b0ᵀQ1b0 + q1ᵀb0

  // Dynamics to x_{k+2}.
  set_ab(s1.A, A0, t.A);
  set_ab(s1.A, B0, t.B.leftCols(nu0));
  std::copy_n(s1.B.data(), nx2 * nu1, t.B.data() + static_cast<std::ptrdiff_t>(nx2) * nu0);
  t.b = s1.b;
  add_ax(s1.A, s0.b, t.b);
  // [B0ᵀ; A0ᵀ] once: the products below are then plain A B (register tiles reuse each loaded
  // column four times; a transposed product reloads it per column).
  double* BAt = BA0t_.data();
  const int ldt = static_cast<int>(BA0t_.rows());
  kernels::transpose(nx1, nu0, B0.data(), nx1, BAt, ldt);
  kernels::transpose(nx1, nx0, A0.data(), nx1, BAt + nu0, ldt);
  const double* At = BAt + nu0;
  // Cost. Q = Q0 + A0ᵀQ1A0: its lower triangle (blocks of 4 columns), then mirrored.
  t.Q = s0.Q;
  for (int cb = 0; cb < nx0; cb += 4)
    kernels::gemm_nn(nx0 - cb, std::min(4, nx0 - cb), nx1, At + cb, ldt,
                     QA + std::ptrdiff_t(cb) * ldq, ldq, t.Q.data() + cb + std::ptrdiff_t(cb) * nx0,
                     nx0);
  for (int c = 1; c < nx0; ++c) {
    double* qc = t.Q.data() + std::ptrdiff_t(c) * nx0;
    const double* qr = t.Q.data() + c;
    for (int r = 0; r < c; ++r) qc[r] = qr[std::ptrdiff_t(r) * nx0];
  }
  // S = [S0 + B0ᵀQ1A0; S1A0].
  t.S.topRows(nu0) = s0.S;
  kernels::gemm_nn(nu0, nx0, nx1, BAt, ldt, QA, ldq, t.S.data(), nu);
  // R = [R0 + B0ᵀQ1B0, (S1B0)ᵀ; S1B0, R1].
  t.R.topLeftCorner(nu0, nu0) = s0.R;
  kernels::gemm_nn(nu0, nu0, nx1, BAt, ldt, QB, ldq, t.R.data(), nu);
  t.R.bottomRightCorner(nu1, nu1) = s1.R;
  // [r; q] += [B0ᵀ; A0ᵀ] g1 (r's tail is stage k+1's).
  t.r.head(nu0) = s0.r;
  t.q = s0.q;
  kernels::gemv_n(nu0, nx1, BAt, ldt, g1.data(), t.r.data());
  kernels::gemv_n(nx0, nx1, At, ldt, g1.data(), t.q.data());
  t.r.tail(nu1) = s1.r;
  if (nu1 > 0 && !is_zero(s1.S)) {
    set_ab(s1.S, A0, t.S.bottomRows(nu1));
    set_ab(s1.S, B0, t.R.bottomLeftCorner(nu1, nu0));
    add_ax(s1.S, s0.b, t.r.tail(nu1));
  } else {  // S1 = 0 (the controllers' Gauss-Newton blocks): nothing to multiply
    t.S.bottomRows(nu1).setZero();
    t.R.bottomLeftCorner(nu1, nu0).setZero();
  }
  t.R.topRightCorner(nu0, nu1) = t.R.bottomLeftCorner(nu1, nu0).transpose();
  // Constraints: [bu0; bu1], bx0, [g0; bx1 rows; g1 rows].
  std::copy_n(s0.idxbu.data(), nbu0, t.idxbu.data());
  for (int r = 0; r < nbu1; ++r) t.idxbu[nbu0 + r] = s1.idxbu[r] + nu0;
  std::copy_n(s0.lbu.data(), nbu0, t.lbu.data());
  std::copy_n(s1.lbu.data(), nbu1, t.lbu.data() + nbu0);
  std::copy_n(s0.ubu.data(), nbu0, t.ubu.data());
  std::copy_n(s1.ubu.data(), nbu1, t.ubu.data() + nbu0);
  t.idxbx = s0.idxbx;
  t.lbx = s0.lbx;
  t.ubx = s0.ubx;
  const int ngt = ng0 + nbx1 + ng1;
  for (int c = 0; c < nx0; ++c) std::copy_n(s0.C.data() + c * ng0, ng0, t.C.data() + c * ngt);
  for (int c = 0; c < nu0; ++c) std::copy_n(s0.D.data() + c * ng0, ng0, t.D.data() + c * ngt);
  t.D.topRightCorner(ng0 + nbx1, nu1).setZero();
  std::copy_n(s0.lg.data(), ng0, t.lg.data());
  std::copy_n(s0.ug.data(), ng0, t.ug.data());
  for (int r = 0; r < nbx1; ++r) {  // x_{k+1}[idx] = A0[idx,:] x + B0[idx,:] u0 + b0[idx]
    const int idx = s1.idxbx[r], row = ng0 + r;
    const double* a = A0.data() + idx;
    const double* b = B0.data() + idx;
    double* tc = t.C.data() + row;
    double* td = t.D.data() + row;
    for (int c = 0; c < nx0; ++c) tc[std::ptrdiff_t(c) * ngt] = a[std::ptrdiff_t(c) * nx1];
    for (int c = 0; c < nu0; ++c) td[std::ptrdiff_t(c) * ngt] = b[std::ptrdiff_t(c) * nx1];
    t.lg[row] = s1.lbx[r] - s0.b[idx];
    t.ug[row] = s1.ubx[r] - s0.b[idx];
  }
  if (ng1 > 0) {  // C1 x_{k+1} + D1 u1 = C1A0 x + C1B0 u0 + D1 u1 + C1 b0
    const int r0 = ng0 + nbx1;
    auto C = t.C.middleRows(r0, ng1);
    auto D = t.D.middleRows(r0, ng1);
    set_ab(s1.C, A0, C);
    set_ab(s1.C, B0, D.leftCols(nu0));
    D.rightCols(nu1) = s1.D;
    for (int r = 0; r < ng1; ++r) {
      const double cb = s1.C.row(r).dot(s0.b);
      t.lg[r0 + r] = s1.lg[r] - cb;
      t.ug[r0 + r] = s1.ug[r] - cb;
    }
  }
  // Soft constraints: stage k's, then stage k+1's, re-indexed into the block's d.
  const std::array<Segment, 6> segments = pair_segments(d, k);
  const auto block_index = [&](int stage, int c) {
    for (const Segment& sg : segments)
      if (sg.stage == stage && c >= sg.offset && c < sg.offset + sg.size)
        return sg.block + c - sg.offset;
    return -1;  // unreachable: the indices were validated
  };
  for (int r = 0; r < ns0; ++r) t.idxs[r] = block_index(0, s0.idxs[r]);
  for (int r = 0; r < ns1; ++r) t.idxs[ns0 + r] = block_index(1, s1.idxs[r]);
  for (auto [dst, a, b] : {std::tuple{&t.Zl, &s0.Zl, &s1.Zl}, std::tuple{&t.Zu, &s0.Zu, &s1.Zu},
                           std::tuple{&t.zl, &s0.zl, &s1.zl}, std::tuple{&t.zu, &s0.zu, &s1.zu}}) {
    std::copy_n(a->data(), ns0, dst->data());
    std::copy_n(b->data(), ns1, dst->data() + ns0);
  }
}

bool QpRiccatiIpmPairs::condense(const OcpQp& qp) {
  prepared_ = false;
  restricted_ = false;
  if (!ready_ || !ocp_qp_valid_for(qp, dims_, settings_.check_data)) return false;
  for (std::size_t j = 0; j < first_.size(); ++j) {
    if (count_[j] == 2) {
      condense_pair(qp, static_cast<int>(j));
    } else {
      qpc_.stage[j] = qp.stage[first_[j]];  // same sizes: no allocation
      constant_[j] = 0.0;
    }
  }
  set_inner_settings();
  return true;
}

void QpRiccatiIpmPairs::prepare(const OcpQp& qp) {
  if (!condense(qp)) return;
  inner_->prepare(qpc_);  // a nested level condenses its pairs (x0 plays no part)
  prepared_ = true;
}

void QpRiccatiIpmPairs::prepare(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) {
  if (!condense(qp)) return;
  qpc_.x0 = qp.x0;  // not read by the preparation; set for a consistent QP
  if (warm != QpWarmStart::cold) {
    restrict_warm_start(start);
    restricted_ = true;
  }
  inner_->prepare(qpc_, solc_, warm);
  prepared_ = true;
}

void QpRiccatiIpmPairs::set_inner_settings() {
  Settings& inner = inner_->settings();
  inner = settings_;
  inner.check_data = false;
}

void QpRiccatiIpmPairs::restrict_warm_start(const OcpQpSolution& sol) {
  const OcpQpDims& d = dims_;
  for (std::size_t jj = 0; jj < first_.size(); ++jj) {
    const int j = static_cast<int>(jj), k = first_[jj];
    if (count_[jj] == 1) {
      copy_stage(sol, k, solc_, j, k < d.N);
      continue;
    }
    const int nu0 = d.nu[k], nu1 = d.nu[k + 1], ns0 = d.ns[k], ns1 = d.ns[k + 1];
    solc_.x[j] = sol.x[k];
    solc_.u[j].head(nu0) = sol.u[k];
    solc_.u[j].tail(nu1) = sol.u[k + 1];
    solc_.pi[j] = sol.pi[k + 1];
    for (const Segment& g : pair_segments(d, k)) {  // plain copies: most segments are tiny or empty
      std::copy_n(sol.lam_l[k + g.stage].data() + g.offset, g.size, solc_.lam_l[j].data() + g.block);
      std::copy_n(sol.lam_u[k + g.stage].data() + g.offset, g.size, solc_.lam_u[j].data() + g.block);
    }
    for (auto [dst, src] : {std::pair{&solc_.sl, &sol.sl}, std::pair{&solc_.su, &sol.su},
                            std::pair{&solc_.lam_sl, &sol.lam_sl},
                            std::pair{&solc_.lam_su, &sol.lam_su}}) {
      (*dst)[j].head(ns0) = (*src)[k];
      (*dst)[j].tail(ns1) = (*src)[k + 1];
    }
  }
}

void QpRiccatiIpmPairs::expand(const OcpQp& qp, OcpQpSolution& sol) const {
  const OcpQpDims& d = dims_;
  double constant = 0.0;
  for (std::size_t jj = 0; jj < first_.size(); ++jj) {
    const int j = static_cast<int>(jj), k = first_[jj];
    constant += constant_[jj];
    if (count_[jj] == 1) {
      copy_stage(solc_, j, sol, k, k < d.N);
      continue;
    }
    const OcpQpStage &s0 = qp.stage[k], &s1 = qp.stage[k + 1];
    const int nu0 = d.nu[k], nu1 = d.nu[k + 1], nbu1 = d.nbu[k + 1], nbx1 = d.nbx[k + 1];
    const int ng1 = d.ng[k + 1], ns0 = d.ns[k], ns1 = d.ns[k + 1];
    sol.x[k] = solc_.x[j];
    sol.u[k] = solc_.u[j].head(nu0);
    sol.u[k + 1] = solc_.u[j].tail(nu1);
    Eigen::VectorXd& x1 = sol.x[k + 1];
    x1 = s0.b;
    add_ax(s0.A, sol.x[k], x1);
    add_ax(s0.B, sol.u[k], x1);
    for (const Segment& g : pair_segments(d, k)) {
      std::copy_n(solc_.lam_l[j].data() + g.block, g.size, sol.lam_l[k + g.stage].data() + g.offset);
      std::copy_n(solc_.lam_u[j].data() + g.block, g.size, sol.lam_u[k + g.stage].data() + g.offset);
    }
    for (auto [dst, src] : {std::pair{&sol.sl, &solc_.sl[j]}, std::pair{&sol.su, &solc_.su[j]},
                            std::pair{&sol.lam_sl, &solc_.lam_sl[j]},
                            std::pair{&sol.lam_su, &solc_.lam_su[j]}}) {
      (*dst)[k] = src->head(ns0);
      (*dst)[k + 1] = src->tail(ns1);
    }
    // π_k from the stationarity in x_{k+1}.
    sol.pi[k + 1] = solc_.pi[j];
    Eigen::VectorXd& pk = sol.pi[k];
    pk = s1.q;
    add_ax(s1.Q, x1, pk);
    add_atx(s1.S, sol.u[k + 1], pk);
    add_atx(s1.A, sol.pi[k + 1], pk);
    for (int r = 0; r < nbx1; ++r)
      pk[s1.idxbx[r]] -= sol.lam_l[k + 1][nbu1 + r] - sol.lam_u[k + 1][nbu1 + r];
    for (int r0 = 0; r0 < ng1; r0 += 16) {  // + C1ᵀ(λ_u − λ_l) of the general rows
      double diff[16];
      const int n = std::min(16, ng1 - r0);
      for (int r = 0; r < n; ++r)
        diff[r] = sol.lam_u[k + 1][nbu1 + nbx1 + r0 + r] - sol.lam_l[k + 1][nbu1 + nbx1 + r0 + r];
      kernels::gemv_t(n, d.nx[k + 1], s1.C.data() + r0, ng1, diff, pk.data());
    }
  }
  sol.lam_x0 = solc_.lam_x0;
  sol.status = solc_.status;
  sol.iterations = solc_.iterations;
  sol.objective = solc_.objective + constant;
  sol.res_stat = solc_.res_stat;
  sol.res_eq = solc_.res_eq;
  sol.res_ineq = solc_.res_ineq;
  sol.res_comp = solc_.res_comp;
}

QpStatus QpRiccatiIpmPairs::solve(const OcpQp& qp, OcpQpSolution& sol, QpWarmStart warm) {
  if (!prepared_) prepare(qp);
  if (!prepared_) return sol.set_invalid_data();
  prepared_ = false;
  qpc_.x0 = qp.x0;
  if (warm != QpWarmStart::cold && !restricted_) restrict_warm_start(sol);
  restricted_ = false;
  inner_->solve(qpc_, solc_, warm);
  expand(qp, sol);
  return sol.status;
}

}  // namespace mixpilot
