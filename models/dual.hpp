#pragma once
// Forward-mode AD scalar Dual<n>: a value and its derivatives with respect to n directions,
// a + Σ_j ∂a/∂z_j ε_j with ε_i ε_j = 0.
//
// Why not Eigen's AutoDiffScalar: its expression templates leave nested temporaries that g++
// does not flatten; a whole ERK4 step with it ran several times slower than with this type
// (core/numerics/integrator_erk4.hpp). Here every operation is eager: one pass over the derivatives,
// stored as g++ vector-extension blocks of 4 doubles (one AVX2 register each, padded with
// zero lanes, which every operation keeps zero), so the optimizer keeps the temporaries of
// an inlined expression in registers and emits one FMA-width instruction per block.
// Loops over blocks carry `#pragma GCC unroll`: unrolled early, g++ cannot turn a copy loop
// into a memcpy call, which it expands into 8/16-byte moves that stall store forwarding.
//
// Only what the models use is provided: + − * / (mixed with double), sqrt, sin, cos. Values
// go through the same operations as on double.
#include <cmath>

#include <Eigen/Core>

namespace mixpilot::models {

template <int n>
struct Dual {
  using Block = double __attribute__((vector_size(32)));
  static constexpr int size = n;               // derivative directions
  static constexpr int blocks = (n + 3) / 4;   // storage, padded to whole blocks

  double v;             // value
  Block d[blocks];      // ∂v/∂z_j in d[j / 4][j % 4], j < n; zero for j ≥ n

  // Uninitialized, like double (Eigen default-constructs its coefficients).
  Dual() = default;
  // Member-wise copies: the implicit ones copy v with its padding in 16/32-byte pieces, whose
  // loads straddle the 8-byte store of v and stall store forwarding.
  Dual(const Dual& a) : v(a.v) {
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) d[j] = a.d[j];
  }
  Dual& operator=(const Dual& a) {
    v = a.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) d[j] = a.d[j];
    return *this;
  }
  // A constant: zero derivatives.
  Dual(double value) : v(value) {  // NOLINT(google-explicit-constructor): mixes with double
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) d[j] = Block{};
  }
  // The independent variable z_i = value (seed direction i). The unit vector is built by
  // lane compares, in registers: writing one lane through memory and then reading the block
  // back stalls store forwarding.
  static Dual variable(double value, int i) {
    const Block lane = {0.0, 1.0, 2.0, 3.0}, one = {1.0, 1.0, 1.0, 1.0}, zero = {};
    Dual r;
    r.v = value;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = lane == double(i - 4 * j) ? one : zero;
    return r;
  }
  // As Eigen's AutoDiffScalar(value, n, i): z_i = value; n must equal the size.
  Dual(double value, [[maybe_unused]] int nder, int i) : Dual(variable(value, i)) {
    eigen_assert(nder == n);
  }

  double value() const { return v; }
  double derivative(int j) const { return d[j / 4][j % 4]; }
  // ∂v/∂z as a vector, as AutoDiffScalar::derivatives() (a copy).
  Eigen::Matrix<double, n, 1> derivatives() const {
    Eigen::Matrix<double, n, 1> r;
    for (int j = 0; j < n; ++j) r(j) = derivative(j);
    return r;
  }

  // d(a ± b) = da ± db
  friend Dual operator-(const Dual& a) {
    Dual r;
    r.v = -a.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = -a.d[j];
    return r;
  }
  friend Dual operator+(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v + b.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = a.d[j] + b.d[j];
    return r;
  }
  friend Dual operator-(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v - b.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = a.d[j] - b.d[j];
    return r;
  }
  friend Dual operator+(const Dual& a, double c) {
    Dual r = a;
    r.v = a.v + c;
    return r;
  }
  friend Dual operator+(double c, const Dual& a) {
    Dual r = a;
    r.v = c + a.v;
    return r;
  }
  friend Dual operator-(const Dual& a, double c) {
    Dual r = a;
    r.v = a.v - c;
    return r;
  }
  friend Dual operator-(double c, const Dual& a) {
    Dual r;
    r.v = c - a.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = -a.d[j];
    return r;
  }

  // d(ab) = a db + b da
  friend Dual operator*(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v * b.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = a.v * b.d[j] + b.v * a.d[j];
    return r;
  }
  friend Dual operator*(const Dual& a, double c) {
    Dual r;
    r.v = a.v * c;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = a.d[j] * c;
    return r;
  }
  friend Dual operator*(double c, const Dual& a) {
    Dual r;
    r.v = c * a.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = c * a.d[j];
    return r;
  }

  // d(a/b) = (da − (a/b) db)/b: one scalar division, then multiplies.
  friend Dual operator/(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v / b.v;
    const double inv = 1.0 / b.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = (a.d[j] - r.v * b.d[j]) * inv;
    return r;
  }
  friend Dual operator/(const Dual& a, double c) {
    Dual r;
    r.v = a.v / c;
    const double inv = 1.0 / c;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = a.d[j] * inv;
    return r;
  }
  // d(c/b) = −(c/b) db / b
  friend Dual operator/(double c, const Dual& b) {
    Dual r;
    r.v = c / b.v;
    const double k = -r.v / b.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = k * b.d[j];
    return r;
  }

  Dual& operator+=(const Dual& b) { return *this = *this + b; }
  Dual& operator-=(const Dual& b) { return *this = *this - b; }
  Dual& operator*=(const Dual& b) { return *this = *this * b; }
  Dual& operator/=(const Dual& b) { return *this = *this / b; }
  Dual& operator+=(double c) { return *this = *this + c; }
  Dual& operator-=(double c) { return *this = *this - c; }
  Dual& operator*=(double c) { return *this = *this * c; }
  Dual& operator/=(double c) { return *this = *this / c; }

  // d√a = da / (2√a)
  friend Dual sqrt(const Dual& a) {
    Dual r;
    r.v = std::sqrt(a.v);
    const double k = 0.5 / r.v;
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = k * a.d[j];
    return r;
  }
  // d sin a = cos a da;  d cos a = −sin a da  (g++ merges the pair into one sincos call)
  friend Dual sin(const Dual& a) {
    Dual r;
    r.v = std::sin(a.v);
    const double k = std::cos(a.v);
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = k * a.d[j];
    return r;
  }
  friend Dual cos(const Dual& a) {
    Dual r;
    r.v = std::cos(a.v);
    const double k = -std::sin(a.v);
#pragma GCC unroll 16
    for (int j = 0; j < blocks; ++j) r.d[j] = k * a.d[j];
    return r;
  }
};

