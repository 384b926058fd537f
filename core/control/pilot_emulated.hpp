#pragma once
// Emulated pilot of SPEC §5.4 (thesis eq. 7.9): a second NMPC on the same model tracks the
// planner's η^r with cost ½(Δηᵀ Q1 Δη + γᵀ Q2 γ + v_bᵀ Q3 v_b + ωᵀ Q4 ω + ΔΩᵀ Q5 ΔΩ + uᵀ R1 u),
// ΔΩ = Ω − Ω_hov; its stage-1 prediction is the pilot's command (φ_h, θ_h, Ω_h) = (φ*_1, θ*_1,
// Ω*_1). The pilot sees the true state; a reaction delay holds each command back by
// round(delay/Δt) control steps (hover command until the first one arrives).
#include <vector>

#include "core/numerics/integrator_erk4.hpp"
#include "core/nlp/ocp.hpp"
#include "core/control/pilot.hpp"
#include "core/nlp/rti.hpp"
#include "core/control/mi_settings.hpp"
#include "models/mikrokopter.hpp"

namespace mixpilot {

class EmulatedPilot final : public PilotSource {
 public:
  EmulatedPilot() = default;
  EmulatedPilot(const EmulatedPilot&) = delete;
  EmulatedPilot& operator=(const EmulatedPilot&) = delete;

  SetupResult setup(const models::MikroKopter& model, const PilotProfile& profile,
             const HelixReference& reference, double dt);

  std::string name() const override { return profile_.name; }
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override;

  // The pilot's NMPC and its reaction delay line.
  struct State final : PilotState {
    RtiState rti;
    std::vector<PilotCommand> delay_line;
    bool started = false;
  };
  void save(std::unique_ptr<PilotState>& state) const override;
  // Only a State of a pilot with the same horizon and reaction delay.
  [[nodiscard]] bool restore(const PilotState* state) override;
  // Back to the state setup() left: the NMPC's solver as set up, to be warm-started at hover
  // from the next command's state, and the reaction delay line full of hover commands.
  void take_over() override;

 private:
  models::MikroKopter model_{};
  IntegratorErk4<models::MikroKopter> integrator_{};
  PilotProfile profile_{};
  HelixReference helix_{};
  double dt_ = 0.015;
  SelectionOutput output_;
  SelectionOutput terminal_output_;
  Ocp ocp_;
  RtiSolver rti_;
  std::vector<PilotCommand> delay_line_;  // ring buffer of delay_steps + 1 commands
  bool started_ = false;
  RtiState initial_;   // the solver's state as setup() left it (take_over())
  PilotCommand hover_;  // what the delay line holds before the first command arrives
};

// A pilot who ignores the reference and steers straight at the nearest obstacle at full tilt,
// holding altitude towards the obstacle's centre height: the test of the safety constraints.
class RecklessPilot final : public PilotSource {
 public:
  RecklessPilot(const models::MikroKopter& model, const Arena& arena, double max_tilt)
      : model_(model), arena_(arena), max_tilt_(max_tilt) {}

  std::string name() const override { return "reckless"; }
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override;
  // Keeps nothing (save() leaves the state null): its command follows from the vehicle's state.
  [[nodiscard]] bool restore(const PilotState*) override { return true; }

 private:
  models::MikroKopter model_;
  Arena arena_;
  double max_tilt_;
};

}  // namespace mixpilot
