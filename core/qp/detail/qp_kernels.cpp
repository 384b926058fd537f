#include "core/qp/detail/qp_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace mixpilot::kernels {

using std::ptrdiff_t;

void trmm_rl(int n, int m, const double* A, int lda, const double* L, int ldl, double* Y,
             int ldy) {
  for (int j = 0; j < m; ++j) {
    double* y = Y + static_cast<ptrdiff_t>(j) * ldy;
    for (int r = 0; r < n; ++r) y[r] = 0.0;
    for (int k = j; k < m; ++k) {
      const double a = L[k + static_cast<ptrdiff_t>(j) * ldl];
      const double* ak = A + static_cast<ptrdiff_t>(k) * lda;
      for (int r = 0; r < n; ++r) y[r] += a * ak[r];
    }
  }
}

void syrk_ln(int n, int m, const double* Y, int ldy, double* C, int ldc) {
  for (int j = 0; j < n; ++j) {
    double* c = C + static_cast<ptrdiff_t>(j) * ldc;
    for (int k = 0; k < m; ++k) {
      const double* yk = Y + static_cast<ptrdiff_t>(k) * ldy;
      const double a = yk[j];
      for (int r = j; r < n; ++r) c[r] += a * yk[r];
    }
  }
}

bool potrf_l(int n, int n_strict, double* C, int ldc, double* inv_diag, double psd_tol,
             double pivot_floor) {
  for (int j = 0; j < n; ++j) {
    double* cj = C + static_cast<ptrdiff_t>(j) * ldc;
    const double d0 = std::abs(cj[j]);
    for (int k = 0; k < j; ++k) {
      const double* ck = C + static_cast<ptrdiff_t>(k) * ldc;
      const double a = ck[j];
      for (int r = j; r < n; ++r) cj[r] -= a * ck[r];
    }
    double p = cj[j];
    if (!(p > pivot_floor)) {
      if (!((j >= n_strict || d0 > 0.0) && p >= -psd_tol * d0)) return false;
      p = std::max(pivot_floor, psd_tol * d0);  // no curvature: regularized (see the header)
    }
    const double s = std::sqrt(p), is = 1.0 / s;
    inv_diag[j] = is;
    cj[j] = s;
    for (int r = j + 1; r < n; ++r) cj[r] *= is;
  }
  return true;
}

void trsv_ln(int n, const double* L, int ldl, const double* dinv, int lddinv, double* x) {
  // Blocks of 4 columns: the block's components z = M_b x_b with the block's inverse (a 4 x 4
  // matrix-vector product instead of a substitution chain), then the rows below updated with z
  // (4-row AVX2 chunks, scalar tail).
  for (int jb = 0; jb < n; jb += 4) {
    const int bw = n - jb < 4 ? n - jb : 4;
    const double* M = dinv + jb;
#if defined(__AVX2__) && defined(__FMA__)
    if (bw == 4) {
      const __m256d x0 = _mm256_broadcast_sd(x + jb), x1 = _mm256_broadcast_sd(x + jb + 1),
                    x2 = _mm256_broadcast_sd(x + jb + 2), x3 = _mm256_broadcast_sd(x + jb + 3);
      __m256d z = _mm256_mul_pd(_mm256_loadu_pd(M), x0);
      __m256d z2 = _mm256_mul_pd(_mm256_loadu_pd(M + lddinv), x1);
      z = _mm256_fmadd_pd(_mm256_loadu_pd(M + 2 * lddinv), x2, z);
      z2 = _mm256_fmadd_pd(_mm256_loadu_pd(M + 3 * lddinv), x3, z2);
      z = _mm256_add_pd(z, z2);
      _mm256_storeu_pd(x + jb, z);
      if (jb + 4 >= n) break;
      const double* l0 = L + static_cast<ptrdiff_t>(jb) * ldl;
      const __m256d z0 = _mm256_permute4x64_pd(z, 0x00), z1 = _mm256_permute4x64_pd(z, 0x55),
                    zz2 = _mm256_permute4x64_pd(z, 0xAA), z3 = _mm256_permute4x64_pd(z, 0xFF);
      int r = jb + 4;
      for (; r + 4 <= n; r += 4) {
        __m256d v = _mm256_fnmadd_pd(_mm256_loadu_pd(l0 + r), z0, _mm256_loadu_pd(x + r));
        __m256d w = _mm256_mul_pd(_mm256_loadu_pd(l0 + ldl + r), z1);
        v = _mm256_fnmadd_pd(_mm256_loadu_pd(l0 + 2 * ldl + r), zz2, v);
        w = _mm256_fmadd_pd(_mm256_loadu_pd(l0 + 3 * ldl + r), z3, w);
        _mm256_storeu_pd(x + r, _mm256_sub_pd(v, w));
      }
      for (; r < n; ++r)
        x[r] -= l0[r] * x[jb] + l0[ldl + r] * x[jb + 1] + l0[2 * ldl + r] * x[jb + 2] +
                l0[3 * ldl + r] * x[jb + 3];
      continue;
    }
#endif
    double z[4];
    for (int r = 0; r < bw; ++r) {
      double s = 0.0;
      for (int c = 0; c <= r; ++c) s += M[r + static_cast<ptrdiff_t>(c) * lddinv] * x[jb + c];
      z[r] = s;
    }
    for (int r = 0; r < bw; ++r) x[jb + r] = z[r];
    for (int c = 0; c < bw; ++c) {
      const double* lc = L + static_cast<ptrdiff_t>(jb + c) * ldl;
      for (int r = jb + bw; r < n; ++r) x[r] -= lc[r] * z[c];
    }
  }
}

