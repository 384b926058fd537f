#pragma once
// MikroKopter, SPEC §3.3. ϑ = (p, γ, v_b, ω, Ω) ∈ R¹⁶ with ZYX Euler angles γ = (φ, θ, ψ) and
// rotor speeds Ω; u = τ rotor torques [N·m] ∈ R⁴. Parameters in the thesis's scaled units
// (Ω in 10³ rad/s), used as these numbers.
#include <cmath>

#include <Eigen/Core>

#include "models/dual.hpp"
#include "models/model.hpp"

namespace mixpilot::models {

struct MikroKopterParams {
  double m = 1.04;       // [kg]
  double l = 0.23;       // arm length [m]
  double Jxx = 0.01;     // [kg·m²]
  double Jyy = 0.01;
  double Jzz = 0.07;
  double C_T = 595.0;    // thrust coefficient (scaled)
  double C_D = 10.0;     // drag coefficient (scaled)
  double J_m = 0.08;     // rotor inertia (scaled; SPEC §3.3)
  double D = 0.5;        // rotor viscous friction (scaled; SPEC §3.3)
  double g = 9.81;       // [m/s²]
  double omega_min = 0.0;  // Table 7.1 bounds
  double omega_max = 0.09;
  double tau_min = -0.1285;
  double tau_max = 0.1285;
};

struct MikroKopter {
  static constexpr int nx = 16;
  static constexpr int nu = 4;
  static constexpr const char* name = "mikrokopter";
  using State = Eigen::Matrix<double, nx, 1>;
  using Input = Eigen::Matrix<double, nu, 1>;

  MikroKopterParams p{};

  // ṗ = R(γ) v_b;  γ̇ = ZYX Euler kinematics (SPEC §2);
  // v̇_b = (0,0,F_z/m) − R(γ)ᵀ(0,0,g) − ω × v_b;  ω̇ = J⁻¹(M − ω × Jω);
  // Ω̇ = (τ − C_D Ω⊙Ω − D Ω)/J_m  (SPEC §3.3).
  template <class T>
  void dynamics(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Matrix<T, nu, 1>& u,
                Eigen::Matrix<T, nx, 1>& xdot) const {
    using std::cos;
    using std::sin;
    const T &phi = x(3), &theta = x(4), &psi = x(5);
    const T &vx = x(6), &vy = x(7), &vz = x(8);
    const T &wx = x(9), &wy = x(10), &wz = x(11);

    const T cph = cos(phi), sph = sin(phi);
    const T cth = cos(theta), sth = sin(theta);
    const T cps = cos(psi), sps = sin(psi);

    // R = Rz(ψ) Ry(θ) Rx(φ)
    const T r00 = cps * cth, r01 = cps * sth * sph - sps * cph, r02 = cps * sth * cph + sps * sph;
    const T r10 = sps * cth, r11 = sps * sth * sph + cps * cph, r12 = sps * sth * cph - cps * sph;
    const T r20 = -sth, r21 = cth * sph, r22 = cth * cph;

    xdot(0) = r00 * vx + r01 * vy + r02 * vz;
    xdot(1) = r10 * vx + r11 * vy + r12 * vz;
    xdot(2) = r20 * vx + r21 * vy + r22 * vz;

    const T tth = sth / cth;
    xdot(3) = wx + sph * tth * wy + cph * tth * wz;
    xdot(4) = cph * wy - sph * wz;
    xdot(5) = (sph * wy + cph * wz) / cth;

    const T s1 = x(12) * x(12), s2 = x(13) * x(13), s3 = x(14) * x(14), s4 = x(15) * x(15);
    const T fz = p.C_T * (s1 + s2 + s3 + s4);
    const T mx = (p.C_T * p.l) * (s2 - s4);
    const T my = (p.C_T * p.l) * (s3 - s1);
    const T mz = p.C_D * (s1 - s2 + s3 - s4);

    xdot(6) = -p.g * r20 - (wy * vz - wz * vy);
    xdot(7) = -p.g * r21 - (wz * vx - wx * vz);
    xdot(8) = fz / p.m - p.g * r22 - (wx * vy - wy * vx);

    const T jwx = p.Jxx * wx, jwy = p.Jyy * wy, jwz = p.Jzz * wz;
    xdot(9) = (mx - (wy * jwz - wz * jwy)) / p.Jxx;
    xdot(10) = (my - (wz * jwx - wx * jwz)) / p.Jyy;
    xdot(11) = (mz - (wx * jwy - wy * jwx)) / p.Jzz;

    const double inv_jm = 1.0 / p.J_m;
    xdot(12) = (u(0) - p.C_D * s1 - p.D * x(12)) * inv_jm;
    xdot(13) = (u(1) - p.C_D * s2 - p.D * x(13)) * inv_jm;
    xdot(14) = (u(2) - p.C_D * s3 - p.D * x(14)) * inv_jm;
    xdot(15) = (u(3) - p.C_D * s4 - p.D * x(15)) * inv_jm;
  }

