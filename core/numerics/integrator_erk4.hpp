#pragma once
// Classical explicit Runge-Kutta 4 (ERK4), SPEC §2/§4:
//   k1 = f(x, u), k2 = f(x + Δt/2 k1, u), k3 = f(x + Δt/2 k2, u), k4 = f(x + Δt k3, u),
//   x⁺ = x + Δt/6 (k1 + 2 k2 + 2 k3 + k4), then the model's projection (models/model.hpp).
// Sensitivities: the step is evaluated once in forward-mode AD (models/dual.hpp) with nx + nu
// seeded directions (z = (x, u)), f by the model's hand-written tangent where it has one
// (models::dynamics_dual), so A and B are the exact derivatives of the discrete map, identical
// to forward propagation of the variational equations through the same Butcher tableau
// ("internal numerical differentiation"), without forming dense nx x nx products per stage.
// All temporaries are fixed-size and live on the stack: no heap allocation.
#include "core/numerics/integrator.hpp"
#include "core/numerics/matrix_checks.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/model.hpp"
#include "models/pendubot.hpp"

namespace mixpilot {

template <models::DynamicModel Model>
class IntegratorErk4 final : public Integrator {
 public:
  static constexpr int kNx = Model::nx;
  static constexpr int kNu = Model::nu;
  using State = Eigen::Matrix<double, kNx, 1>;
  using Input = Eigen::Matrix<double, kNu, 1>;
  using MatA = Eigen::Matrix<double, kNx, kNx>;
  using MatB = Eigen::Matrix<double, kNx, kNu>;

  explicit IntegratorErk4(const Model& model = Model{}) : model_(model) {}

  const Model& model() const { return model_; }

  // Fixed-size entry points (no virtual dispatch, no copies).
  template <class Scalar>
  void step(const Eigen::Matrix<Scalar, kNx, 1>& x, const Eigen::Matrix<Scalar, kNu, 1>& u,
            double dt, Eigen::Matrix<Scalar, kNx, 1>& x_next) const;
  // ... with A = ∂x⁺/∂x and B = ∂x⁺/∂u.
  void step(const State& x, const Input& u, double dt, State& x_next, MatA& A, MatB& B) const;

  // Integrator interface.
  int nx() const override { return kNx; }
  int nu() const override { return kNu; }

  IntegratorStatus step(const Eigen::Ref<const Eigen::VectorXd>& x,
                        const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                        Eigen::Ref<Eigen::VectorXd> x_next) const override {
    State xn;
    step<double>(State(x), Input(u), dt, xn);
    x_next = xn;
    return all_finite(xn) ? IntegratorStatus::success : IntegratorStatus::non_finite;
  }

  IntegratorStatus step_sensitivities(const Eigen::Ref<const Eigen::VectorXd>& x,
                                      const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                                      Eigen::Ref<Eigen::VectorXd> x_next,
                                      Eigen::Ref<Eigen::MatrixXd> A,
                                      Eigen::Ref<Eigen::MatrixXd> B) const override {
    State xn;
    MatA a;
    MatB b;
    step(State(x), Input(u), dt, xn, a, b);
    x_next = xn;
    A = a;
    B = b;
    const bool finite = all_finite(xn) && all_finite(a) && all_finite(b);
    return finite ? IntegratorStatus::success : IntegratorStatus::non_finite;
  }

 private:
  static constexpr int kNz = kNx + kNu;
  using Ad = models::AutoDiff<kNz>;
  using AdState = Eigen::Matrix<Ad, kNx, 1>;
  using AdInput = Eigen::Matrix<Ad, kNu, 1>;

  // One pass over k per stage: acc (+)= w k, then the next stage's point xs = x + c k (x is
  // the seeded state, so ∂xs/∂z = [I 0] + c ∂k/∂z).
  template <bool first>
  static void stage(const AdState& x, double c, double w, const AdState& k, AdState& acc,
                    AdState& xs) {
    for (int i = 0; i < kNx; ++i) {
      acc(i).v = first ? k(i).v : acc(i).v + w * k(i).v;
      xs(i).v = x(i).v + c * k(i).v;
#pragma GCC unroll 16
      for (int j = 0; j < Ad::blocks; ++j) {
        acc(i).d[j] = first ? k(i).d[j] : acc(i).d[j] + w * k(i).d[j];
        xs(i).d[j] = x(i).d[j] + c * k(i).d[j];
      }
    }
  }
  // x⁺ = x + Δt/6 (acc + k4), into xs.
  static void finish(const AdState& x, double c, const AdState& k, const AdState& acc,
                     AdState& xs) {
    for (int i = 0; i < kNx; ++i) {
      xs(i).v = x(i).v + c * (acc(i).v + k(i).v);
#pragma GCC unroll 16
      for (int j = 0; j < Ad::blocks; ++j) {
        xs(i).d[j] = x(i).d[j] + c * (acc(i).d[j] + k(i).d[j]);
      }
    }
  }