// A dependent variable from its partial derivatives: r = value, dr = Σ_k c_k da_k. For a
// hand-written tangent of a function whose Jacobian is sparse (a model's dynamics_tangent):
// one pass over the derivatives per nonzero, none for the intermediate terms the AD of the
// same formula differentiates.
template <int n, int K>
Dual<n> chain(double value, const double (&c)[K], const Dual<n>* const (&a)[K]) {
  Dual<n> r;
  r.v = value;
#pragma GCC unroll 16
  for (int j = 0; j < Dual<n>::blocks; ++j) {
    typename Dual<n>::Block s = c[0] * a[0]->d[j];
#pragma GCC unroll 16
    for (int k = 1; k < K; ++k) s += c[k] * a[k]->d[j];
    r.d[j] = s;
  }
  return r;
}

}  // namespace mixpilot::models

// Eigen: Dual is a real scalar, and mixes with double in expressions (x + h * k).
namespace Eigen {

template <int n>
struct NumTraits<mixpilot::models::Dual<n>> : GenericNumTraits<double> {
  using Real = mixpilot::models::Dual<n>;
  using NonInteger = mixpilot::models::Dual<n>;
  using Nested = mixpilot::models::Dual<n>;
  using Literal = double;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = mixpilot::models::Dual<n>::blocks + 1,
    AddCost = mixpilot::models::Dual<n>::blocks + 1,
    MulCost = 2 * (mixpilot::models::Dual<n>::blocks) + 1,
  };
};

template <int n, class BinaryOp>
struct ScalarBinaryOpTraits<mixpilot::models::Dual<n>, double, BinaryOp> {
  using ReturnType = mixpilot::models::Dual<n>;
};
template <int n, class BinaryOp>
struct ScalarBinaryOpTraits<double, mixpilot::models::Dual<n>, BinaryOp> {
  using ReturnType = mixpilot::models::Dual<n>;
};

}  // namespace Eigen