void trsv_lt(int n, const double* L, int ldl, const double* inv_diag, double* x) {
  for (int j = n - 1; j >= 0; --j) {
    const double* lj = L + static_cast<ptrdiff_t>(j) * ldl;
    double s = x[j];
    for (int r = j + 1; r < n; ++r) s -= lj[r] * x[r];
    x[j] = s * inv_diag[j];
  }
}

// ---------------------------------------------------------------------------------------------
// Register-blocked AVX2/FMA kernels. Row counts are padded to multiples of 4: every matrix these
// read or write has ld ≥ pad4(rows) and its padding rows are readable (and, for inputs, zero).

namespace {

inline int pad4(int n) { return (n + 3) & ~3; }

// ‖Y(row, :)‖² of an n x m column-major Y; Y may be null when m = 0 (no offset is formed then).
inline double row_norm2(int m, const double* Y, int row, int ldy) {
  double s = 0.0;
  for (int k = 0; k < m; ++k) {
    const double v = Y[row + static_cast<ptrdiff_t>(k) * ldy];
    s += v * v;
  }
  return s;
}

#if defined(__AVX2__) && defined(__FMA__)
// acc[r][c] ±= Σ_k A(r·4 .. r·4+3, k) · B(c, k)   (A: NR x kc, B: NC x kc, both column-major).
template <int NR, int NC, bool SUB>
inline void nt_acc(int kc, const double* A, int lda, const double* B, int ldb, __m256d (&acc)[2][4]) {
  for (int k = 0; k < kc; ++k) {
    const double* a = A + static_cast<ptrdiff_t>(k) * lda;
    const double* b = B + static_cast<ptrdiff_t>(k) * ldb;
    const __m256d a0 = _mm256_loadu_pd(a);
    const __m256d a1 = NR == 8 ? _mm256_loadu_pd(a + 4) : a0;
    for (int c = 0; c < NC; ++c) {
      const __m256d bc = _mm256_broadcast_sd(b + c);
      if constexpr (SUB) {
        acc[0][c] = _mm256_fnmadd_pd(a0, bc, acc[0][c]);
        if constexpr (NR == 8) acc[1][c] = _mm256_fnmadd_pd(a1, bc, acc[1][c]);
      } else {
        acc[0][c] = _mm256_fmadd_pd(a0, bc, acc[0][c]);
        if constexpr (NR == 8) acc[1][c] = _mm256_fmadd_pd(a1, bc, acc[1][c]);
      }
    }
  }
}

// Y(rb.., jb..jb+NC) = Σ_{k ≥ jb} A(rb.., k) L(k, jb..)  (L's strict upper triangle is zero).
template <int NR, int NC>
inline void trmm_tile(int m, int jb, const double* A, int lda, const double* L, int ldl, double* Y,
                      int ldy) {
  __m256d acc[2][4];
  for (int c = 0; c < 4; ++c) acc[0][c] = acc[1][c] = _mm256_setzero_pd();
  for (int k = jb; k < m; ++k) {
    const double* a = A + static_cast<ptrdiff_t>(k) * lda;
    const __m256d a0 = _mm256_loadu_pd(a);
    const __m256d a1 = NR == 8 ? _mm256_loadu_pd(a + 4) : a0;
    for (int c = 0; c < NC; ++c) {
      const __m256d bc = _mm256_broadcast_sd(L + k + static_cast<ptrdiff_t>(jb + c) * ldl);
      acc[0][c] = _mm256_fmadd_pd(a0, bc, acc[0][c]);
      if constexpr (NR == 8) acc[1][c] = _mm256_fmadd_pd(a1, bc, acc[1][c]);
    }
  }
  for (int c = 0; c < NC; ++c) {
    double* y = Y + static_cast<ptrdiff_t>(jb + c) * ldy;
    _mm256_storeu_pd(y, acc[0][c]);
    if constexpr (NR == 8) _mm256_storeu_pd(y + 4, acc[1][c]);
  }
}

// C(rb.., jb..jb+NC) += Y(rb.., :) Y(jb.., :)ᵀ − C(rb.., 0:jb) C(jb.., 0:jb)ᵀ.
template <int NR, int NC>
inline void syrk_tile(int m, int rb, int jb, const double* Y, int ldy, double* C, int ldc) {
  __m256d acc[2][4];
  for (int c = 0; c < NC; ++c) {
    const double* col = C + rb + static_cast<ptrdiff_t>(jb + c) * ldc;
    acc[0][c] = _mm256_loadu_pd(col);
    acc[1][c] = NR == 8 ? _mm256_loadu_pd(col + 4) : acc[0][c];
  }
  if (m > 0) nt_acc<NR, NC, false>(m, Y + rb, ldy, Y + jb, ldy, acc);  // Y may be empty (null)
  nt_acc<NR, NC, true>(jb, C + rb, ldc, C + jb, ldc, acc);
  for (int c = 0; c < NC; ++c) {
    double* col = C + rb + static_cast<ptrdiff_t>(jb + c) * ldc;
    _mm256_storeu_pd(col, acc[0][c]);
    if constexpr (NR == 8) _mm256_storeu_pd(col + 4, acc[1][c]);
  }
}

template <template <int, int> class F, class... Args>
inline void dispatch(int nr, int nc, Args... args) {
  if (nr == 8) {
    switch (nc) {
      case 1: F<8, 1>::run(args...); break;
      case 2: F<8, 2>::run(args...); break;
      case 3: F<8, 3>::run(args...); break;
      default: F<8, 4>::run(args...); break;
    }
  } else {
    switch (nc) {
      case 1: F<4, 1>::run(args...); break;
      case 2: F<4, 2>::run(args...); break;
      case 3: F<4, 3>::run(args...); break;
      default: F<4, 4>::run(args...); break;
    }
  }
}
template <int NR, int NC>
struct TrmmTile {
  static void run(int m, int jb, const double* A, int lda, const double* L, int ldl, double* Y,
                  int ldy) {
    trmm_tile<NR, NC>(m, jb, A, lda, L, ldl, Y, ldy);
  }
};
template <int NR, int NC>
struct SyrkTile {
  static void run(int m, int rb, int jb, const double* Y, int ldy, double* C, int ldc) {
    syrk_tile<NR, NC>(m, rb, jb, Y, ldy, C, ldc);
  }
};
#endif

}  // namespace

