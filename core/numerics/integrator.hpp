#pragma once
// The integrator role: one step x⁺ = F(x, u, Δt) of a model with piecewise-constant input,
// optionally with the forward sensitivities A = ∂F/∂x and B = ∂F/∂u (SPEC §4).
// Variants live in integrator_<name>.hpp. Steps write into caller-owned storage and never
// allocate, so they can run inside the control loop.
#include <Eigen/Core>

namespace mixpilot {

enum class IntegratorStatus {
  success,
  non_finite,  // the result (state or sensitivities) contains NaN or Inf
};

class Integrator {
 public:
  virtual ~Integrator() = default;

  virtual int nx() const = 0;
  virtual int nu() const = 0;

  // x_next (nx) = F(x (nx), u (nu), dt).
  virtual IntegratorStatus step(const Eigen::Ref<const Eigen::VectorXd>& x,
                                const Eigen::Ref<const Eigen::VectorXd>& u, double dt,
                                Eigen::Ref<Eigen::VectorXd> x_next) const = 0;

  // As step(), plus A (nx x nx) = ∂F/∂x and B (nx x nu) = ∂F/∂u.
  virtual IntegratorStatus step_sensitivities(const Eigen::Ref<const Eigen::VectorXd>& x,
                                              const Eigen::Ref<const Eigen::VectorXd>& u,
                                              double dt, Eigen::Ref<Eigen::VectorXd> x_next,
                                              Eigen::Ref<Eigen::MatrixXd> A,
                                              Eigen::Ref<Eigen::MatrixXd> B) const = 0;
};

}  // namespace mixpilot
