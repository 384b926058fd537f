#pragma once
// Crazyflie 2.1, SPEC §3.2. ξ = (p, q, v_b, ω) ∈ R¹³ with q = (qw, qx, qy, qz),
// u = Ω propeller speeds [krpm] ∈ R⁴.
#include <array>
#include <cmath>

#include <Eigen/Core>

#include "models/dual.hpp"
#include "models/model.hpp"

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

  // Body-to-world rotation R(q) of the unit quaternion q = (qw, qx, qy, qz), row by row.
  template <class T>
  static std::array<T, 9> rotation(const T& qw, const T& qx, const T& qy, const T& qz) {
    return {1.0 - 2.0 * (qy * qy + qz * qz), 2.0 * (qx * qy - qw * qz), 2.0 * (qx * qz + qw * qy),
            2.0 * (qx * qy + qw * qz), 1.0 - 2.0 * (qx * qx + qz * qz), 2.0 * (qy * qz - qw * qx),
            2.0 * (qx * qz - qw * qy), 2.0 * (qy * qz + qw * qx), 1.0 - 2.0 * (qx * qx + qy * qy)};
  }

  // ṗ = R(q) v_b;  q̇ = ½ q ⊗ (0, ω);  v̇_b = (0,0,F_z/m) − R(q)ᵀ(0,0,g) − ω × v_b;
  // ω̇ = J⁻¹(M − ω × Jω)  (SPEC §3.2).
  template <class T>
  void dynamics(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Matrix<T, nu, 1>& u,
                Eigen::Matrix<T, nx, 1>& xdot) const {
    const T &qw = x(3), &qx = x(4), &qy = x(5), &qz = x(6);
    const T &vx = x(7), &vy = x(8), &vz = x(9);
    const T &wx = x(10), &wy = x(11), &wz = x(12);

    const auto [r00, r01, r02, r10, r11, r12, r20, r21, r22] = rotation(qw, qx, qy, qz);

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

  // The same f on dual numbers, ∂f/∂z from the Jacobian's nonzeros (models/model.hpp); the
  // values are dynamics<double>'s. With v = v_b:
  //   ∂ṗ/∂v = R,  ∂ṗ/∂q_k = (∂R/∂q_k) v, where ∂R/∂qw = 2[0 −qz qy; qz 0 −qx; −qy qx 0],
  //   ∂R/∂qx = 2[0 qy qz; qy −2qx −qw; qz qw −2qx], ∂R/∂qy = 2[−2qy qx qw; qx 0 qz; −qw qz −2qy],
  //   ∂R/∂qz = 2[−2qz −qw qx; qw −2qz qy; qx qy 0];
  //   q̇ is bilinear in (q, ω); v̇ is gravity's third row of R (its q-partials as above) and
  //   −ω × v, bilinear; ω̇ = J⁻¹(M − ω × Jω) and F_z, M are linear in Ω_i², ∂Ω_i² = 2Ω_i.
  template <int n>
  void dynamics_tangent(const Eigen::Matrix<Dual<n>, nx, 1>& x,
                        const Eigen::Matrix<Dual<n>, nu, 1>& u,
                        Eigen::Matrix<Dual<n>, nx, 1>& xdot) const {
    const auto [xv, uv, f] = values_and_dynamics(*this, x, u);
    const double qw = xv(3), qx = xv(4), qy = xv(5), qz = xv(6);
    const double vx = xv(7), vy = xv(8), vz = xv(9), wx = xv(10), wy = xv(11), wz = xv(12);
    const auto [r00, r01, r02, r10, r11, r12, r20, r21, r22] = rotation(qw, qx, qy, qz);
    using P = const Dual<n>*;  // the tangents of the state's and input's components
    const P dqw = &x(3), dqx = &x(4), dqy = &x(5), dqz = &x(6);
    const P dvx = &x(7), dvy = &x(8), dvz = &x(9), dwx = &x(10), dwy = &x(11), dwz = &x(12);
    const P du1 = &u(0), du2 = &u(1), du3 = &u(2), du4 = &u(3);

    xdot(0) = chain(f(0), {r00, r01, r02, 2.0 * (qy * vz - qz * vy), 2.0 * (qy * vy + qz * vz),
                           2.0 * (-2.0 * qy * vx + qx * vy + qw * vz),
                           2.0 * (-2.0 * qz * vx - qw * vy + qx * vz)},
                    {dvx, dvy, dvz, dqw, dqx, dqy, dqz});
    xdot(1) = chain(f(1), {r10, r11, r12, 2.0 * (qz * vx - qx * vz),
                           2.0 * (qy * vx - 2.0 * qx * vy - qw * vz), 2.0 * (qx * vx + qz * vz),
                           2.0 * (qw * vx - 2.0 * qz * vy + qy * vz)},
                    {dvx, dvy, dvz, dqw, dqx, dqy, dqz});
    xdot(2) = chain(f(2), {r20, r21, r22, 2.0 * (qx * vy - qy * vx),
                           2.0 * (qz * vx + qw * vy - 2.0 * qx * vz),
                           2.0 * (-qw * vx + qz * vy - 2.0 * qy * vz), 2.0 * (qx * vx + qy * vy)},
                    {dvx, dvy, dvz, dqw, dqx, dqy, dqz});

    xdot(3) = chain(f(3), {-0.5 * wx, -0.5 * wy, -0.5 * wz, -0.5 * qx, -0.5 * qy, -0.5 * qz},
                    {dqx, dqy, dqz, dwx, dwy, dwz});
    xdot(4) = chain(f(4), {0.5 * wx, 0.5 * wz, -0.5 * wy, 0.5 * qw, -0.5 * qz, 0.5 * qy},
                    {dqw, dqy, dqz, dwx, dwy, dwz});
    xdot(5) = chain(f(5), {0.5 * wy, -0.5 * wz, 0.5 * wx, 0.5 * qz, 0.5 * qw, -0.5 * qx},
                    {dqw, dqx, dqz, dwx, dwy, dwz});
    xdot(6) = chain(f(6), {0.5 * wz, 0.5 * wy, -0.5 * wx, -0.5 * qy, 0.5 * qx, 0.5 * qw},
                    {dqw, dqx, dqy, dwx, dwy, dwz});

    const double g2 = 2.0 * p.g;
    xdot(7) = chain(f(7), {g2 * qy, -g2 * qz, g2 * qw, -g2 * qx, wz, -wy, -vz, vy},
                    {dqw, dqx, dqy, dqz, dvy, dvz, dwy, dwz});
    xdot(8) = chain(f(8), {-g2 * qx, -g2 * qw, -g2 * qz, -g2 * qy, -wz, wx, vz, -vx},
                    {dqw, dqx, dqy, dqz, dvx, dvz, dwx, dwz});
    const double o1 = uv(0), o2 = uv(1), o3 = uv(2), o4 = uv(3);
    const double kt = 2.0 * p.C_T / p.m;
    xdot(9) = chain(f(9), {2.0 * g2 * qx, 2.0 * g2 * qy, wy, -wx, -vy, vx, kt * o1, kt * o2,
                           kt * o3, kt * o4},
                    {dqx, dqy, dvx, dvy, dwx, dwy, du1, du2, du3, du4});

    const double kx = 2.0 * p.C_T * p.l / p.Jxx, ky = 2.0 * p.C_T * p.l / p.Jyy,
                 kz = 2.0 * p.C_D / p.Jzz;
    const double ex = (p.Jzz - p.Jyy) / p.Jxx, ey = (p.Jxx - p.Jzz) / p.Jyy,
                 ez = (p.Jyy - p.Jxx) / p.Jzz;
    xdot(10) = chain(f(10), {-kx * o1, -kx * o2, kx * o3, kx * o4, -ex * wz, -ex * wy},
                     {du1, du2, du3, du4, dwy, dwz});
    xdot(11) = chain(f(11), {-ky * o1, ky * o2, ky * o3, -ky * o4, -ey * wz, -ey * wx},
                     {du1, du2, du3, du4, dwx, dwz});
    xdot(12) = chain(f(12), {-kz * o1, kz * o2, -kz * o3, kz * o4, -ez * wy, -ez * wx},
                     {du1, du2, du3, du4, dwx, dwy});
  }

  // A world-frame force F [N] on the centre of mass besides gravity and thrust (an instructor's
  // gust on the simulated plant, SPEC §10): v̇_b += R(q)ᵀ F / m added to xdot = f(x, u). Apart
  // from dynamics(), so the controller's model is untouched (models::WithExternalForce).
  template <class T>
  void add_external_force(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Vector3d& force,
                          Eigen::Matrix<T, nx, 1>& xdot) const {
    const T &qw = x(3), &qx = x(4), &qy = x(5), &qz = x(6);
    const auto [r00, r01, r02, r10, r11, r12, r20, r21, r22] = rotation(qw, qx, qy, qz);
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