namespace {
// Inverse of L's bw x bw diagonal block at (jb, jb) into dinv (rows jb..jb+3, 4 columns, zero
// above the diagonal and outside the block): M_ii = 1/L_ii, M_ij = −(Σ_{j≤k<i} L_ik M_kj)/L_ii.
// A zero pivot (inv_diag 0) gives a zero row and column, as the substitution would.
inline void diag_block_inverse(int jb, int bw, const double* C, int ldc, const double* inv_diag,
                               double* dinv, int ldd) {
  double* M = dinv + jb;
  if (bw == 4) {  // unrolled: this runs once per block of every factorization
    const double* l0 = C + jb + static_cast<ptrdiff_t>(jb) * ldc;
    const double *l1 = l0 + ldc, *l2 = l1 + ldc;
    const double i0 = inv_diag[jb], i1 = inv_diag[jb + 1], i2 = inv_diag[jb + 2],
                 i3 = inv_diag[jb + 3];
    const double m10 = -l0[1] * i0 * i1;
    const double m21 = -l1[2] * i1 * i2;
    const double m32 = -l2[3] * i2 * i3;
    const double m20 = -(l0[2] * i0 + l1[2] * m10) * i2;
    const double m31 = -(l1[3] * i1 + l2[3] * m21) * i3;
    const double m30 = -(l0[3] * i0 + l1[3] * m10 + l2[3] * m20) * i3;
    double* c0 = M;
    double *c1 = c0 + ldd, *c2 = c1 + ldd, *c3 = c2 + ldd;
    c0[0] = i0, c0[1] = m10, c0[2] = m20, c0[3] = m30;
    c1[0] = 0.0, c1[1] = i1, c1[2] = m21, c1[3] = m31;
    c2[0] = 0.0, c2[1] = 0.0, c2[2] = i2, c2[3] = m32;
    c3[0] = 0.0, c3[1] = 0.0, c3[2] = 0.0, c3[3] = i3;
    return;
  }
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) M[r + static_cast<ptrdiff_t>(c) * ldd] = 0.0;
  for (int c = 0; c < bw; ++c) {
    M[c + static_cast<ptrdiff_t>(c) * ldd] = inv_diag[jb + c];
    for (int r = c + 1; r < bw; ++r) {
      double s = 0.0;
      for (int k = c; k < r; ++k)
        s += C[jb + r + static_cast<ptrdiff_t>(jb + k) * ldc] * M[k + static_cast<ptrdiff_t>(c) * ldd];
      M[r + static_cast<ptrdiff_t>(c) * ldd] = -s * inv_diag[jb + r];
    }
  }
}
}  // namespace

void trmm_rl_padded(int n, int m, const double* A, int lda, const double* L, int ldl, double* Y,
                    int ldy) {
#if defined(__AVX2__) && defined(__FMA__)
  const int np = pad4(n);
  for (int rb = 0; rb < np; rb += 8) {
    const int nr = np - rb >= 8 ? 8 : 4;
    if (nr == 4 && rb + 4 > np) break;
    for (int jb = 0; jb < m; jb += 4)
      dispatch<TrmmTile>(nr, m - jb >= 4 ? 4 : m - jb, m, jb, A + rb, lda, L, ldl, Y + rb, ldy);
  }
#else
  trmm_rl(pad4(n), m, A, lda, L, ldl, Y, ldy);
#endif
}

