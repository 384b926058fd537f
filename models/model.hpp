#pragma once
// What every dynamic model provides, and its continuous-time Jacobians by forward-mode AD.
//
// Jacobians come from forward-mode automatic differentiation (models/dual.hpp, a dual number
// with a fixed-size derivative array) rather than hand-written formulas: they are exact to
// rounding, cannot drift from the model when it changes, and the fixed size lets the compiler
// unroll and vectorize the derivative arithmetic, which exploits the sparsity of f for free
// (each elementary operation costs one short vector update). See core/numerics/integrator_erk4.hpp for
// the same technique applied to a whole ERK4 step, which is what the NMPC uses.
#include <concepts>

#include <Eigen/Core>

#include "models/dual.hpp"

namespace mixpilot::models {

template <class M>
concept DynamicModel = requires(const M& m, const Eigen::Matrix<double, M::nx, 1>& x,
                                const Eigen::Matrix<double, M::nu, 1>& u,
                                Eigen::Matrix<double, M::nx, 1>& xdot) {
  { M::nx } -> std::convertible_to<int>;
  { M::nu } -> std::convertible_to<int>;
  { M::name } -> std::convertible_to<const char*>;
  m.dynamics(x, u, xdot);
};

// Models whose state lives on a manifold (unit quaternions) provide project(x), applied after
// every integrator step; the others need nothing.
template <class M, class T>
void project(const M& model, Eigen::Matrix<T, M::nx, 1>& x) {
  if constexpr (requires { model.project(x); }) model.project(x);
}

// Forward-mode AD scalar carrying derivatives with respect to n directions. Constructed and
// read like Eigen's AutoDiffScalar: Ad(value, n, i), .value(), .derivatives().
template <int n>
using AutoDiff = Dual<n>;

// f(x, u) with ∂f/∂x (nx x nx) and ∂f/∂u (nx x nu).
template <DynamicModel M>
void dynamics_jacobians(const M& model, const Eigen::Matrix<double, M::nx, 1>& x,
                        const Eigen::Matrix<double, M::nu, 1>& u,
                        Eigen::Matrix<double, M::nx, 1>& f,
                        Eigen::Matrix<double, M::nx, M::nx>& fx,
                        Eigen::Matrix<double, M::nx, M::nu>& fu) {
  constexpr int nx = M::nx, nu = M::nu, nz = nx + nu;
  using Ad = AutoDiff<nz>;
  Eigen::Matrix<Ad, nx, 1> xa;
  Eigen::Matrix<Ad, nu, 1> ua;
  for (int i = 0; i < nx; ++i) xa(i) = Ad(x(i), nz, i);
  for (int i = 0; i < nu; ++i) ua(i) = Ad(u(i), nz, nx + i);
  Eigen::Matrix<Ad, nx, 1> fa;
  model.dynamics(xa, ua, fa);
  for (int i = 0; i < nx; ++i) {
    f(i) = fa(i).value();
    for (int j = 0; j < nx; ++j) fx(i, j) = fa(i).derivative(j);
    for (int j = 0; j < nu; ++j) fu(i, j) = fa(i).derivative(nx + j);
  }
}

}  // namespace mixpilot::models
