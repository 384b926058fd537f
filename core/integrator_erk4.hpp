#pragma once
// Classical explicit Runge-Kutta 4 (ERK4), SPEC §2/§4:
//   k1 = f(x, u), k2 = f(x + Δt/2 k1, u), k3 = f(x + Δt/2 k2, u), k4 = f(x + Δt k3, u),
//   x⁺ = x + Δt/6 (k1 + 2 k2 + 2 k3 + k4), then the model's projection (models/model.hpp).
// Sensitivities: the step is evaluated once in forward-mode AD with nx + nu seeded directions
// (z = (x, u)), so A and B are the exact derivatives of the discrete map, identical to forward
// propagation of the variational equations through the same Butcher tableau ("internal
// numerical differentiation"), without forming dense nx x nx products per stage.
// All temporaries are fixed-size and live on the stack: no heap allocation.
#include "core/integrator.hpp"
#include "models/model.hpp"

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
            double dt, Eigen::Matrix<Scalar, kNx, 1>& x_next) const {
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

  void step(const State& x, const Input& u, double dt, State& x_next, MatA& A, MatB& B) const {
    constexpr int nz = kNx + kNu;
    using Ad = models::AutoDiff<nz>;
    Eigen::Matrix<Ad, kNx, 1> xa, xn;
    Eigen::Matrix<Ad, kNu, 1> ua;
    for (int i = 0; i < kNx; ++i) xa(i) = Ad(x(i), nz, i);
    for (int i = 0; i < kNu; ++i) ua(i) = Ad(u(i), nz, kNx + i);
    step(xa, ua, dt, xn);
    for (int i = 0; i < kNx; ++i) {
      x_next(i) = xn(i).value();
      A.row(i) = xn(i).derivatives().template head<kNx>().transpose();
      B.row(i) = xn(i).derivatives().template tail<kNu>().transpose();
    }
  }

  // Integrator interface.
  int nx() const override { return kNx; }
  int nu() const override { return kNu; }

  IntegratorStatus step(const Eigen::Ref<const Eigen::VectorXd>& x,
                        const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                        Eigen::Ref<Eigen::VectorXd> x_next) const override {
    State xn;
    step<double>(State(x), Input(u), dt, xn);
    x_next = xn;
    return xn.allFinite() ? IntegratorStatus::success : IntegratorStatus::non_finite;
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
    const bool finite = xn.allFinite() && a.allFinite() && b.allFinite();
    return finite ? IntegratorStatus::success : IntegratorStatus::non_finite;
  }

 private:
  Model model_;
};

}  // namespace mixpilot