bool syrk_potrf_ln_padded(int n, int m, const double* Y, int ldy, double* C, int ldc, int n_strict,
                          double* inv_diag, double psd_tol, double pivot_floor, double* dinv,
                          int lddinv) {
#if defined(__AVX2__) && defined(__FMA__)
  const int np = pad4(n);
  double d0[4];
  for (int jb = 0; jb < n; jb += 4) {
    const int bw = n - jb >= 4 ? 4 : n - jb;
    // C_jj before the update; the magnitude C_jj + ‖Y_j‖² is only formed for a pivot ≤ 0.
    for (int c = 0; c < bw; ++c) d0[c] = C[jb + c + static_cast<ptrdiff_t>(jb + c) * ldc];
    for (int rb = jb; rb < np; rb += 8) {
      const int nr = np - rb >= 8 ? 8 : 4;
      dispatch<SyrkTile>(nr, bw, m, rb, jb, Y, ldy, C, ldc);
    }
    // Factor the diagonal block, then the panel below it.
    for (int c = 0; c < bw; ++c) {
      const int j = jb + c;
      double* cj = C + static_cast<ptrdiff_t>(j) * ldc;
      double p = cj[j];
      for (int cc = 0; cc < c; ++cc) {
        const double l = C[j + static_cast<ptrdiff_t>(jb + cc) * ldc];
        p -= l * l;
      }
      if (!(p > pivot_floor)) {
        const double mag = std::abs(d0[c] + row_norm2(m, Y, j, ldy));
        if (!((j >= n_strict || mag > 0.0) && p >= -psd_tol * mag)) return false;
        p = std::max(pivot_floor, psd_tol * mag);  // no curvature: regularized (see the header)
      }
      const double sq = std::sqrt(p);
      const double is = 1.0 / sq;
      cj[j] = sq;
      inv_diag[j] = is;
      for (int r = 0; r < c; ++r) cj[jb + r] = 0.0;  // keep the strict upper triangle zero
      // Rows below the diagonal inside the block (scalar), then the panel in 4-row vectors.
      for (int r = j + 1; r < jb + 4 && r < np; ++r) {
        double v = cj[r];
        for (int cc = 0; cc < c; ++cc)
          v -= C[r + static_cast<ptrdiff_t>(jb + cc) * ldc] * C[j + static_cast<ptrdiff_t>(jb + cc) * ldc];
        cj[r] = v * is;
      }
      const __m256d vis = _mm256_set1_pd(is);
      for (int r = jb + 4; r < np; r += 4) {
        __m256d v = _mm256_loadu_pd(cj + r);
        for (int cc = 0; cc < c; ++cc) {
          const double* ccol = C + static_cast<ptrdiff_t>(jb + cc) * ldc;
          v = _mm256_fnmadd_pd(_mm256_loadu_pd(ccol + r), _mm256_broadcast_sd(ccol + j), v);
        }
        _mm256_storeu_pd(cj + r, _mm256_mul_pd(v, vis));
      }
    }
    diag_block_inverse(jb, bw, C, ldc, inv_diag, dinv, lddinv);
  }
  return true;
#else
  syrk_ln(n, m, Y, ldy, C, ldc);
  if (!potrf_l(n, n_strict, C, ldc, inv_diag, psd_tol, pivot_floor)) return false;
  for (int jb = 0; jb < n; jb += 4)
    diag_block_inverse(jb, n - jb >= 4 ? 4 : n - jb, C, ldc, inv_diag, dinv, lddinv);
  return true;
#endif
}

