#pragma once
// Crazyflie 2.1, SPEC §3.2. ξ = (p, q, v_b, ω) ∈ R¹³ with q = (qw, qx, qy, qz),
// u = Ω propeller speeds [krpm] ∈ R⁴.
#include <cmath>

#include <Eigen/Core>

namespace mixpilot::models {

struct CrazyflieParams {
  double m = 0.033;        // [kg] (SPEC corrects the thesis's 0.33)
  double l = 0.0325;       // arm length [m]
  double Jxx = 1.395e-5;   // [kg·m²]
  double Jyy = 1.395e-5;   // [kg·m²]
  double Jzz = 2.173e-5;   // [kg·m²]
  double C_D = 7.9379e-6;  // drag torque coefficient [N·m/krpm²]
  double C_T = 3.25e-4;    // thrust coefficient [N/krpm²]
  double g = 9.81;         // [m/s²]
  double omega_min = 0.0;  // input bounds [krpm]
  double omega_max = 22.0;
};

struct Crazyflie {
  static constexpr int nx = 13;
  static constexpr int nu = 4;
  static constexpr const char* name = "crazyflie";
  using State = Eigen::Matrix<double, nx, 1>;
  using Input = Eigen::Matrix<double, nu, 1>;

  CrazyflieParams p{};

  // ṗ = R(q) v_b;  q̇ = ½ q ⊗ (0, ω);  v̇_b = (0,0,F_z/m) − R(q)ᵀ(0,0,g) − ω × v_b;
  // ω̇ = J⁻¹(M − ω × Jω)  (SPEC §3.2).
  template <class T>
  void dynamics(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Matrix<T, nu, 1>& u,
                Eigen::Matrix<T, nx, 1>& xdot) const {
    const T &qw = x(3), &qx = x(4), &qy = x(5), &qz = x(6);
    const T &vx = x(7), &vy = x(8), &vz = x(9);
    const T &wx = x(10), &wy = x(11), &wz = x(12);

    // Body-to-world rotation of the unit quaternion.
    const T r00 = 1.0 - 2.0 * (qy * qy + qz * qz), r01 = 2.0 * (qx * qy - qw * qz),
            r02 = 2.0 * (qx * qz + qw * qy);
    const T r10 = 2.0 * (qx * qy + qw * qz), r11 = 1.0 - 2.0 * (qx * qx + qz * qz),
            r12 = 2.0 * (qy * qz - qw * qx);
    const T r20 = 2.0 * (qx * qz - qw * qy), r21 = 2.0 * (qy * qz + qw * qx),
            r22 = 1.0 - 2.0 * (qx * qx + qy * qy);

    xdot(0) = r00 * vx + r01 * vy + r02 * vz;
    xdot(1) = r10 * vx + r11 * vy + r12 * vz;
    xdot(2) = r20 * vx + r21 * vy + r22 * vz;

    xdot(3) = -0.5 * (qx * wx + qy * wy + qz * wz);
    xdot(4) = 0.5 * (qw * wx + qy * wz - qz * wy);
    xdot(5) = 0.5 * (qw * wy + qz * wx - qx * wz);
    xdot(6) = 0.5 * (qw * wz + qx * wy - qy * wx);

    const T s1 = u(0) * u(0), s2 = u(1) * u(1), s3 = u(2) * u(2), s4 = u(3) * u(3);
    const T fz = p.C_T * (s1 + s2 + s3 + s4);
    const T mx = (p.C_T * p.l) * (-s1 - s2 + s3 + s4);
    const T my = (p.C_T * p.l) * (-s1 + s2 + s3 - s4);
    const T mz = p.C_D * (-s1 + s2 - s3 + s4);

    xdot(7) = -p.g * r20 - (wy * vz - wz * vy);
    xdot(8) = -p.g * r21 - (wz * vx - wx * vz);
    xdot(9) = fz / p.m - p.g * r22 - (wx * vy - wy * vx);

    const T jwx = p.Jxx * wx, jwy = p.Jyy * wy, jwz = p.Jzz * wz;
    xdot(10) = (mx - (wy * jwz - wz * jwy)) / p.Jxx;
    xdot(11) = (my - (wz * jwx - wx * jwz)) / p.Jyy;
    xdot(12) = (mz - (wx * jwy - wy * jwx)) / p.Jzz;
  }

  // A world-frame force F [N] on the centre of mass besides gravity and thrust (an instructor's
  // gust on the simulated plant, SPEC §10): v̇_b += R(q)ᵀ F / m added to xdot = f(x, u). Apart
  // from dynamics(), so the controller's model is untouched (models::WithExternalForce).
  template <class T>
  void add_external_force(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Vector3d& force,
                          Eigen::Matrix<T, nx, 1>& xdot) const {
    const T &qw = x(3), &qx = x(4), &qy = x(5), &qz = x(6);
    const T r00 = 1.0 - 2.0 * (qy * qy + qz * qz), r01 = 2.0 * (qx * qy - qw * qz),
            r02 = 2.0 * (qx * qz + qw * qy);
    const T r10 = 2.0 * (qx * qy + qw * qz), r11 = 1.0 - 2.0 * (qx * qx + qz * qz),
            r12 = 2.0 * (qy * qz - qw * qx);
    const T r20 = 2.0 * (qx * qz - qw * qy), r21 = 2.0 * (qy * qz + qw * qx),
            r22 = 1.0 - 2.0 * (qx * qx + qy * qy);
    const double fx = force.x() / p.m, fy = force.y() / p.m, fz = force.z() / p.m;
    xdot(7) += r00 * fx + r10 * fy + r20 * fz;
    xdot(8) += r01 * fx + r11 * fy + r21 * fz;
    xdot(9) += r02 * fx + r12 * fy + r22 * fz;
  }

  // Retraction onto the state manifold after each integrator step: q ← q/‖q‖. ERK4 alone keeps
  // ‖q‖ to ~1e-8 per 15 ms step under flight-like angular accelerations; the projection makes
  // it exact to rounding without lowering the order (SPEC §2: q is a unit quaternion).
  template <class T>
  void project(Eigen::Matrix<T, nx, 1>& x) const {
    using std::sqrt;
    const T inv_norm = 1.0 / sqrt(x(3) * x(3) + x(4) * x(4) + x(5) * x(5) + x(6) * x(6));
    for (int i = 3; i < 7; ++i) x(i) *= inv_norm;
  }

  // Ω = √(m g / 4 C_T) ≈ 15.78 krpm.
  double hover_speed() const { return std::sqrt(p.m * p.g / (4.0 * p.C_T)); }

  State hover_state(const Eigen::Vector3d& position) const {
    State x = Eigen::Matrix<double, nx, 1>::Zero();
    x.head<3>() = position;
    x(3) = 1.0;
    return x;
  }
  Input hover_input() const {
    return Eigen::Matrix<double, nu, 1>::Constant(hover_speed());
  }
};

}  // namespace mixpilot::models
