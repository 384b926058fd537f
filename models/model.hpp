#pragma once
// What every dynamic model provides, and its continuous-time Jacobians by forward-mode AD.
//
// Jacobians come from forward-mode automatic differentiation (models/dual.hpp, a dual number
// with a fixed-size derivative array) rather than hand-written formulas: they are exact to
// rounding, cannot drift from the model when it changes, and the fixed size lets the compiler
// unroll and vectorize the derivative arithmetic (each elementary operation costs one short
// vector update). See core/numerics/integrator_erk4.hpp for the same technique applied to a
// whole ERK4 step, which is what the NMPC uses.
//
// A model may also give dynamics_tangent(): the same f on dual numbers with ∂f/∂z written out
// from its Jacobian's nonzeros (models::chain), which skips the derivative arithmetic of every
// intermediate term (a rotation matrix's nine entries, say). The NMPC's sensitivities then use
// it; tests/test_models.cpp holds it to the AD of dynamics() at random points and directions.
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

// f(x, u) on dual numbers: the model's hand-written tangent where it has one, else the AD of
// dynamics().
template <class M, int n>
void dynamics_dual(const M& model, const Eigen::Matrix<Dual<n>, M::nx, 1>& x,
                   const Eigen::Matrix<Dual<n>, M::nu, 1>& u,
                   Eigen::Matrix<Dual<n>, M::nx, 1>& xdot) {
  if constexpr (requires { model.dynamics_tangent(x, u, xdot); })
    model.dynamics_tangent(x, u, xdot);
  else
    model.dynamics(x, u, xdot);
}

// For a dynamics_tangent: the values of its dual arguments, and f at them by dynamics<double>
// (the tangent's values; its derivatives come from the Jacobian's nonzeros).
template <class M>
struct TangentValues {
  typename M::State x;  // nx
  typename M::Input u;  // nu
  typename M::State f;  // nx: f(x, u)
};
template <class M, int n>
TangentValues<M> values_and_dynamics(const M& model, const Eigen::Matrix<Dual<n>, M::nx, 1>& x,
                                     const Eigen::Matrix<Dual<n>, M::nu, 1>& u) {
  TangentValues<M> v;
  for (int i = 0; i < M::nx; ++i) v.x(i) = x(i).v;
  for (int i = 0; i < M::nu; ++i) v.u(i) = u(i).v;
  model.dynamics(v.x, v.u, v.f);
  return v;
}

// Forward-mode AD scalar carrying derivatives with respect to n directions. Constructed and
// read like Eigen's AutoDiffScalar: Ad(value, n, i), .value(), .derivatives().
template <int n>
using AutoDiff = Dual<n>;

// A model with a world-frame force on its centre of mass (an instructor's gust on a simulated
// plant, SPEC §10): f(x, u) + the model's add_external_force(x, force). The plain model's
// dynamics() are left as they are, so the controller's model, which does not know the force,
// computes exactly what it did.
template <class M>
struct WithExternalForce {
  static constexpr int nx = M::nx;
  static constexpr int nu = M::nu;
  static constexpr const char* name = M::name;
  using State = Eigen::Matrix<double, nx, 1>;
  using Input = Eigen::Matrix<double, nu, 1>;

  M model{};
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // [N] world frame

  template <class T>
  void dynamics(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Matrix<T, nu, 1>& u,
                Eigen::Matrix<T, nx, 1>& xdot) const {
    model.dynamics(x, u, xdot);
    model.add_external_force(x, force, xdot);
  }
  template <class T>
  void project(Eigen::Matrix<T, nx, 1>& x) const {
    models::project(model, x);
  }
};

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
  dynamics_dual(model, xa, ua, fa);
  for (int i = 0; i < nx; ++i) {
    f(i) = fa(i).value();
    for (int j = 0; j < nx; ++j) fx(i, j) = fa(i).derivative(j);
    for (int j = 0; j < nu; ++j) fu(i, j) = fa(i).derivative(nx + j);
  }
}

}  // namespace mixpilot::models