#if defined(__AVX2__) && defined(__FMA__)
namespace {

inline __m256i tail_mask(int rem) {  // lanes < rem set (rem in 1..4)
  return _mm256_cmpgt_epi64(_mm256_set1_epi64x(rem), _mm256_setr_epi64x(0, 1, 2, 3));
}

// y(0:m) += A(0:m, 0:n) x with m ≤ 4·NB (NB ≤ 8): NB independent accumulators (one per 4 rows),
// the last chunk masked; columns split over two accumulator sets to halve the FMA dependency
// chains. The accumulators are named registers: held in an array, GCC 12 stores them back to the
// stack after every column.
template <int NB>
inline void gemv_n_small(int m, int n, const double* A, int lda, const double* x, double* y) {
  static_assert(NB >= 1 && NB <= 8);
  const int rem = m - 4 * (NB - 1);  // rows in the last chunk, 1..4
  const __m256i mask = tail_mask(rem);
  auto ld = [&](const double* p, int b) {
    return b == NB - 1 ? _mm256_maskload_pd(p + 4 * b, mask) : _mm256_loadu_pd(p + 4 * b);
  };
  __m256d a0, a1, a2, a3, a4, a5, a6, a7;  // only the first NB are used
  __m256d b0 = _mm256_setzero_pd(), b1 = b0, b2 = b0, b3 = b0, b4 = b0, b5 = b0, b6 = b0, b7 = b0;
  a0 = ld(y, 0);
  if constexpr (NB > 1) a1 = ld(y, 1);
  if constexpr (NB > 2) a2 = ld(y, 2);
  if constexpr (NB > 3) a3 = ld(y, 3);
  if constexpr (NB > 4) a4 = ld(y, 4);
  if constexpr (NB > 5) a5 = ld(y, 5);
  if constexpr (NB > 6) a6 = ld(y, 6);
  if constexpr (NB > 7) a7 = ld(y, 7);
#define MIXPILOT_GEMV_COL(acc, col, xv)                                     \
  do {                                                                      \
    acc##0 = _mm256_fmadd_pd(ld(col, 0), xv, acc##0);                       \
    if constexpr (NB > 1) acc##1 = _mm256_fmadd_pd(ld(col, 1), xv, acc##1); \
    if constexpr (NB > 2) acc##2 = _mm256_fmadd_pd(ld(col, 2), xv, acc##2); \
    if constexpr (NB > 3) acc##3 = _mm256_fmadd_pd(ld(col, 3), xv, acc##3); \
    if constexpr (NB > 4) acc##4 = _mm256_fmadd_pd(ld(col, 4), xv, acc##4); \
    if constexpr (NB > 5) acc##5 = _mm256_fmadd_pd(ld(col, 5), xv, acc##5); \
    if constexpr (NB > 6) acc##6 = _mm256_fmadd_pd(ld(col, 6), xv, acc##6); \
    if constexpr (NB > 7) acc##7 = _mm256_fmadd_pd(ld(col, 7), xv, acc##7); \
  } while (0)
  int j = 0;
  for (; j + 2 <= n; j += 2) {
    const double* c0 = A + static_cast<ptrdiff_t>(j) * lda;
    const __m256d x0 = _mm256_broadcast_sd(x + j), x1 = _mm256_broadcast_sd(x + j + 1);
    MIXPILOT_GEMV_COL(a, c0, x0);
    MIXPILOT_GEMV_COL(b, c0 + lda, x1);
  }
  if (j < n) {
    const __m256d x0 = _mm256_broadcast_sd(x + j);
    MIXPILOT_GEMV_COL(a, A + static_cast<ptrdiff_t>(j) * lda, x0);
  }
#undef MIXPILOT_GEMV_COL
  auto st = [&](int b, __m256d v) {
    if (b == NB - 1)
      _mm256_maskstore_pd(y + 4 * b, mask, v);
    else
      _mm256_storeu_pd(y + 4 * b, v);
  };
  st(0, _mm256_add_pd(a0, b0));
  if constexpr (NB > 1) st(1, _mm256_add_pd(a1, b1));
  if constexpr (NB > 2) st(2, _mm256_add_pd(a2, b2));
  if constexpr (NB > 3) st(3, _mm256_add_pd(a3, b3));
  if constexpr (NB > 4) st(4, _mm256_add_pd(a4, b4));
  if constexpr (NB > 5) st(5, _mm256_add_pd(a5, b5));
  if constexpr (NB > 6) st(6, _mm256_add_pd(a6, b6));
  if constexpr (NB > 7) st(7, _mm256_add_pd(a7, b7));
}

// Horizontal sums of four vectors: (Σa, Σb, Σc, Σd).
inline __m256d hsum4(__m256d a, __m256d b, __m256d c, __m256d d) {
  const __m256d ab = _mm256_hadd_pd(a, b);  // a0+a1, b0+b1, a2+a3, b2+b3
  const __m256d cd = _mm256_hadd_pd(c, d);
  const __m256d lo = _mm256_permute2f128_pd(ab, cd, 0x20);
  const __m256d hi = _mm256_permute2f128_pd(ab, cd, 0x31);
  return _mm256_add_pd(lo, hi);
}

}  // namespace
#endif

void gemv_n(int m, int n, const double* A, int lda, const double* x, double* y) {
  if (m <= 0 || n <= 0) return;
#if defined(__AVX2__) && defined(__FMA__)
  while (m > 32) {
    gemv_n_small<8>(32, n, A, lda, x, y);
    A += 32, y += 32, m -= 32;
  }
  switch ((m + 3) / 4) {
    case 1: gemv_n_small<1>(m, n, A, lda, x, y); break;
    case 2: gemv_n_small<2>(m, n, A, lda, x, y); break;
    case 3: gemv_n_small<3>(m, n, A, lda, x, y); break;
    case 4: gemv_n_small<4>(m, n, A, lda, x, y); break;
    case 5: gemv_n_small<5>(m, n, A, lda, x, y); break;
    case 6: gemv_n_small<6>(m, n, A, lda, x, y); break;
    case 7: gemv_n_small<7>(m, n, A, lda, x, y); break;
    default: gemv_n_small<8>(m, n, A, lda, x, y); break;
  }
#else
  for (int j = 0; j < n; ++j)
    for (int r = 0; r < m; ++r) y[r] += A[r + static_cast<ptrdiff_t>(j) * lda] * x[j];
#endif
}

