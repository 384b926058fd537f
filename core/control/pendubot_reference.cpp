#include "core/control/pendubot_reference.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/numerics/integrator_erk4.hpp"

namespace mixpilot {

void pendubot_energy_guess(const models::Pendubot& model, double dt, int N, double u_max,
                           OcpTrajectory& traj) {
  const IntegratorErk4<models::Pendubot> erk4(model);
  const double e_top = model.energy(models::Pendubot::up_up());
  traj.x.assign(N + 1, Eigen::VectorXd::Zero(4));
  traj.u.assign(N, Eigen::VectorXd::Zero(1));
  models::Pendubot::State x = models::Pendubot::down_down(), xn;
  traj.x[0] = x;
  for (int i = 0; i < N; ++i) {
    // Pump energy into link 1 (dE/dt = u q̇1), keep link 2 in line with link 1; start with a
    // push, since at rest q̇1 = 0.
    double u = 40.0 * (e_top - model.energy(x)) * x(2) - 0.2 * wrap_angle(x(1)) - 0.02 * x(3);
    if (std::abs(x(2)) < 0.05 && model.energy(x) < 0.05 * e_top) u = u_max;
    u = std::clamp(u, -u_max, u_max);
    erk4.step<double>(x, models::Pendubot::Input(u), dt, xn);
    x = xn;
    traj.u[i](0) = u;
    traj.x[i + 1] = x;
  }
}

namespace {

// One Ipopt solve of the reference OCP on (N, dt) from `traj`.
IpoptOcpResult solve_reference(const PendubotReferenceSettings& s, int N, double dt,
                               const models::Pendubot& model, OcpTrajectory& traj) {
  PendubotOcpSettings os;
  os.N = N;
  os.dt = dt;
  os.u_max = s.u_max;
  os.velocity_bound = s.velocity_bound;
  os.soft_velocity_bounds = false;
  os.weights << s.angle_weight, s.angle_weight, s.velocity_weight, s.velocity_weight,
      s.input_weight;
  // Stage costs are sums over intervals: scale with dt so both grids weigh the same integral.
  os.weights *= dt / s.dt;
  os.terminal_weights << s.terminal_weight, s.terminal_weight, 0.1 * s.terminal_weight,
      0.1 * s.terminal_weight;
  const PendubotSwingup problem(os, model);
  OcpStageData data(problem.ocp());
  problem.set_up_target(data);
  IpoptOcpSolver solver(s.ipopt);
  return solver.solve(problem.ocp(), data, models::Pendubot::down_down(), traj);
}

void linear_guess(int N, double dt, OcpTrajectory& traj) {
  traj.x.assign(N + 1, Eigen::VectorXd::Zero(4));
  traj.u.assign(N, Eigen::VectorXd::Zero(1));
  for (int i = 0; i <= N; ++i) {
    traj.x[i](0) = -std::numbers::pi * (1.0 - double(i) / N);
    traj.x[i](2) = std::numbers::pi / (N * dt);
  }
}

}  // namespace

PendubotReferenceResult compute_pendubot_reference(const PendubotReferenceSettings& s,
                                                   const models::Pendubot& model) {
  PendubotReferenceResult r;
  OcpTrajectory& fine = r.trajectory;
  const int f = s.coarse_factor;
  if (f > 1 && s.N % f == 0) {
    const int Nc = s.N / f;
    OcpTrajectory coarse;
    if (s.guess == 0) {
      linear_guess(Nc, s.dt * f, coarse);
    } else {
      pendubot_energy_guess(model, s.dt * f, Nc, s.u_max, coarse);
    }
    r.coarse = solve_reference(s, Nc, s.dt * f, model, coarse);
    fine.x.assign(s.N + 1, Eigen::VectorXd::Zero(4));
    fine.u.assign(s.N, Eigen::VectorXd::Zero(1));
    for (int i = 0; i <= s.N; ++i) {
      const int j = std::min(i / f, Nc - 1);
      const double w = double(i - j * f) / f;
      fine.x[i] = (1.0 - w) * coarse.x[j] + w * coarse.x[j + 1];
      if (i < s.N) fine.u[i] = coarse.u[j];
    }
  } else if (s.guess == 0) {
    linear_guess(s.N, s.dt, fine);
  } else {
    pendubot_energy_guess(model, s.dt, s.N, s.u_max, fine);
  }
  // Ipopt's variable bounds want an interior start.
  for (std::size_t i = 1; i < fine.x.size(); ++i) {
    for (int j = 0; j < 2; ++j) {
      const double b = 0.999 * s.velocity_bound(j);
      fine.x[i](2 + j) = std::clamp(fine.x[i](2 + j), -b, b);
    }
  }
  r.ipopt = solve_reference(s, s.N, s.dt, model, fine);
  for (const auto& u : fine.u) r.max_abs_u = std::max(r.max_abs_u, std::abs(u(0)));
  for (const auto& x : fine.x) {
    r.max_abs_velocity = r.max_abs_velocity.cwiseMax(x.tail<2>().cwiseAbs());
  }
  r.final_error = fine.x.back().cwiseAbs().maxCoeff();
  return r;
}

}  // namespace mixpilot
