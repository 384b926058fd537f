#pragma once
// Whole-matrix checks that run on every linearization and every QP, written as reductions the
// compiler vectorizes: Eigen's allFinite() costs several instructions per entry, and a
// floating-point sum of |entries| is not vectorized without reassociation.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <Eigen/Core>

namespace mixpilot {

// An entry's bits without the sign: nonzero unless the entry is ±0.
inline constexpr std::uint64_t kMagnitudeBits = ~(std::uint64_t{1} << 63);

// Σ m·0 is 0 when every entry of m is finite and NaN as soon as one is NaN or ±inf (Eigen
// vectorizes its sums).
template <class Derived>
[[nodiscard]] bool all_finite(const Eigen::DenseBase<Derived>& m) {
  return (m.derived().array() * 0.0).sum() == 0.0;
}

// The bits of p[0..n) OR-ed, the sign masked off once at the end: nonzero unless every entry is
// ±0. A contiguous integer reduction, which the compiler vectorizes.
[[nodiscard]] inline std::uint64_t magnitude_bits(const double* p, std::ptrdiff_t n) {
  std::uint64_t bits = 0;
  for (std::ptrdiff_t k = 0; k < n; ++k) bits |= std::bit_cast<std::uint64_t>(p[k]);
  return bits & kMagnitudeBits;
}

// Every off-diagonal entry of the n x n column-major matrix a (leading dimension ld) is ±0
// (NaN and ±inf count as nonzero). Rows in blocks of 4 with the diagonal's lane masked off: a
// per-entry test of r == c keeps the loop scalar, and the two runs around the diagonal are too
// short for a vectorized loop to pay.
[[nodiscard]] inline bool is_diagonal(const double* a, int n, int ld) {
  using U4 = std::uint64_t __attribute__((vector_size(32)));
  const U4 lane = {0, 1, 2, 3};
  U4 acc = {};
  std::uint64_t bits = 0;
  for (int c = 0; c < n; ++c) {
    const double* col = a + static_cast<std::ptrdiff_t>(c) * ld;
    int r = 0;
    for (; r + 4 <= n; r += 4) {
      U4 v;
      std::memcpy(&v, col + r, sizeof v);
      acc |= v & static_cast<U4>(lane + std::uint64_t(r) != std::uint64_t(c));
    }
    for (; r < n; ++r)
      if (r != c) bits |= std::bit_cast<std::uint64_t>(col[r]);
  }
  bits |= acc[0] | acc[1] | acc[2] | acc[3];
  return (bits & kMagnitudeBits) == 0;
}
[[nodiscard]] inline bool is_diagonal(const Eigen::MatrixXd& m) {
  return is_diagonal(m.data(), static_cast<int>(m.rows()), static_cast<int>(m.rows()));
}

// Every entry is ±0 (NaN and ±inf count as nonzero).
[[nodiscard]] inline bool is_zero(const Eigen::MatrixXd& m) {
  return magnitude_bits(m.data(), m.size()) == 0;
}

}  // namespace mixpilot