void gemv_t(int m, int n, const double* A, int lda, const double* x, double* y) {
  if (m <= 0 || n <= 0) return;
#if defined(__AVX2__) && defined(__FMA__)
  const int m4 = m & ~3, rem = m - m4;
  const __m256i mask = tail_mask(rem > 0 ? rem : 4);
  const __m256d xt = rem > 0 ? _mm256_maskload_pd(x + m4, mask) : _mm256_setzero_pd();
  // Columns in blocks of 4; a last block of 1-3 repeats column c0 where a column is absent and
  // stores only the present sums.
  for (int j = 0; j < n; j += 4) {
    const int nc = n - j < 4 ? n - j : 4;
    const double* c0 = A + static_cast<ptrdiff_t>(j) * lda;
    const double* c1 = nc > 1 ? c0 + lda : c0;
    const double* c2 = nc > 2 ? c0 + 2 * static_cast<ptrdiff_t>(lda) : c0;
    const double* c3 = nc > 3 ? c0 + 3 * static_cast<ptrdiff_t>(lda) : c0;
    __m256d a0 = _mm256_setzero_pd(), a1 = a0, a2 = a0, a3 = a0;
    for (int r = 0; r < m4; r += 4) {
      const __m256d xr = _mm256_loadu_pd(x + r);
      a0 = _mm256_fmadd_pd(_mm256_loadu_pd(c0 + r), xr, a0);
      a1 = _mm256_fmadd_pd(_mm256_loadu_pd(c1 + r), xr, a1);
      a2 = _mm256_fmadd_pd(_mm256_loadu_pd(c2 + r), xr, a2);
      a3 = _mm256_fmadd_pd(_mm256_loadu_pd(c3 + r), xr, a3);
    }
    if (rem > 0) {
      a0 = _mm256_fmadd_pd(_mm256_maskload_pd(c0 + m4, mask), xt, a0);
      a1 = _mm256_fmadd_pd(_mm256_maskload_pd(c1 + m4, mask), xt, a1);
      a2 = _mm256_fmadd_pd(_mm256_maskload_pd(c2 + m4, mask), xt, a2);
      a3 = _mm256_fmadd_pd(_mm256_maskload_pd(c3 + m4, mask), xt, a3);
    }
    const __m256d sums = hsum4(a0, a1, a2, a3);
    if (nc == 4) {
      _mm256_storeu_pd(y + j, _mm256_add_pd(_mm256_loadu_pd(y + j), sums));
    } else {
      const __m256i ym = tail_mask(nc);
      _mm256_maskstore_pd(y + j, ym, _mm256_add_pd(_mm256_maskload_pd(y + j, ym), sums));
    }
  }
#else
  for (int j = 0; j < n; ++j) {
    double s = 0.0;
    for (int r = 0; r < m; ++r) s += A[r + static_cast<ptrdiff_t>(j) * lda] * x[r];
    y[j] += s;
  }
#endif
}

#if defined(__AVX2__) && defined(__FMA__)
namespace {
// Rows r..r+3 (mask m0) and, with TWO, r+4..r+7 (mask m1) of C += A B; columns in blocks of 4.
// FULL: both masks are all lanes, so plain loads and stores (masked ones cost more on Zen).
template <bool TWO, bool FULL>
inline void gemm_nn_rows(int n, int k, const double* A, int lda, const double* B, int ldb,
                         double* C, int ldc, __m256i m0, __m256i m1, bool overwrite) {
  const __m256d zero = _mm256_setzero_pd();
  const auto ldc0 = [&](const double* p) {  // C's old values, or zero
    if (overwrite) return zero;
    if constexpr (FULL) return _mm256_loadu_pd(p);
    else return _mm256_maskload_pd(p, m0);
  };
  const auto ldc1 = [&](const double* p) {
    if (overwrite) return zero;
    if constexpr (FULL) return _mm256_loadu_pd(p);
    else return _mm256_maskload_pd(p, m1);
  };
  const auto ld0 = [&](const double* p) {
    if constexpr (FULL) return _mm256_loadu_pd(p);
    else return _mm256_maskload_pd(p, m0);
  };
  const auto ld1 = [&](const double* p) {
    if constexpr (FULL) return _mm256_loadu_pd(p);
    else return _mm256_maskload_pd(p, m1);
  };
  const auto st0 = [&](double* p, __m256d v) {
    if constexpr (FULL) _mm256_storeu_pd(p, v);
    else _mm256_maskstore_pd(p, m0, v);
  };
  const auto st1 = [&](double* p, __m256d v) {
    if constexpr (FULL) _mm256_storeu_pd(p, v);
    else _mm256_maskstore_pd(p, m1, v);
  };
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    double* c = C + static_cast<ptrdiff_t>(j) * ldc;
    __m256d c00 = ldc0(c), c01 = ldc0(c + ldc), c02 = ldc0(c + 2 * ldc), c03 = ldc0(c + 3 * ldc);
    __m256d c10 = _mm256_setzero_pd(), c11 = c10, c12 = c10, c13 = c10;
    if constexpr (TWO) {
      c10 = ldc1(c + 4), c11 = ldc1(c + ldc + 4);
      c12 = ldc1(c + 2 * ldc + 4), c13 = ldc1(c + 3 * ldc + 4);
    }
    const double* b = B + static_cast<ptrdiff_t>(j) * ldb;
    for (int p = 0; p < k; ++p) {
      const double* a = A + static_cast<ptrdiff_t>(p) * lda;
      const __m256d a0 = ld0(a);
      const __m256d b0 = _mm256_broadcast_sd(b + p), b1 = _mm256_broadcast_sd(b + ldb + p),
                    b2 = _mm256_broadcast_sd(b + 2 * ldb + p),
                    b3 = _mm256_broadcast_sd(b + 3 * ldb + p);
      c00 = _mm256_fmadd_pd(a0, b0, c00);
      c01 = _mm256_fmadd_pd(a0, b1, c01);
      c02 = _mm256_fmadd_pd(a0, b2, c02);
      c03 = _mm256_fmadd_pd(a0, b3, c03);
      if constexpr (TWO) {
        const __m256d a1 = ld1(a + 4);
        c10 = _mm256_fmadd_pd(a1, b0, c10);
        c11 = _mm256_fmadd_pd(a1, b1, c11);
        c12 = _mm256_fmadd_pd(a1, b2, c12);
        c13 = _mm256_fmadd_pd(a1, b3, c13);
      }
    }
    st0(c, c00);
    st0(c + ldc, c01);
    st0(c + 2 * ldc, c02);
    st0(c + 3 * ldc, c03);
    if constexpr (TWO) {
      st1(c + 4, c10);
      st1(c + ldc + 4, c11);
      st1(c + 2 * ldc + 4, c12);
      st1(c + 3 * ldc + 4, c13);
    }
  }
  for (; j < n; ++j) {
    double* c = C + static_cast<ptrdiff_t>(j) * ldc;
    const double* b = B + static_cast<ptrdiff_t>(j) * ldb;
    __m256d c0 = ldc0(c), c1 = _mm256_setzero_pd();
    if constexpr (TWO) c1 = ldc1(c + 4);
    for (int p = 0; p < k; ++p) {
      const double* a = A + static_cast<ptrdiff_t>(p) * lda;
      const __m256d bp = _mm256_broadcast_sd(b + p);
      c0 = _mm256_fmadd_pd(ld0(a), bp, c0);
      if constexpr (TWO) c1 = _mm256_fmadd_pd(ld1(a + 4), bp, c1);
    }
    st0(c, c0);
    if constexpr (TWO) st1(c + 4, c1);
  }
}
}  // namespace
#endif