  // The same f on dual numbers, ∂f/∂z from the Jacobian's nonzeros (models/model.hpp); the
  // values are dynamics<double>'s. With a = sφ ω_y + cφ ω_z, b = cφ ω_y − sφ ω_z:
  //   ∂ṗ/∂v = R,  ∂ṗ/∂φ = (r_i2 v_y − r_i1 v_z)_i,  ∂ṗ/∂θ = (cψ T, sψ T, −(cθ v_x + sθ sφ v_y +
  //   sθ cφ v_z)) with T = −sθ v_x + cθ sφ v_y + cθ cφ v_z,  ∂ṗ/∂ψ = (−ṗ_y, ṗ_x, 0);
  //   φ̇: ∂φ = tθ b, ∂θ = a/cθ²;  θ̇: ∂φ = −a;  ψ̇: ∂φ = b/cθ, ∂θ = a tθ/cθ;
  //   v̇ and ω̇ are bilinear in (v, ω) plus gravity's R row and the rotor terms ∂Ω_i² = 2Ω_i.
  template <int n>
  void dynamics_tangent(const Eigen::Matrix<Dual<n>, nx, 1>& x,
                        const Eigen::Matrix<Dual<n>, nu, 1>& u,
                        Eigen::Matrix<Dual<n>, nx, 1>& xdot) const {
    const auto [xv, uv, f] = values_and_dynamics(*this, x, u);
    const double vx = xv(6), vy = xv(7), vz = xv(8), wx = xv(9), wy = xv(10), wz = xv(11);
    const double cph = std::cos(xv(3)), sph = std::sin(xv(3));
    const double cth = std::cos(xv(4)), sth = std::sin(xv(4));
    const double cps = std::cos(xv(5)), sps = std::sin(xv(5));
    const double r00 = cps * cth, r01 = cps * sth * sph - sps * cph;
    const double r02 = cps * sth * cph + sps * sph, r10 = sps * cth;
    const double r11 = sps * sth * sph + cps * cph, r12 = sps * sth * cph - cps * sph;
    const double r20 = -sth, r21 = cth * sph, r22 = cth * cph;
    using P = const Dual<n>*;  // the tangents of the state's components
    const P dph = &x(3), dth = &x(4), dps = &x(5), dvx = &x(6), dvy = &x(7), dvz = &x(8);
    const P dwx = &x(9), dwy = &x(10), dwz = &x(11);
    const P dO1 = &x(12), dO2 = &x(13), dO3 = &x(14), dO4 = &x(15);

    const double T = -sth * vx + cth * sph * vy + cth * cph * vz;
    xdot(0) = chain(f(0), {r00, r01, r02, r02 * vy - r01 * vz, cps * T, -f(1)},
                    {dvx, dvy, dvz, dph, dth, dps});
    xdot(1) = chain(f(1), {r10, r11, r12, r12 * vy - r11 * vz, sps * T, f(0)},
                    {dvx, dvy, dvz, dph, dth, dps});
    xdot(2) = chain(f(2), {r20, r21, r22, r22 * vy - r21 * vz,
                           -(cth * vx + sth * sph * vy + sth * cph * vz)},
                    {dvx, dvy, dvz, dph, dth});

    const double a = sph * wy + cph * wz, b = cph * wy - sph * wz;
    const double tth = sth / cth, icth = 1.0 / cth;
    xdot(3) = chain(f(3), {1.0, sph * tth, cph * tth, tth * b, a * icth * icth},
                    {dwx, dwy, dwz, dph, dth});
    xdot(4) = chain(f(4), {cph, -sph, -a}, {dwy, dwz, dph});
    xdot(5) = chain(f(5), {sph * icth, cph * icth, b * icth, a * tth * icth},
                    {dwy, dwz, dph, dth});

    const double g = p.g;
    xdot(6) = chain(f(6), {g * cth, wz, -wy, -vz, vy}, {dth, dvy, dvz, dwy, dwz});
    xdot(7) = chain(f(7), {-g * r22, g * sth * sph, -wz, wx, vz, -vx},
                    {dph, dth, dvx, dvz, dwx, dwz});
    const double o1 = xv(12), o2 = xv(13), o3 = xv(14), o4 = xv(15);
    const double kt = 2.0 * p.C_T / p.m;
    xdot(8) = chain(f(8), {g * r21, g * sth * cph, wy, -wx, -vy, vx, kt * o1, kt * o2, kt * o3,
                           kt * o4},
                    {dph, dth, dvx, dvy, dwx, dwy, dO1, dO2, dO3, dO4});

    const double kl = 2.0 * p.C_T * p.l, kd = 2.0 * p.C_D;
    const double ex = (p.Jzz - p.Jyy) / p.Jxx, ey = (p.Jxx - p.Jzz) / p.Jyy,
                 ez = (p.Jyy - p.Jxx) / p.Jzz;
    xdot(9) = chain(f(9), {kl * o2 / p.Jxx, -kl * o4 / p.Jxx, -ex * wz, -ex * wy},
                    {dO2, dO4, dwy, dwz});
    xdot(10) = chain(f(10), {kl * o3 / p.Jyy, -kl * o1 / p.Jyy, -ey * wz, -ey * wx},
                     {dO3, dO1, dwx, dwz});
    xdot(11) = chain(f(11), {kd * o1 / p.Jzz, -kd * o2 / p.Jzz, kd * o3 / p.Jzz,
                             -kd * o4 / p.Jzz, -ez * wy, -ez * wx},
                     {dO1, dO2, dO3, dO4, dwx, dwy});

    const double inv_jm = 1.0 / p.J_m;
    for (int i = 0; i < nu; ++i) {
      const double o = xv(12 + i);
      xdot(12 + i) = chain(f(12 + i), {-(kd * o + p.D) * inv_jm, inv_jm}, {&x(12 + i), &u(i)});
    }
  }

