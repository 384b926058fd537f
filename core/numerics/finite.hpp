#pragma once
// Σ m·0 is 0 when every entry of m is finite and NaN as soon as one is NaN or ±inf: one
// vectorized sum, where Eigen's allFinite() costs several instructions per entry (these checks
// run on every linearization and every QP).
#include <Eigen/Core>

namespace mixpilot {

template <class Derived>
[[nodiscard]] bool all_finite(const Eigen::DenseBase<Derived>& m) {
  return (m.derived().array() * 0.0).sum() == 0.0;
}

}  // namespace mixpilot
