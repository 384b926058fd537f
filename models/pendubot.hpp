#pragma once
// Pendubot (Quanser), SPEC §3.1. x = (q1, q2, q̇1, q̇2), u = shoulder torque [N·m].
// q1 is measured from the upward vertical, q2 relative to link 1; up-up is x = 0.
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mixpilot::models {

struct PendubotParams {
  double m1 = 0.193;    // link 1 mass [kg]
  double l1 = 0.1483;   // link 1 length [m]
  double a1 = 0.1032;   // link 1 CoM distance [m]
  double J1 = 3.54e-4;  // link 1 inertia about its CoM [kg·m²]
  double m2 = 0.073;    // link 2 mass [kg]
  double l2 = 0.1804;   // link 2 length [m] (geometry only)
  double a2 = 0.1065;   // link 2 CoM distance [m]
  double J2 = 2e-4;     // link 2 inertia about its CoM [kg·m²]
  double Jm = 4.74e-4;  // motor inertia reflected to the shoulder [kg·m²]
  double g = 9.81;      // [m/s²]
  double u_max = 0.4;   // input bound |u| ≤ u_max [N·m] (SPEC §5.1)
};

struct Pendubot {
  static constexpr int nx = 4;
  static constexpr int nu = 1;
  static constexpr const char* name = "pendubot";
  using State = Eigen::Matrix<double, nx, 1>;
  using Input = Eigen::Matrix<double, nu, 1>;

  PendubotParams p{};

  // ẋ = f(x, u): M(q) q̈ + C(q, q̇) + G(q) = (u, 0).
  template <class T>
  void dynamics(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Matrix<T, nu, 1>& u,
                Eigen::Matrix<T, nx, 1>& xdot) const {
    using std::cos;
    using std::sin;
    const T& q1 = x(0);
    const T& q2 = x(1);
    const T& dq1 = x(2);
    const T& dq2 = x(3);
    const T cos1 = cos(q1), sin1 = sin(q1);
    const T c2 = cos(q2), s2 = sin(q2);
    const double k = p.m2 * p.l1 * p.a2;

    const T m11 = p.m1 * p.a1 * p.a1 + p.m2 * (p.l1 * p.l1 + p.a2 * p.a2) + 2.0 * k * c2 + p.J1 +
                  p.J2 + p.Jm;
    const T m12 = p.m2 * p.a2 * p.a2 + k * c2 + p.J2;
    const double m22 = p.m2 * p.a2 * p.a2 + p.J2;

    // cos(a + π/2) = −sin(a). sin(q1 + q2) is expanded to sin q1 cos q2 + cos q1 sin q2: two
    // sincos calls instead of three, which dominate an ERK4 step with sensitivities.
    const T g2 = -(p.m2 * p.a2 * p.g) * (sin1 * c2 + cos1 * s2);
    const T g1 = -((p.m1 * p.a1 + p.m2 * p.l1) * p.g) * sin1 + g2;
    const T c1 = -k * s2 * (dq2 * dq2 + 2.0 * dq1 * dq2);
    const T cc2 = k * s2 * dq1 * dq1;

    // Solve the 2x2 system M q̈ = τ − C − G by Cramer's rule (M is symmetric positive definite).
    const T r1 = u(0) - c1 - g1;
    const T r2 = -cc2 - g2;
    const T det = m11 * m22 - m12 * m12;
    xdot(0) = dq1;
    xdot(1) = dq2;
    xdot(2) = (m22 * r1 - m12 * r2) / det;
    xdot(3) = (m11 * r2 - m12 * r1) / det;
  }

  // Total mechanical energy T + V with V = 0 at the down-down rest, so E ≥ 0.
  double energy(const State& x) const {
    const double c2 = std::cos(x(1));
    const double k = p.m2 * p.l1 * p.a2;
    const double m11 = p.m1 * p.a1 * p.a1 + p.m2 * (p.l1 * p.l1 + p.a2 * p.a2) + 2.0 * k * c2 +
                       p.J1 + p.J2 + p.Jm;
    const double m12 = p.m2 * p.a2 * p.a2 + k * c2 + p.J2;
    const double m22 = p.m2 * p.a2 * p.a2 + p.J2;
    const double kinetic =
        0.5 * (m11 * x(2) * x(2) + 2.0 * m12 * x(2) * x(3) + m22 * x(3) * x(3));
    // V = (m1 a1 + m2 l1) g cos q1 + m2 a2 g cos(q1 + q2), whose gradient is G(q).
    const double v = (p.m1 * p.a1 + p.m2 * p.l1) * p.g * std::cos(x(0)) +
                     p.m2 * p.a2 * p.g * std::cos(x(0) + x(1));
    const double v_min = -(p.m1 * p.a1 + p.m2 * p.l1) * p.g - p.m2 * p.a2 * p.g;
    return kinetic + v - v_min;
  }

  static State up_up() { return Eigen::Matrix<double, nx, 1>::Zero(); }
  static State down_down() {
    return Eigen::Matrix<double, nx, 1>(-std::numbers::pi, 0.0, 0.0, 0.0);
  }
};

}  // namespace mixpilot::models
