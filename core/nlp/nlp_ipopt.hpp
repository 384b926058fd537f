#pragma once
// Offline solution of the OCP of core/nlp/ocp.hpp to convergence with Ipopt (SPEC §4: reference
// trajectories and "fully converged" baselines). Multiple shooting with the same ERK4 as the
// NMPC: the NLP variables are
//
//   w = (u_0, x_1, u_1, ..., x_{N−1}, u_{N−1}, x_N, slacks),   x_0 = x̄_0 is not a variable,
//
// with the constraints, stage by stage (i = 0..N−1, then stage k = i+1):
//   F(x_i, u_i) − x_{i+1} = 0                              Jacobian blocks [A_i B_i −I]
//   lg_j ≤ g_j(x_k, u_k, p_k) ≤ ug_j                      hard path constraints, rows [Gx Gu]
//   g_j + s_l ≥ lg_j,  g_j − s_u ≤ ug_j                   soft path constraints (finite sides)
//   x_k[idxbx_j] + s_l ≥ lbx_j,  x_k[idxbx_j] − s_u ≤ ubx_j  soft state bounds (finite sides)
// Hard input and state bounds are Ipopt variable bounds; slacks are ≥ 0 with cost ½Z s² + z s.
// A, B come from Integrator::step_sensitivities; the Jacobian is sparse with exactly this
// block structure. Ipopt is an implementation detail: its headers stay in nlp_ipopt.cpp.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/nlp/ocp.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

// The Hessian of the Lagrangian that Ipopt factorizes.
enum class IpoptHessian {
  // Gauss-Newton blocks J_yᵀ W J_y of the cost (exact for SelectionOutput) and the exact slack
  // weights Z, plus the constraint curvature Σ λ_j ∇²c_j by central differences of the same
  // sensitivities (A, B and Gx, Gu) along each stage variable. Newton-like: the default.
  gauss_newton_fd_curvature,
  // Gauss-Newton cost blocks only (constraint curvature dropped): exact for linear dynamics,
  // but did not reach 1e-10 on the smooth step in 1000 iterations (see nlp_ipopt.cpp).
  gauss_newton,
  // Ipopt's L-BFGS ("limited-memory"); no second derivatives at all. Same caveat.
  limited_memory,
};

struct IpoptOcpSettings {
  double tolerance = ipopt_defaults::kTolerance;
  int max_iterations = ipopt_defaults::kMaxIterations;
  int print_level = ipopt_defaults::kPrintLevel;  // 0: silent
  IpoptHessian hessian = IpoptHessian::gauss_newton_fd_curvature;
  double curvature_step = ipopt_defaults::kCurvatureStep;
};

enum class IpoptOcpStatus {
  solved,             // converged to `tolerance`
  acceptable,         // Ipopt's "solved to acceptable level"
  max_iterations,     // iteration limit reached; the result is the last iterate
  infeasible,         // Ipopt detected local infeasibility
  failed,             // restoration failure, tiny steps, evaluation errors, ...
  invalid_input,      // Ocp::check() failed or the data, x̄_0 or guess have the wrong sizes
};

const char* to_string(IpoptOcpStatus status);

struct IpoptOcpResult {
  IpoptOcpStatus status = IpoptOcpStatus::failed;
  int ipopt_return_code = 0;  // Ipopt::ApplicationReturnStatus (0 = Solve_Succeeded)
  int iterations = 0;
  double objective = 0.0;  // cost at the returned trajectory, slack penalties included
  double dynamics_residual = 0.0;      // max_i ‖F(x_i, u_i) − x_{i+1}‖∞ at the result
  double constraint_violation = 0.0;   // Ipopt's unscaled final constraint violation
  double dual_infeasibility = 0.0;     // Ipopt's unscaled final dual infeasibility
  double solve_seconds = 0.0;          // wall clock
  const char* message = "";            // why the input is invalid, or Ipopt's status in words
};

class IpoptOcpSolver {
 public:
  using Settings = IpoptOcpSettings;

  explicit IpoptOcpSolver(const Settings& settings = Settings{});
  ~IpoptOcpSolver();
  IpoptOcpSolver(const IpoptOcpSolver&) = delete;
  IpoptOcpSolver& operator=(const IpoptOcpSolver&) = delete;

  const Settings& settings() const { return settings_; }

  // Solves from the initial guess in `guess_and_result` (N+1 states, N inputs of the OCP's
  // sizes; guess.x[0] is ignored) and writes the last Ipopt iterate back into it, x[0] = x0.
  // On invalid_input the trajectory is untouched. Never throws; prints only if print_level > 0.
  IpoptOcpResult solve(const Ocp& ocp, const OcpStageData& data, const Eigen::VectorXd& x0,
                       OcpTrajectory& guess_and_result);

  // Slacks of the last solve, per stage (N+1 entries, stage 0 all zero): entry j is the soft
  // item j of (soft_state_bounds, soft_constraints) in that order; 0 for an infinite side.
  const std::vector<Eigen::VectorXd>& slack_lower() const { return slack_lower_; }
  const std::vector<Eigen::VectorXd>& slack_upper() const { return slack_upper_; }

 private:
  struct Impl;
  Settings settings_;
  std::unique_ptr<Impl> impl_;
  std::vector<Eigen::VectorXd> slack_lower_;  // N+1 x (nsbx + nsg)
  std::vector<Eigen::VectorXd> slack_upper_;  // N+1 x (nsbx + nsg)
};

}  // namespace mixpilot
