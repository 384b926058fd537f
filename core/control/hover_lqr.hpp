#pragma once
// Hover-hold LQR of the MikroKopter (SPEC §3.3): the mixed-initiative mode's safe controller
// when the MPC cannot keep its period (core/modes/safety_net.hpp). Discrete LQR on the ERK4 map
// at hover over Δt, u = u_hover − K (x − x_hold) with x_hold the hover state at the position to
// hold (yaw 0, as the MPC's Q_e regulates it), clipped to the torque bounds. The weights are the
// MI cost's at λ = 0 (Q_η, Q_e, R: the planner's own), plus small ones on φ, θ and Ω so that
// every state is penalized.
#include <Eigen/Core>

#include "core/control/mi_settings.hpp"
#include "core/numerics/setup_result.hpp"
#include "models/mikrokopter.hpp"

namespace mixpilot {

class HoverLqr {
 public:
  using Model = models::MikroKopter;
  using State = Model::State;
  using Input = Model::Input;
  static constexpr int nx = Model::nx;  // 16
  static constexpr int nu = Model::nu;  // 4

  // Fails when the Riccati equation does not converge.
  SetupResult setup(const Model& model, const MiWeights& weights, double dt);
  // The input that holds `position`, from the state x. Allocates nothing.
  void control(const State& x, const Eigen::Vector3d& position, Input& u) const;

  const Eigen::Matrix<double, nu, nx>& K() const { return K_; }
  // Spectral radius of A − B K (< 1: the closed loop of the linearization is stable).
  double spectral_radius() const { return spectral_radius_; }

 private:
  Eigen::Matrix<double, nu, nx> K_ = Eigen::Matrix<double, nu, nx>::Zero();  // nu x nx
  State x_hover_ = State::Zero();  // nx: hover at the origin
  Input u_hover_ = Input::Zero();  // nu
  double u_min_ = 0.0, u_max_ = 0.0;
  double spectral_radius_ = 0.0;
};

}  // namespace mixpilot
