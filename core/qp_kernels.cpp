#include "core/qp_kernels.hpp"

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

void syr_lower(int n, double alpha, const double* y, double* C, int ldc) {
  for (int j = 0; j < n; ++j) {
    double* c = C + static_cast<ptrdiff_t>(j) * ldc;
    const double a = alpha * y[j];
    for (int r = j; r < n; ++r) c[r] += a * y[r];
  }
}

bool potrf_l(int n, int n_strict, double* C, int ldc, double* inv_diag, double psd_tol) {
  for (int j = 0; j < n; ++j) {
    double* cj = C + static_cast<ptrdiff_t>(j) * ldc;
    const double d0 = std::abs(cj[j]);
    for (int k = 0; k < j; ++k) {
      const double* ck = C + static_cast<ptrdiff_t>(k) * ldc;
      const double a = ck[j];
      for (int r = j; r < n; ++r) cj[r] -= a * ck[r];
    }
    const double p = cj[j];
    if (p > 0.0) {
      const double s = std::sqrt(p), is = 1.0 / s;
      inv_diag[j] = is;
      cj[j] = s;
      for (int r = j + 1; r < n; ++r) cj[r] *= is;
    } else if ((j >= n_strict || d0 > 0.0) && p >= -psd_tol * d0) {
      inv_diag[j] = 0.0;
      for (int r = j; r < n; ++r) cj[r] = 0.0;
    } else {
      return false;
    }
  }
  return true;
}

