#pragma once
// Whole-matrix checks that run on every linearization and every QP, written as reductions the
// compiler vectorizes: Eigen's allFinite() costs several instructions per entry, and a
// floating-point sum of |entries| is not vectorized without reassociation.
#include <bit>
#include <cstddef>
#include <cstdint>

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

// Every off-diagonal entry of the n x n column-major matrix a (leading dimension ld) is ±0
// (NaN and ±inf count as nonzero): the magnitudes' bits OR-ed, an integer reduction.
[[nodiscard]] inline bool is_diagonal(const double* a, int n, int ld) {
  std::uint64_t bits = 0;
  for (int c = 0; c < n; ++c) {
    const double* col = a + static_cast<std::ptrdiff_t>(c) * ld;
    for (int r = 0; r < n; ++r)
      bits |= r == c ? 0 : std::bit_cast<std::uint64_t>(col[r]) & kMagnitudeBits;
  }
  return bits == 0;
}
[[nodiscard]] inline bool is_diagonal(const Eigen::MatrixXd& m) {
  return is_diagonal(m.data(), static_cast<int>(m.rows()), static_cast<int>(m.rows()));
}

// Every entry is ±0 (NaN and ±inf count as nonzero).
[[nodiscard]] inline bool is_zero(const Eigen::MatrixXd& m) {
  std::uint64_t bits = 0;
  for (Eigen::Index k = 0; k < m.size(); ++k)
    bits |= std::bit_cast<std::uint64_t>(m.data()[k]) & kMagnitudeBits;
  return bits == 0;
}

}  // namespace mixpilot
