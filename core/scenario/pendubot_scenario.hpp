#pragma once
// Scenario files of mode `pendubot_swingup` (docs/scenario-format.md, "Pendubot swing-up") →
// PendubotScenario: the NMPC and LQR settings of core/control/pendubot.hpp, the plant, the
// sensor and the swing-up reference the NMPC tracks.
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "core/control/pendubot.hpp"
#include "core/nlp/trajectory_io.hpp"
#include "core/numerics/types.hpp"
#include "models/pendubot.hpp"

namespace mixpilot {

struct PendubotScenario {
  std::string name;
  std::string source_path;
  double duration = 8.0;  // [s]
  double angle_tolerance = pendubot_defaults::kAngleTolerance;  // [rad]

  PendubotOcpSettings controller{};
  std::string reference_path;   // as written (relative to the scenario file's folder)
  TrajectoryFile reference;     // loaded and checked (Δt = controller.dt, nx = 4, nu = 1)

  // Switch rule of core/modes/pendubot_mode.hpp.
  struct Lqr {
    bool enabled = true;
    Eigen::Vector4d q{3.0, 3.0, 1.0, 1.0};  // default: the NMPC's W
    double r = 5.0;
    double enter_angle = pendubot_defaults::kLqrEnter;            // [rad]
    double enter_velocity = pendubot_defaults::kLqrEnterVelocity;  // [rad/s]
    double exit_angle = pendubot_defaults::kLqrExit;              // [rad]
  } lqr;

  struct Plant {
    double rate_hz = pendubot_defaults::kPlantRateHz;  // RK4 substeps per second (≥ 1000)
    Eigen::Vector4d initial_state = models::Pendubot::down_down();
  } plant;

  struct Sensor {
    bool quantization = false;
    int counts_q1 = pendubot_defaults::kEncoderCounts1;  // per turn
    int counts_q2 = pendubot_defaults::kEncoderCounts2;
    double velocity_cutoff_hz = pendubot_defaults::kVelocityCutoffHz;  // 0: raw differences
    // "difference": angles = encoder cell centres, velocities = low-passed differences.
    // "observer": the model predicts x̂ over Δt with the applied input, and the encoder angles
    // correct it (α-β gains): q̂ += α e, q̇̂ += β e / Δt with e = q_enc − q̂⁻.
    std::string estimator = "difference";
    double observer_alpha = pendubot_defaults::kObserverAlpha;
    double observer_beta = pendubot_defaults::kObserverBeta;
  } sensor;
};

// Reading `mode = "pendubot_swingup"` scenarios. On failure: nullopt and one
// `<file>:<line>:<col>: <key path>: <what was expected>` line per problem.
std::optional<PendubotScenario> load_pendubot_scenario(const std::string& path, std::string& error);
// The same from text; the reference path is resolved against source_name's folder.
std::optional<PendubotScenario> parse_pendubot_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error);

}  // namespace mixpilot
