#pragma once
// Pilot input: whatever flies the vehicle (emulated pilot, recording, gamepad, network peer)
// yields the same command stream, one command per control step (SPEC §6).
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace mixpilot {

// A device's link to the pilot (SPEC §6, input loss). While it is not `ok` the planner has the
// authority: lost (unplugged, or no new input for longer than the timeout), then waiting for
// the sticks to be re-centred, then handing the authority back gradually.
enum class InputState : std::uint8_t { ok = 0, lost = 1, recentre = 2, returning = 3 };
const char* to_string(InputState s);

// The human reference ν^r = (φ_h, θ_h, Ω_h) of SPEC §5.4, and how much authority the source
// grants: the controller uses min(λ, authority), so 0 hands the vehicle to the planner (as
// λ = 0) and a ramp back to 1 returns it without a jump.
struct PilotCommand {
  double roll = 0.0;                                // φ_h [rad]
  double pitch = 0.0;                               // θ_h [rad]
  Eigen::Vector4d rotor_speed = Eigen::Vector4d::Zero();  // Ω_h (scaled units, SPEC §3.3)
  double authority = 1.0;                           // cap on λ, in [0, 1]
  InputState input = InputState::ok;
};

// Raw device input that produced a command (sensor_msgs/Joy in recordings). Fixed capacity,
// so telemetry holding it is copied without allocating.
struct JoyInput {
  static constexpr int kMaxAxes = 8;
  static constexpr int kMaxButtons = 32;
  std::array<float, kMaxAxes> axes{};             // [-1, 1], the first num_axes are used
  std::array<std::int32_t, kMaxButtons> buttons{};  // 0 / 1, the first num_buttons are used
  int num_axes = 0;
  int num_buttons = 0;
};

// What a pilot source keeps between commands, saved with a snapshot of the flight
// (core/modes/mode.hpp: Mode::save). Each source that keeps something derives its own.
struct PilotState {
  virtual ~PilotState() = default;
};

class PilotSource {
 public:
  virtual ~PilotSource() = default;
  // "novice", "gamepad", "replay:<file>", ...
  virtual std::string name() const = 0;
  // The command for control step `step` at time t, given the true state x. Returns false when
  // the source has nothing more to give (end of a recording).
  virtual bool command(std::int64_t step, double t, const Eigen::VectorXd& x,
                       PilotCommand& out) = 0;
  // The raw device input behind the last command, if the source is a device.
  virtual const JoyInput* joy() const { return nullptr; }

  // Snapshots of a flight (Mode::save, Mode::restore). save() copies what the next command()
  // reads into `state`: the first save makes it (replacing another source's), later ones copy
  // into it and allocate nothing. A source that keeps nothing between commands, or cannot go
  // back to an earlier one, leaves it null (the default).
  virtual void save(std::unique_ptr<PilotState>& state) const { state.reset(); }
  // Continues from `state`, saved by a source of the same kind and setup; false, changing
  // nothing, when it cannot. A source whose commands follow from the step and the vehicle's
  // state alone (a recording, the reckless pilot) continues from any state, so it can take
  // over a flight saved with another source. The default refuses: a device reads the present,
  // and cannot give the commands of the past again.
  [[nodiscard]] virtual bool restore(const PilotState* state) {
    (void)state;
    return false;
  }
  // Fly from here (SPEC §10, Mode::take_over): the source takes over a flight at a step it did
  // not fly, from the present, rather than continuing another source. An emulated pilot
  // cold-starts its NMPC from the state its next command is given, as at a flight's start; a
  // device reads from now on and a recording gives its commands of the steps to come, so they
  // have nothing to do (the default). Allocates nothing.
  virtual void take_over() {}
  // The instructor's input loss (SPEC §10): the source's input counts as lost for the steps
  // before `until_step`, then comes back as it does after a lost device (SPEC §6). true: the
  // source does it itself (a device: lost, then re-centre and the ramp; a recording: its
  // commands hold the loss as it was flown); false (the default): the source has no device,
  // and the mode applies SPEC §6's rule to its commands. Allocates nothing.
  [[nodiscard]] virtual bool lose_input(std::int64_t until_step) {
    (void)until_step;
    return false;
  }
};

}  // namespace mixpilot
