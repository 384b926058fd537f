#include "core/qp_kernels.hpp"

#include <cmath>
#include <cstddef>

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
  for (int j = 0; j < n; ++j) {
    const double* lj = L + static_cast<ptrdiff_t>(j) * ldl;
    const double z = x[j] * inv_diag[j];
    x[j] = z;
    for (int r = j + 1; r < n; ++r) x[r] -= lj[r] * z;
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

void trmv_lt_add(int n, const double* L, int ldl, const double* x, double* y) {
  for (int j = 0; j < n; ++j) {
    const double* lj = L + static_cast<ptrdiff_t>(j) * ldl;
    double s = 0.0;
    for (int r = j; r < n; ++r) s += lj[r] * x[r];
    y[j] += s;
  }
}

void trmv_ln(int n, const double* L, int ldl, const double* x, double* y) {
  for (int r = 0; r < n; ++r) y[r] = 0.0;
  for (int j = 0; j < n; ++j) {
    const double* lj = L + static_cast<ptrdiff_t>(j) * ldl;
    const double a = x[j];
    for (int r = j; r < n; ++r) y[r] += lj[r] * a;
  }
}

}  // namespace mixpilot::kernels