void gemm_nn(int m, int n, int k, const double* A, int lda, const double* B, int ldb, double* C,
             int ldc, bool overwrite) {
  if (m <= 0 || n <= 0) return;
  if (k <= 0) {
    if (overwrite)
      for (int j = 0; j < n; ++j)
        for (int r = 0; r < m; ++r) C[r + static_cast<ptrdiff_t>(j) * ldc] = 0.0;
    return;
  }
#if defined(__AVX2__) && defined(__FMA__)
  for (int r = 0; r < m; r += 8) {
    const int rows = m - r < 8 ? m - r : 8;
    const int r0 = rows < 4 ? rows : 4, r1 = rows - r0;
    const __m256i m0 = tail_mask(r0), m1 = tail_mask(r1 > 0 ? r1 : 4);
    if (rows == 8)
      gemm_nn_rows<true, true>(n, k, A + r, lda, B, ldb, C + r, ldc, m0, m1, overwrite);
    else if (r1 > 0)
      gemm_nn_rows<true, false>(n, k, A + r, lda, B, ldb, C + r, ldc, m0, m1, overwrite);
    else if (rows == 4)
      gemm_nn_rows<false, true>(n, k, A + r, lda, B, ldb, C + r, ldc, m0, m1, overwrite);
    else
      gemm_nn_rows<false, false>(n, k, A + r, lda, B, ldb, C + r, ldc, m0, m1, overwrite);
  }
#else
  if (overwrite)
    for (int j = 0; j < n; ++j)
      for (int r = 0; r < m; ++r) C[r + static_cast<ptrdiff_t>(j) * ldc] = 0.0;
  for (int j = 0; j < n; ++j)
    for (int p = 0; p < k; ++p)
      for (int r = 0; r < m; ++r)
        C[r + static_cast<ptrdiff_t>(j) * ldc] +=
            A[r + static_cast<ptrdiff_t>(p) * lda] * B[p + static_cast<ptrdiff_t>(j) * ldb];
#endif
}

void trsv_lt_small(int n, const double* dinv, int lddinv, double* x) {
#if defined(__AVX2__) && defined(__FMA__)
  // z_j = Σ_r M_rj x_r: four independent dot products of length 4 (M is zero outside n x n).
  const __m256i mask = tail_mask(n);
  const __m256d xv = _mm256_maskload_pd(x, mask);
  const __m256d z = hsum4(_mm256_mul_pd(_mm256_loadu_pd(dinv), xv),
                          _mm256_mul_pd(_mm256_loadu_pd(dinv + lddinv), xv),
                          _mm256_mul_pd(_mm256_loadu_pd(dinv + 2 * lddinv), xv),
                          _mm256_mul_pd(_mm256_loadu_pd(dinv + 3 * lddinv), xv));
  _mm256_maskstore_pd(x, mask, z);
#else
  double z[4];
  for (int j = 0; j < n; ++j) {
    z[j] = 0.0;
    for (int r = j; r < n; ++r) z[j] += dinv[r + static_cast<ptrdiff_t>(j) * lddinv] * x[r];
  }
  for (int j = 0; j < n; ++j) x[j] = z[j];
#endif
}

