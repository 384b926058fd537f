#pragma once
// Internal to the qp layer (core/qp/detail/). Small dense kernels of the Riccati recursion
// (core/qp/qp_riccati_ipm.cpp), on column-major storage with leading dimensions. Sizes are
// those of one stage (≲ 30), where general BLAS-style blocking does not pay; see qp_kernels.cpp
// for the register-blocked versions.
namespace mixpilot::kernels {

// Y (n x m) = A (n x m) · L (m x m, lower triangular).
void trmm_rl(int n, int m, const double* A, int lda, const double* L, int ldl, double* Y, int ldy);

// C (n x n, lower triangle) += Y Yᵀ, Y n x m.
void syrk_ln(int n, int m, const double* Y, int ldy, double* C, int ldc);

// In-place lower Cholesky C = L Lᵀ (IPM blocks are ill-conditioned by design, so pivots are not
// compared with a relative threshold). A pivot p ≤ pivot_floor with p ≥ −psd_tol·|C_jj| is a
// direction without curvature: of a state column (j ≥ n_strict: a positive semidefinite
// cost-to-go) or of an input column with C_jj > 0 (its Schur complement vanished to rounding error
// under huge barrier weights). It is regularized to max(pivot_floor, psd_tol·|C_jj|) > 0 (C_jj
// before the elimination), not dropped: the Riccati
// recursion forms Δπ = L (Lᵀ Δx + L⁻¹ g), which keeps g's component along that direction only if
// L is invertible (a zero column would lose it, and a warm start whose multipliers leave a residual
// there would never converge). Otherwise — negative curvature, or an input with no curvature at
// all — returns false.
bool potrf_l(int n, int n_strict, double* C, int ldc, double* inv_diag, double psd_tol,
             double pivot_floor);

// x ← L⁻¹ x (zero pivots, inv_diag 0, give zero components), with dinv the inverses of L's 4 x 4 diagonal
// blocks as syrk_potrf_ln_padded stores them.
void trsv_ln(int n, const double* L, int ldl, const double* dinv, int lddinv, double* x);
// x ← L⁻ᵀ x.
void trsv_lt(int n, const double* L, int ldl, const double* inv_diag, double* x);
// x ← L⁻ᵀ x for n ≤ 4 from the inverse M of L (dinv as syrk_potrf_ln_padded stores it): x ← Mᵀx,
// four independent dot products instead of a substitution chain.
void trsv_lt_small(int n, const double* dinv, int lddinv, double* x);
// Lᵀ x = b for n a multiple of 4, with the inverses of L's 4 x 4 diagonal blocks (as
// trsv_ln): per block from the last, x_b ← M_bᵀ (x_b − L_{>b,b}ᵀ x_{>b}); no scalar chain.
void trsv_lt_blocked(int n, const double* L, int ldl, const double* dinv, int lddinv, double* x);

// Register-blocked (AVX2/FMA) variants on row-padded storage: all row counts are rounded up to
// a multiple of 4, so every ld must be ≥ pad4(rows) and padding rows must be readable (inputs'
// padding rows zero). L's strict upper triangle must be zero.
// Y (pad4(n) x m) = A · L (m x m lower).
void trmm_rl_padded(int n, int m, const double* A, int lda, const double* L, int ldl, double* Y,
                    int ldy);
// C += Y Yᵀ (Y n x m) and C = L Lᵀ in place, fused (left-looking, 4 columns at a time), with
// potrf_l's pivot rules; keeps C's strict upper triangle zero.
// Also stores the inverse of each 4 x 4 diagonal block of L (rows jb..jb+3 of the 4 columns of
// dinv, zero above the diagonal; ld ≥ pad4(n)) for trsv_ln: its substitution chains become
// matrix-vector products.
bool syrk_potrf_ln_padded(int n, int m, const double* Y, int ldy, double* C, int ldc, int n_strict,
                          double* inv_diag, double psd_tol, double pivot_floor, double* dinv,
                          int lddinv);
// y (m) += A x (A m x n);  y (n) += Aᵀ x (A m x n). Exact row counts, no padding needed.
void gemv_n(int m, int n, const double* A, int lda, const double* x, double* y);
// C += A B with A m x k, B k x n, C m x n (column-major, any leading dimensions): 8 x 4 register
// tiles, B broadcast (the small products of partial condensing, where Eigen's GEMM spends more
// on packing than on the products).
// With overwrite, C = A B (C's old values are not read).
void gemm_nn(int m, int n, int k, const double* A, int lda, const double* B, int ldb, double* C,
             int ldc, bool overwrite = false);
void gemv_t(int m, int n, const double* A, int lda, const double* x, double* y);
// B (n x m) = Aᵀ with A m x n (column-major, any leading dimensions): 4 x 4 register blocks,
// the QP's matrices into the solver's transposed layouts ([Bᵀ; Aᵀ], [Dᵀ; Cᵀ]).
void transpose(int m, int n, const double* A, int lda, double* B, int ldb);

// The fraction-to-boundary search of an interior-point step: the largest α ≤ alpha with
// z + α dz ≥ 0 (z > 0), i.e. min(alpha, min over dz_k < 0 of −z_k/dz_k); *block receives the
// first k attaining it when it is below alpha, else −1. NaN components never block. Vectorized:
// blocks of 4 where no component can block cost one FMA and a compare, no division.
double max_step(int m, const double* z, const double* dz, double alpha, int* block);

}  // namespace mixpilot::kernels