  Model model_;
};

template <models::DynamicModel Model>
template <class Scalar>
void IntegratorErk4<Model>::step(const Eigen::Matrix<Scalar, kNx, 1>& x,
                                 const Eigen::Matrix<Scalar, kNu, 1>& u, double dt,
                                 Eigen::Matrix<Scalar, kNx, 1>& x_next) const {
  Eigen::Matrix<Scalar, kNx, 1> k, acc, xs;
  model_.dynamics(x, u, k);  // k1
  acc = k;
  xs = x + (0.5 * dt) * k;
  model_.dynamics(xs, u, k);  // k2
  acc += 2.0 * k;
  xs = x + (0.5 * dt) * k;
  model_.dynamics(xs, u, k);  // k3
  acc += 2.0 * k;
  xs = x + dt * k;
  model_.dynamics(xs, u, k);  // k4
  acc += k;
  x_next = x + (dt / 6.0) * acc;
  models::project(model_, x_next);
}

template <models::DynamicModel Model>
void IntegratorErk4<Model>::step(const State& x, const Input& u, double dt, State& x_next,
                                 MatA& A, MatB& B) const {
  // The same arithmetic as step<double>, on dual numbers seeded with z = (x, u). Stage
  // updates are written out per derivative block instead of through Eigen expressions: a
  // Dual is a struct of up to ~200 bytes, and the temporaries Eigen copies around cost more
  // than the derivative arithmetic itself.
  AdState xz, xs, k, acc;
  AdInput ua;
  for (int i = 0; i < kNx; ++i) xz(i) = Ad::variable(x(i), i);
  for (int i = 0; i < kNu; ++i) ua(i) = Ad::variable(u(i), kNx + i);
  models::dynamics_dual(model_, xz, ua, k);  // k1
  stage<true>(xz, 0.5 * dt, 1.0, k, acc, xs);
  models::dynamics_dual(model_, xs, ua, k);  // k2
  stage<false>(xz, 0.5 * dt, 2.0, k, acc, xs);
  models::dynamics_dual(model_, xs, ua, k);  // k3
  stage<false>(xz, dt, 2.0, k, acc, xs);
  models::dynamics_dual(model_, xs, ua, k);  // k4
  finish(xz, dt / 6.0, k, acc, xs);
  models::project(model_, xs);
  for (int i = 0; i < kNx; ++i) {
    x_next(i) = xs(i).v;
    for (int j = 0; j < kNx; ++j) A(i, j) = xs(i).derivative(j);
    for (int j = 0; j < kNu; ++j) B(i, j) = xs(i).derivative(kNx + j);
  }
}

// The shipped models' steps are compiled once, in core/numerics/integrator_erk4.cpp, and every
// binary calls that copy: copies compiled in different translation units can differ in their
// instructions (inlining, fused multiply-adds) and so in rounding, and a replay (score, the
// window, a test's own) must repeat the flight of any other binary bit for bit.
#define MIXPILOT_ERK4_STEPS(prefix, M)                                                        \
  prefix template void IntegratorErk4<M>::step<double>(                                     \
      const Eigen::Matrix<double, M::nx, 1>&, const Eigen::Matrix<double, M::nu, 1>&, double, \
      Eigen::Matrix<double, M::nx, 1>&) const;                                              \
  prefix template void IntegratorErk4<M>::step(const IntegratorErk4<M>::State&,             \
                                               const IntegratorErk4<M>::Input&, double,     \
                                               IntegratorErk4<M>::State&,                   \
                                               IntegratorErk4<M>::MatA&,                    \
                                               IntegratorErk4<M>::MatB&) const;
MIXPILOT_ERK4_STEPS(extern, models::MikroKopter)
MIXPILOT_ERK4_STEPS(extern, models::Crazyflie)
MIXPILOT_ERK4_STEPS(extern, models::Pendubot)
MIXPILOT_ERK4_STEPS(extern, models::WithExternalForce<models::MikroKopter>)
MIXPILOT_ERK4_STEPS(extern, models::WithExternalForce<models::Crazyflie>)

}  // namespace mixpilot