void trsv_ln(int n, const double* L, int ldl, const double* inv_diag, double* x) {
  // Blocks of 4 columns: the 4 x 4 diagonal block by substitution, then the rows below updated
  // with the block's 4 solved components (4-row AVX2 chunks, the last one masked).
  for (int jb = 0; jb < n; jb += 4) {
    const int bw = n - jb < 4 ? n - jb : 4;
    if (bw == 4) {  // unrolled: the generic loop below costs more in loop control than flops
      const double* l0 = L + jb + static_cast<ptrdiff_t>(jb) * ldl;
      const double* l1 = l0 + ldl;
      const double* l2 = l1 + ldl;
      double* xb = x + jb;
      const double z0 = xb[0] * inv_diag[jb];
      const double z1 = (xb[1] - l0[1] * z0) * inv_diag[jb + 1];
      const double z2 = (xb[2] - l0[2] * z0 - l1[2] * z1) * inv_diag[jb + 2];
      const double z3 = (xb[3] - l0[3] * z0 - l1[3] * z1 - l2[3] * z2) * inv_diag[jb + 3];
      xb[0] = z0, xb[1] = z1, xb[2] = z2, xb[3] = z3;
    } else {
      for (int c = 0; c < bw; ++c) {
        const int j = jb + c;
        const double* lj = L + static_cast<ptrdiff_t>(j) * ldl;
        const double z = x[j] * inv_diag[j];
        x[j] = z;
        for (int r = j + 1; r < jb + bw; ++r) x[r] -= lj[r] * z;
      }
    }
    if (jb + 4 >= n) break;
#if defined(__AVX2__) && defined(__FMA__)
    const double* l0 = L + static_cast<ptrdiff_t>(jb) * ldl;
    const __m256d z0 = _mm256_broadcast_sd(x + jb), z1 = _mm256_broadcast_sd(x + jb + 1),
                  z2 = _mm256_broadcast_sd(x + jb + 2), z3 = _mm256_broadcast_sd(x + jb + 3);
    int r = jb + 4;
    for (; r + 4 <= n; r += 4) {
      __m256d v = _mm256_loadu_pd(x + r);
      v = _mm256_fnmadd_pd(_mm256_loadu_pd(l0 + r), z0, v);
      v = _mm256_fnmadd_pd(_mm256_loadu_pd(l0 + ldl + r), z1, v);
      v = _mm256_fnmadd_pd(_mm256_loadu_pd(l0 + 2 * ldl + r), z2, v);
      v = _mm256_fnmadd_pd(_mm256_loadu_pd(l0 + 3 * ldl + r), z3, v);
      _mm256_storeu_pd(x + r, v);
    }
    for (; r < n; ++r)
      x[r] -= l0[r] * x[jb] + l0[ldl + r] * x[jb + 1] + l0[2 * ldl + r] * x[jb + 2] +
              l0[3 * ldl + r] * x[jb + 3];
#else
    for (int c = 0; c < 4; ++c) {
      const double* lc = L + static_cast<ptrdiff_t>(jb + c) * ldl;
      for (int r = jb + 4; r < n; ++r) x[r] -= lc[r] * x[jb + c];
    }
#endif
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

inline double row_norm2(int m, const double* y, int ldy) {
  double s = 0.0;
  for (int k = 0; k < m; ++k) s += y[static_cast<ptrdiff_t>(k) * ldy] * y[static_cast<ptrdiff_t>(k) * ldy];
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
  nt_acc<NR, NC, false>(m, Y + rb, ldy, Y + jb, ldy, acc);
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
                          double* inv_diag, double psd_tol) {
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
      double is;
      if (p > 0.0) {
        const double sq = std::sqrt(p);
        is = 1.0 / sq;
        cj[j] = sq;
      } else if ((j >= n_strict || d0[c] + row_norm2(m, Y + j, ldy) > 0.0) &&
                 p >= -psd_tol * std::abs(d0[c] + row_norm2(m, Y + j, ldy))) {
        is = 0.0;
        cj[j] = 0.0;
      } else {
        return false;
      }
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
  }
  return true;
#else
  syrk_ln(n, m, Y, ldy, C, ldc);
  return potrf_l(n, n_strict, C, ldc, inv_diag, psd_tol);
#endif
}

#if defined(__AVX2__) && defined(__FMA__)
namespace {

inline __m256i tail_mask(int rem) {  // lanes < rem set (rem in 1..4)
  return _mm256_cmpgt_epi64(_mm256_set1_epi64x(rem), _mm256_setr_epi64x(0, 1, 2, 3));
}

// y(0:m) += A(0:m, 0:n) x with m ≤ 4·NB: NB independent accumulators (one per 4 rows), the last
// chunk masked; columns split over two accumulator sets to halve the FMA dependency chains.
template <int NB>
inline void gemv_n_small(int m, int n, const double* A, int lda, const double* x, double* y) {
  const int rem = m - 4 * (NB - 1);  // rows in the last chunk, 1..4
  const __m256i mask = tail_mask(rem);
  __m256d acc[NB], acc2[NB];
  for (int b = 0; b < NB; ++b) acc2[b] = _mm256_setzero_pd();
  for (int b = 0; b < NB - 1; ++b) acc[b] = _mm256_loadu_pd(y + 4 * b);
  acc[NB - 1] = _mm256_maskload_pd(y + 4 * (NB - 1), mask);
  int j = 0;
  for (; j + 2 <= n; j += 2) {
    const double* c0 = A + static_cast<ptrdiff_t>(j) * lda;
    const double* c1 = c0 + lda;
    const __m256d x0 = _mm256_broadcast_sd(x + j), x1 = _mm256_broadcast_sd(x + j + 1);
    for (int b = 0; b < NB - 1; ++b) {
      acc[b] = _mm256_fmadd_pd(_mm256_loadu_pd(c0 + 4 * b), x0, acc[b]);
      acc2[b] = _mm256_fmadd_pd(_mm256_loadu_pd(c1 + 4 * b), x1, acc2[b]);
    }
    acc[NB - 1] = _mm256_fmadd_pd(_mm256_maskload_pd(c0 + 4 * (NB - 1), mask), x0, acc[NB - 1]);
    acc2[NB - 1] = _mm256_fmadd_pd(_mm256_maskload_pd(c1 + 4 * (NB - 1), mask), x1, acc2[NB - 1]);
  }
  if (j < n) {
    const double* c0 = A + static_cast<ptrdiff_t>(j) * lda;
    const __m256d x0 = _mm256_broadcast_sd(x + j);
    for (int b = 0; b < NB - 1; ++b) acc[b] = _mm256_fmadd_pd(_mm256_loadu_pd(c0 + 4 * b), x0, acc[b]);
    acc[NB - 1] = _mm256_fmadd_pd(_mm256_maskload_pd(c0 + 4 * (NB - 1), mask), x0, acc[NB - 1]);
  }
  for (int b = 0; b < NB - 1; ++b) _mm256_storeu_pd(y + 4 * b, _mm256_add_pd(acc[b], acc2[b]));
  _mm256_maskstore_pd(y + 4 * (NB - 1), mask, _mm256_add_pd(acc[NB - 1], acc2[NB - 1]));
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
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    const double* c0 = A + static_cast<ptrdiff_t>(j) * lda;
    const double *c1 = c0 + lda, *c2 = c1 + lda, *c3 = c2 + lda;
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
    _mm256_storeu_pd(y + j, _mm256_add_pd(_mm256_loadu_pd(y + j), hsum4(a0, a1, a2, a3)));
  }
  for (; j < n; ++j) {
    const double* col = A + static_cast<ptrdiff_t>(j) * lda;
    double s = 0.0;
    for (int r = 0; r < m; ++r) s += col[r] * x[r];
    y[j] += s;
  }
#else
  for (int j = 0; j < n; ++j) {
    double s = 0.0;
    for (int r = 0; r < m; ++r) s += A[r + static_cast<ptrdiff_t>(j) * lda] * x[r];
    y[j] += s;
  }
#endif
}

}  // namespace mixpilot::kernels