void trsv_lt_blocked(int n, const double* L, int ldl, const double* dinv, int lddinv, double* x) {
  for (int jb = n - 4; jb >= 0; jb -= 4) {
    if (jb + 4 < n) {
      double t[4] = {0.0, 0.0, 0.0, 0.0};
      gemv_t(n - jb - 4, 4, L + (jb + 4) + static_cast<ptrdiff_t>(jb) * ldl, ldl, x + jb + 4, t);
      for (int r = 0; r < 4; ++r) x[jb + r] -= t[r];
    }
    trsv_lt_small(4, dinv + jb, lddinv, x + jb);
  }
}

void transpose(int m, int n, const double* A, int lda, double* B, int ldb) {
  const auto at = [](const double* M, int ld, int r, int c) -> const double& {
    return M[r + static_cast<ptrdiff_t>(c) * ld];
  };
  int c = 0;
#if defined(__AVX2__) && defined(__FMA__)
  // Columns c..c+3 of A, rows r..r+3: unpack pairs, then swap 128-bit halves.
  for (; c + 4 <= n; c += 4) {
    int r = 0;
    for (; r + 4 <= m; r += 4) {
      const __m256d a0 = _mm256_loadu_pd(&at(A, lda, r, c));
      const __m256d a1 = _mm256_loadu_pd(&at(A, lda, r, c + 1));
      const __m256d a2 = _mm256_loadu_pd(&at(A, lda, r, c + 2));
      const __m256d a3 = _mm256_loadu_pd(&at(A, lda, r, c + 3));
      const __m256d t0 = _mm256_unpacklo_pd(a0, a1), t1 = _mm256_unpackhi_pd(a0, a1);
      const __m256d t2 = _mm256_unpacklo_pd(a2, a3), t3 = _mm256_unpackhi_pd(a2, a3);
      double* b = B + c + static_cast<ptrdiff_t>(r) * ldb;
      _mm256_storeu_pd(b, _mm256_permute2f128_pd(t0, t2, 0x20));
      _mm256_storeu_pd(b + ldb, _mm256_permute2f128_pd(t1, t3, 0x20));
      _mm256_storeu_pd(b + 2 * static_cast<ptrdiff_t>(ldb), _mm256_permute2f128_pd(t0, t2, 0x31));
      _mm256_storeu_pd(b + 3 * static_cast<ptrdiff_t>(ldb), _mm256_permute2f128_pd(t1, t3, 0x31));
    }
    for (; r < m; ++r)
      for (int j = c; j < c + 4; ++j) B[j + static_cast<ptrdiff_t>(r) * ldb] = at(A, lda, r, j);
  }
#endif
  for (; c < n; ++c)
    for (int r = 0; r < m; ++r) B[c + static_cast<ptrdiff_t>(r) * ldb] = at(A, lda, r, c);
}

double max_step(int m, const double* z, const double* dz, double alpha, int* block) {
  // A component can lower α only where z + α dz ≤ 0 with dz < 0 (an FMA keeps the sign of the
  // exact value, so this never misses a smaller ratio); only such blocks divide.
  double a = alpha;
  int found = -1;  // the block (or tail index) of the last strict improvement
  int k = 0;
#if defined(__AVX2__) && defined(__FMA__)
  const __m256d zero = _mm256_setzero_pd();
  __m256d best = _mm256_set1_pd(a);
  for (; k + 4 <= m; k += 4) {
    const __m256d d = _mm256_loadu_pd(dz + k);
    const __m256d zk = _mm256_loadu_pd(z + k);
    const __m256d neg = _mm256_cmp_pd(d, zero, _CMP_LT_OQ);
    const __m256d hit = _mm256_and_pd(neg, _mm256_cmp_pd(_mm256_fmadd_pd(best, d, zk), zero,
                                                         _CMP_LE_OQ));
    if (_mm256_movemask_pd(hit) == 0) continue;
    const __m256d ratio = _mm256_div_pd(_mm256_sub_pd(zero, zk), d);
    // min_pd returns its second operand when either is NaN: a NaN ratio never wins.
    const __m256d lower = _mm256_min_pd(_mm256_blendv_pd(best, ratio, neg), best);
    const __m128d h = _mm_min_pd(_mm256_castpd256_pd128(lower), _mm256_extractf128_pd(lower, 1));
    const double b = std::min(_mm_cvtsd_f64(h), _mm_cvtsd_f64(_mm_unpackhi_pd(h, h)));
    if (b < a) {
      a = b;
      found = k;
      best = _mm256_set1_pd(a);
    }
  }
#endif
  for (; k < m; ++k)
    if (dz[k] < 0.0 && -z[k] / dz[k] < a) {
      a = -z[k] / dz[k];
      found = k;
    }
  *block = -1;
  // The first component of the improving block that attains α (the same division: exact).
  for (k = found; k >= 0 && k < m; ++k)
    if (dz[k] < 0.0 && -z[k] / dz[k] == a) {
      *block = k;
      break;
    }
  return a;
}

}  // namespace mixpilot::kernels
