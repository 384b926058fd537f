#pragma once
// Offline Pendubot swing-up reference (SPEC §5.1), solved by Ipopt and committed as
// scenarios/references/pendubot_swingup.csv (`mixpilot-reference pendubot-swingup`); the NMPC of
// core/control/pendubot.hpp tracks it.
//
// Down-down → up-up over T = N·dt with |u| ≤ u_max and hard velocity bounds, both tightened from
// SPEC §5.1's so the tracking NMPC keeps authority and margin; cost ½Σ (wq‖q‖² + wv‖q̇‖² + r u²)
// + ½ w_N (‖q_N‖² + 0.1‖q̇_N‖²). Solved twice: first on a grid coarse_factor times coarser from
// the guess q1: −π → 0 linearly, u = 0 (the energy-pumping rollout is a worse start: its link 2
// tumbles and Ipopt ends in a spinning local minimum), then on the 2 ms grid from the coarse
// solution (inputs held, states interpolated).
#include <Eigen/Core>

#include "core/control/pendubot.hpp"
#include "core/nlp/nlp_ipopt.hpp"
#include "core/nlp/ocp.hpp"
#include "core/numerics/types.hpp"
#include "models/pendubot.hpp"

namespace mixpilot {

struct PendubotReferenceSettings {
  int N = 1250;                        // intervals (T = 2.5 s)
  double dt = pendubot_defaults::kDt;  // [s]
  int coarse_factor = 10;              // ≤ 1: solve the fine grid directly
  double u_max = 0.36;                 // 90 % of the 0.4 N·m bound [N·m]
  Eigen::Vector2d velocity_bound{7.0, 4.5};  // 90 % of (7.8, 5) [rad/s]
  double angle_weight = 1.0;
  double velocity_weight = 0.01;
  double input_weight = 1.0;
  double terminal_weight = 1e4;
  // Initial guess: 0 = the linear guess above, 1 = the energy-pumping rollout.
  int guess = 0;
  IpoptOcpSettings ipopt{1e-8, 3000, 0};
};

struct PendubotReferenceResult {
  IpoptOcpResult coarse;  // the coarse-grid solve (iterations 0 when skipped)
  IpoptOcpResult ipopt;   // the 2 ms solve
  OcpTrajectory trajectory;
  double max_abs_u = 0.0;
  Eigen::Vector2d max_abs_velocity = Eigen::Vector2d::Zero();
  double final_error = 0.0;  // ‖x_N‖∞
};

// The energy-pumping rollout used as initial guess: u = sat(k_E (E − E_top) q̇1 − k_p q2 −
// k_d q̇2), ERK4 at dt, N intervals from down-down.
void pendubot_energy_guess(const models::Pendubot& model, double dt, int N, double u_max,
                           OcpTrajectory& traj);

PendubotReferenceResult compute_pendubot_reference(const PendubotReferenceSettings& settings,
                                                   const models::Pendubot& model = {});

}  // namespace mixpilot