  // A world-frame force F [N] on the centre of mass besides gravity and thrust (an instructor's
  // gust on the simulated plant, SPEC §10): v̇_b += R(γ)ᵀ F / m added to xdot = f(x, u). Apart
  // from dynamics(), so the controller's model is untouched (models::WithExternalForce).
  template <class T>
  void add_external_force(const Eigen::Matrix<T, nx, 1>& x, const Eigen::Vector3d& force,
                          Eigen::Matrix<T, nx, 1>& xdot) const {
    using std::cos;
    using std::sin;
    const T cph = cos(x(3)), sph = sin(x(3)), cth = cos(x(4)), sth = sin(x(4));
    const T cps = cos(x(5)), sps = sin(x(5));
    const T r00 = cps * cth, r01 = cps * sth * sph - sps * cph, r02 = cps * sth * cph + sps * sph;
    const T r10 = sps * cth, r11 = sps * sth * sph + cps * cph, r12 = sps * sth * cph - cps * sph;
    const T r20 = -sth, r21 = cth * sph, r22 = cth * cph;
    const double fx = force.x() / p.m, fy = force.y() / p.m, fz = force.z() / p.m;
    xdot(6) += r00 * fx + r10 * fy + r20 * fz;
    xdot(7) += r01 * fx + r11 * fy + r21 * fz;
    xdot(8) += r02 * fx + r12 * fy + r22 * fz;
  }

  // Ω = √(m g / 4 C_T) ≈ 0.0655 and the torque τ = C_D Ω² + D Ω ≈ 0.0756 that holds it.
  double hover_speed() const { return std::sqrt(p.m * p.g / (4.0 * p.C_T)); }
  double hover_torque() const {
    const double w = hover_speed();
    return p.C_D * w * w + p.D * w;
  }

  State hover_state(const Eigen::Vector3d& position) const {
    State x = Eigen::Matrix<double, nx, 1>::Zero();
    x.head<3>() = position;
    x.tail<4>().setConstant(hover_speed());
    return x;
  }
  Input hover_input() const {
    return Eigen::Matrix<double, nu, 1>::Constant(hover_torque());
  }
};

}  // namespace mixpilot::models
