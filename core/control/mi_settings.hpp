#pragma once
// Settings of the mixed-initiative controller and of the emulated pilots (SPEC §5.4, defaults of
// SPEC Table 7.1), and the world they fly in. Plain data: the scenario files
// (core/scenario/scenario_toml.hpp) fill them, the controller never sees the file format.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/obstacle_constraint.hpp"
#include "core/control/ph_index.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

// Planner reference η^r(t) = (cx + R cos(φ0 + ω t), cy + R sin(φ0 + ω t), z0 + v_z t).
struct HelixReference {
  Eigen::Vector2d center{0.0, 0.0};  // axis (x, y) [m]
  double radius = 1.0;               // R [m]
  double start_height = 0.5;         // z0 [m]
  double climb_rate = 0.03;          // v_z [m/s]
  double angular_rate = 0.35;        // ω [rad/s]
  double phase = 0.0;                // φ0 [rad]

  Eigen::Vector3d position(double t) const;
  Eigen::Vector3d velocity(double t) const;
};

struct Obstacle {
  Eigen::Vector3d center{0.0, 0.0, 0.0};  // [m]
  double radius = 0.1;                    // [m]
};

// Axis-aligned flight volume; the floor is min.z().
struct Arena {
  Eigen::Vector3d min{-3.0, -3.0, 0.0};  // [m]
  Eigen::Vector3d max{3.0, 3.0, 3.0};    // [m]
  std::vector<Obstacle> obstacles;
};

// Weights of the mixed-initiative cost (SPEC §5.4, Table 7.1), before the λ rescaling.
struct MiWeights {
  Eigen::Vector3d q_eta{100.0, 100.0, 200.0};  // Q_η on p
  double q_nu = 800.0;                         // Q_ν = q_nu·I6 on (φ, θ, Ω1..4)
  Eigen::Matrix<double, 7, 1> q_e =            // Q_e on (ψ, v_b, ω)
      (Eigen::Matrix<double, 7, 1>() << 10, 3, 3, 3, 3, 3, 10).finished();
  double r = 70.0;                             // R = r·I4 on τ
};

// Whether the planner assists the pilot (SPEC §10). off is a probe flight: λ is pinned to 1 in
// the cost of §5.4 for η and ν, so the planner's reference η^r has no weight and the MPC follows
// the pilot's ν^r, while every constraint stays (Ω and τ bounds, obstacles, arena walls) and so
// does the pilot source's authority cap (a lost device still hands the vehicle to the planner).
// The e and u terms keep a fixed weight (probe_regularization): with none the QP is singular.
// Chosen per flight (ModeRequest::assist, a recording's `assist` metadata), never by the
// scenario file.
enum class Assistance { on, off };

struct MiControllerSettings {
  Assistance assist = Assistance::on;
  int N = mi_defaults::kHorizon;
  double dt = mi_defaults::kDt;  // [s]
  MiWeights weights{};
  PhIndexSettings ph{};
  // Safety beyond the thesis: obstacles (lcl, soft with an exact ℓ1 penalty) and the arena's
  // walls and floor (soft state bounds). Off reproduces the thesis's pure formulation.
  bool safety_constraints = true;
  ObstacleForm obstacle_form = ObstacleForm::lcl;
  int max_constrained_obstacles = mi_defaults::kMaxConstrainedObstacles;  // nearest ones
  double vehicle_radius = mi_defaults::kVehicleRadius;                      // [m]
  double slack_l1 = mi_defaults::kSlackL1;  // exact-penalty weight per constraint side
  double slack_l2 = mi_defaults::kSlackL2;  // ℓ2² weight per constraint side
  double rotor_speed_backoff = mi_defaults::kRotorSpeedBackoff;  // Ω bounds tightened by this
  // A probe's weight on e and u, as a fraction of Q_e and R (the planner's η^r keeps none).
  double probe_regularization = mi_defaults::kProbeRegularization;
};

// An emulated pilot (SPEC §5.4, eq. 7.9): an NMPC tracking η^r with cost
// ½(Δηᵀ Q1 Δη + γᵀ Q2 γ + v_bᵀ Q3 v_b + ωᵀ Q4 ω + ΔΩᵀ Q5 ΔΩ + uᵀ R1 u).
struct PilotProfile {
  std::string name;
  Eigen::Vector3d q1{100.0, 100.0, 100.0};  // Δη = p − η^r
  Eigen::Vector3d q2{1.0, 1.0, 1.0};        // γ = (φ, θ, ψ)
  Eigen::Vector3d q3{1.0, 1.0, 1.0};        // v_b
  Eigen::Vector3d q4{1.0, 1.0, 1.0};        // ω
  double q5 = 10.0;                         // ΔΩ = Ω − Ω_hov (all four rotors)
  double r1 = 10.0;                         // τ
  int N = 30;                               // the pilot's own horizon
  double reaction_delay = 0.0;              // [s] the pilot sees the state this late
  double max_tilt = 0.5;                    // [rad] reckless pilot's full tilt
};

}  // namespace mixpilot
