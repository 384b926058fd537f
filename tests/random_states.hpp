#pragma once
// Random states and inputs inside each model's realistic operating range, for derivative and
// integrator tests.
#include <numbers>
#include <random>

#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"

namespace mixpilot::testing_states {

inline double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline models::Pendubot::State random_state(const models::Pendubot&, std::mt19937& rng) {
  const double pi = std::numbers::pi;
  return {uniform(rng, -pi, pi), uniform(rng, -pi, pi), uniform(rng, -6, 6), uniform(rng, -6, 6)};
}
inline models::Pendubot::Input random_input(const models::Pendubot& m, std::mt19937& rng) {
  return models::Pendubot::Input(uniform(rng, -m.p.u_max, m.p.u_max));
}

// Unit quaternion uniformly on S³; body rates up to 3 rad/s per axis.
inline models::Crazyflie::State random_state(const models::Crazyflie&, std::mt19937& rng) {
  models::Crazyflie::State x;
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector4d q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  for (int i = 0; i < 3; ++i) x(i) = uniform(rng, -1, 1);
  x.segment<4>(3) = q;
  for (int i = 7; i < 10; ++i) x(i) = uniform(rng, -1, 1);
  for (int i = 10; i < 13; ++i) x(i) = uniform(rng, -3, 3);
  return x;
}
inline models::Crazyflie::Input random_input(const models::Crazyflie& m, std::mt19937& rng) {
  models::Crazyflie::Input u;
  for (int i = 0; i < 4; ++i) u(i) = uniform(rng, 0.5 * m.p.omega_max, m.p.omega_max);
  return u;
}

// Tilt within ±0.5 rad (away from the ZYX singularity at θ = ±π/2), any yaw.
inline models::MikroKopter::State random_state(const models::MikroKopter& m, std::mt19937& rng) {
  models::MikroKopter::State x;
  for (int i = 0; i < 3; ++i) x(i) = uniform(rng, -1, 1);
  x(3) = uniform(rng, -0.5, 0.5);
  x(4) = uniform(rng, -0.5, 0.5);
  x(5) = uniform(rng, -std::numbers::pi, std::numbers::pi);
  for (int i = 6; i < 9; ++i) x(i) = uniform(rng, -1, 1);
  for (int i = 9; i < 12; ++i) x(i) = uniform(rng, -2, 2);
  for (int i = 12; i < 16; ++i) x(i) = uniform(rng, 0.3 * m.p.omega_max, m.p.omega_max);
  return x;
}
inline models::MikroKopter::Input random_input(const models::MikroKopter& m, std::mt19937& rng) {
  models::MikroKopter::Input u;
  for (int i = 0; i < 4; ++i) u(i) = uniform(rng, m.p.tau_min, m.p.tau_max);
  return u;
}

// Inputs within ±spread of hover, per rotor: flight-like angular accelerations (for the Crazyflie,
// ±1 krpm of differential speed gives |ω̇| up to ≈ 500 rad/s²), where the full input box can
// spin the vehicle up by thousands of rad/s².
template <class M>
typename M::Input near_hover_input(const M& m, std::mt19937& rng, double spread) {
  typename M::Input u = m.hover_input();
  for (int i = 0; i < M::nu; ++i) u(i) += uniform(rng, -spread, spread);
  return u;
}

}  // namespace mixpilot::testing_states
