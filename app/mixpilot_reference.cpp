// mixpilot-reference: offline reference trajectories computed with Ipopt (core/nlp/nlp_ipopt.hpp).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "core/control/crazyflie_tracking.hpp"
#include "core/nlp/nlp_ipopt.hpp"
#include "core/control/obstacle_avoidance.hpp"
#include "core/control/pendubot_reference.hpp"
#include "core/nlp/trajectory_io.hpp"

namespace {

constexpr const char* kUsage =
    "usage: mixpilot-reference <command> [options]\n"
    "\n"
    "commands:\n"
    "  smooth-step   SPEC 5.2's smooth step of the Crazyflie: hover at (0,0,0.4) to (1,-1,1),\n"
    "                T = 6 s, N = 400, dt = 15 ms, the 5.2 weights, solved to convergence by\n"
    "                Ipopt from the hover guess\n"
    "  pendubot-swingup  SPEC 5.1's swing-up reference: down-down to up-up, dt = 2 ms,\n"
    "                N = 1250 (T = 2.5 s), |u| <= 0.36, |dq| <= (7, 4.5); Ipopt on a 20 ms grid\n"
    "                first, then on 2 ms (scenarios/references/pendubot_swingup.csv; --N: T)\n"
    "  obstacles-p1  SPEC 5.3's obstacle-free reference: hover at (0,0,0.4) to p1 = (1,-1,1),\n"
    "                T = 3 s, N = 200, dt = 15 ms, the 5.3 weights, Ipopt from the hover guess\n"
    "                (scenarios/references/obstacles_to_1_-1_1.csv)\n"
    "  obstacles-p2  the same to p2 = (0.5,-0.5,1) (scenarios/references/obstacles_to_0.5_-0.5_1.csv)\n"
    "\n"
    "options:\n"
    "  --out FILE          write the trajectory as CSV (docs: core/nlp/trajectory_io.hpp)\n"
    "  --hessian NAME      fd-curvature (default), gauss-newton or limited-memory\n"
    "  --tol X             Ipopt tolerance (default 1e-10)\n"
    "  --max-iter N        iteration limit (default 1000)\n"
    "  --N N               intervals of pendubot-swingup (default 1250, a multiple of 10)\n"
    "  --print-level N     Ipopt's log level, 0..12 (default 0: silent; 5: the usual log)\n"
    "  -h, --help          show this help\n";

using namespace mixpilot;

int usage_error(const char* what) {
  std::fprintf(stderr, "mixpilot-reference: %s\n\n%s", what, kUsage);
  return 2;
}

int run_smooth_step(const std::string& out, const IpoptOcpSettings& settings) {
  constexpr int N = 400;
  constexpr double dt = 0.015;
  const Eigen::Vector3d start(0.0, 0.0, 0.4), target(1.0, -1.0, 1.0);
  const CrazyflieTracking problem(N, dt);
  OcpStageData data(problem.ocp());
  problem.set_hover_target(data, target);
  OcpTrajectory traj(problem.ocp());
  problem.hover_guess(traj, start);
  const Eigen::VectorXd x0 = problem.model().hover_state(start);

  std::printf("smooth step: hover (0,0,0.4) -> (1,-1,1), N = %d, dt = %.3f s, T = %.1f s\n", N,
              dt, N * dt);
  IpoptOcpSolver solver(settings);
  const IpoptOcpResult r = solver.solve(problem.ocp(), data, x0, traj);
  std::printf("ipopt: %s (%s), %d iterations, %.2f s\n", to_string(r.status), r.message,
              r.iterations, r.solve_seconds);
  std::printf("objective %.12g, constraint violation %.2e, dual infeasibility %.2e, "
              "dynamics residual %.2e\n",
              r.objective, r.constraint_violation, r.dual_infeasibility, r.dynamics_residual);
  if (r.status != IpoptOcpStatus::solved) {
    std::fprintf(stderr, "mixpilot-reference: Ipopt did not converge; nothing written\n");
    return 1;
  }
  const Eigen::Vector3d pN = traj.x[N].head<3>();
  double omega_min = 1e300, omega_max = -1e300;
  for (const auto& u : traj.u) {
    omega_min = std::min(omega_min, u.minCoeff());
    omega_max = std::max(omega_max, u.maxCoeff());
  }
  std::printf("final position (%.6f, %.6f, %.6f), error %.2e m; Omega in [%.4f, %.4f] krpm\n",
              pN(0), pN(1), pN(2), (pN - target).norm(), omega_min, omega_max);
  if (!out.empty()) {
    std::string error;
    if (!write_trajectory_csv(out, traj, dt, error)) {
      std::fprintf(stderr, "mixpilot-reference: %s\n", error.c_str());
      return 1;
    }
    std::printf("wrote %s\n", out.c_str());
  }
  return 0;
}

// SPEC 5.3 references (thesis eq. 6.7): the obstacle-avoidance OCP without obstacles,
// tracking the hover at `target` over T = 3 s, N = 200.
int run_obstacle_reference(const Eigen::Vector3d& target, const std::string& out,
                           const IpoptOcpSettings& settings) {
  ObstacleControllerSettings cs;
  cs.N = 200;
  cs.dt = 0.015;
  const Eigen::Vector3d start(0.0, 0.0, 0.4);
  const ObstacleAvoidanceOcp problem(0, cs);
  OcpStageData data(problem.ocp());
  problem.set_hover_target(data, target);
  OcpTrajectory traj(problem.ocp());
  problem.hover_guess(traj, start);
  const Eigen::VectorXd x0 = problem.model().hover_state(start);

  std::printf("obstacle reference: hover (0,0,0.4) -> (%g,%g,%g), N = %d, dt = %.3f s, "
              "T = %.1f s\n", target(0), target(1), target(2), cs.N, cs.dt, cs.N * cs.dt);
  IpoptOcpSolver solver(settings);
  const IpoptOcpResult r = solver.solve(problem.ocp(), data, x0, traj);
  std::printf("ipopt: %s (%s), %d iterations, %.2f s\n", to_string(r.status), r.message,
              r.iterations, r.solve_seconds);
  std::printf("objective %.12g, constraint violation %.2e, dual infeasibility %.2e, "
              "dynamics residual %.2e\n",
              r.objective, r.constraint_violation, r.dual_infeasibility, r.dynamics_residual);
  if (r.status != IpoptOcpStatus::solved) {
    std::fprintf(stderr, "mixpilot-reference: Ipopt did not converge; nothing written\n");
    return 1;
  }
  const Eigen::Vector3d pN = traj.x[cs.N].head<3>();
  double omega_min = 1e300, omega_max = -1e300;
  for (const auto& u : traj.u) {
    omega_min = std::min(omega_min, u.minCoeff());
    omega_max = std::max(omega_max, u.maxCoeff());
  }
  std::printf("final position (%.6f, %.6f, %.6f), error %.2e m; Omega in [%.4f, %.4f] krpm\n",
              pN(0), pN(1), pN(2), (pN - target).norm(), omega_min, omega_max);
  if (!out.empty()) {
    std::string error;
    if (!write_trajectory_csv(out, traj, cs.dt, error)) {
      std::fprintf(stderr, "mixpilot-reference: %s\n", error.c_str());
      return 1;
    }
    std::printf("wrote %s\n", out.c_str());
  }
  return 0;
}

// SPEC 5.1: the Pendubot swing-up reference the NMPC tracks (core/control/pendubot_reference.hpp).
int run_pendubot_swingup(const std::string& out, const IpoptOcpSettings& settings, int N) {
  PendubotReferenceSettings s;
  s.ipopt = settings;
  if (N > 0) s.N = N;
  std::printf("pendubot swing-up: down-down -> up-up, N = %d, dt = %.3f s, T = %.2f s, "
              "|u| <= %.2f, |dq| <= (%.2f, %.2f)\n",
              s.N, s.dt, s.N * s.dt, s.u_max, s.velocity_bound(0), s.velocity_bound(1));
  const PendubotReferenceResult res = compute_pendubot_reference(s);
  std::printf("ipopt, 20 ms grid: %s, %d iterations, %.2f s\n", to_string(res.coarse.status),
              res.coarse.iterations, res.coarse.solve_seconds);
  const IpoptOcpResult& r = res.ipopt;
  std::printf("ipopt: %s (%s), %d iterations, %.2f s\n", to_string(r.status), r.message,
              r.iterations, r.solve_seconds);
  std::printf("objective %.12g, constraint violation %.2e, dual infeasibility %.2e, "
              "dynamics residual %.2e\n",
              r.objective, r.constraint_violation, r.dual_infeasibility, r.dynamics_residual);
  std::printf("max |u| %.4f N·m, max |dq| (%.3f, %.3f) rad/s, final |x|inf %.2e\n",
              res.max_abs_u, res.max_abs_velocity(0), res.max_abs_velocity(1), res.final_error);
  if (r.status != IpoptOcpStatus::solved) {
    std::fprintf(stderr, "mixpilot-reference: Ipopt did not converge; nothing written\n");
    return 1;
  }
  if (!out.empty()) {
    std::string error;
    if (!write_trajectory_csv(out, res.trajectory, s.dt, error)) {
      std::fprintf(stderr, "mixpilot-reference: %s\n", error.c_str());
      return 1;
    }
    std::printf("wrote %s\n", out.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string command, out;
  IpoptOcpSettings settings;
  int pendubot_n = 0;
  for (int a = 1; a < argc; ++a) {
    const std::string_view arg = argv[a];
    const bool has_value = a + 1 < argc;
    if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (arg == "--out" && has_value) {
      out = argv[++a];
    } else if (arg == "--hessian" && has_value) {
      const std::string_view name = argv[++a];
      if (name == "fd-curvature")
        settings.hessian = IpoptHessian::gauss_newton_fd_curvature;
      else if (name == "gauss-newton")
        settings.hessian = IpoptHessian::gauss_newton;
      else if (name == "limited-memory")
        settings.hessian = IpoptHessian::limited_memory;
      else
        return usage_error("unknown --hessian (fd-curvature, gauss-newton, limited-memory)");
    } else if (arg == "--tol" && has_value) {
      settings.tolerance = std::atof(argv[++a]);
      if (!(settings.tolerance > 0.0)) return usage_error("--tol must be a positive number");
    } else if (arg == "--max-iter" && has_value) {
      settings.max_iterations = std::atoi(argv[++a]);
    } else if (arg == "--N" && has_value) {
      pendubot_n = std::atoi(argv[++a]);
      if (pendubot_n < 1) return usage_error("--N must be a positive integer");
    } else if (arg == "--print-level" && has_value) {
      settings.print_level = std::atoi(argv[++a]);
    } else if (!arg.empty() && arg[0] != '-' && command.empty()) {
      command = arg;
    } else {
      return usage_error(("unexpected argument '" + std::string(arg) + "'").c_str());
    }
  }
  if (command == "smooth-step") return run_smooth_step(out, settings);
  if (command == "pendubot-swingup") return run_pendubot_swingup(out, settings, pendubot_n);
  if (command == "obstacles-p1") return run_obstacle_reference({1.0, -1.0, 1.0}, out, settings);
  if (command == "obstacles-p2") return run_obstacle_reference({0.5, -0.5, 1.0}, out, settings);
  if (command.empty()) return usage_error("missing command");
  return usage_error(("unknown command '" + command + "'").c_str());
}
