#pragma once
// One interface for every mode (SPEC §5.1–§5.4): mixed initiative, Pendubot swing-up, tracking
// under delay, obstacle avoidance. A mode is made from a parsed scenario (core/modes/
// make_mode.hpp); step() advances one control period, plant substeps included, and allocates
// nothing. Between steps its telemetry and metrics can be read, and its whole state saved into
// a ModeSnapshot and restored, into it or another mode of the same scenario. The session
// (core/modes/session.hpp) drives any mode and hands each step's telemetry to its sinks.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/control/ph_index.hpp"
#include "core/control/pilot.hpp"
#include "core/modes/instructor.hpp"
#include "core/modes/mode_view.hpp"
#include "core/modes/vehicle_link.hpp"
#include "core/nlp/rti.hpp"

namespace mixpilot {

enum class ModeKind { mixed_initiative, pendubot_swingup, crazyflie_tracking, obstacle_avoidance };

const char* to_string(ModeKind kind);
std::optional<ModeKind> mode_kind_from_string(std::string_view name);
// "mixed_initiative, pendubot_swingup, ...", for messages.
std::string mode_kind_names();

// What happened in one control step (bit flags of Telemetry::events).
enum ModeEvent : std::uint32_t {
  kEventFallback = 1u << 0,   // the QP failed: the previous solution's next input was applied
  kEventCollision = 1u << 1,  // contact started: the vehicle touches an obstacle, wall or floor
  kEventViolation = 1u << 2,  // a constraint of the mode was violated (clearance, velocity bound)
  kEventSwitch = 1u << 3,     // the active controller changed (Pendubot NMPC ↔ LQR, MPC ↔ safe)
  kEventLost = 1u << 4,       // the vehicle was lost (non-finite or far away): the run ends
  kEventOverrun = 1u << 5,    // the RTI solve overran its deadline: handled as a fallback
  kEventInputLost = 1u << 6,  // the pilot's device was lost: the planner took the authority
  // A paced run's step whose control input was ready after its period had ended (it started
  // late, or computing took too long), or whose computing took longer than Δt (SPEC §8).
  kEventDeadlineMiss = 1u << 7,
  // The safe controller flew this step: the MPC's plan was spent after fallbacks in a row
  // (core/modes/safety_net.hpp).
  kEventSafeHold = 1u << 8,
};

// A named scalar of one step, for plots that do not know the mode. Names and units are string
// literals of the mode, never pointers into its memory.
struct Channel {
  const char* name = "";
  const char* unit = "";
  double value = 0.0;
};

// One control step k, [t_k, t_k + Δt). A value: copying it (into a buffer sized by a first
// copy) allocates nothing, and it points into nothing, so a render or writer thread can keep it.
struct Telemetry {
  static constexpr int kMaxChannels = 16;

  ModeKind mode = ModeKind::mixed_initiative;
  std::int64_t step = 0;
  double t = 0.0;                   // [s] t_k
  Eigen::VectorXd x;                // nx: true plant state at t_k
  Eigen::VectorXd x_measured;       // nx: the state the controller started from
  Eigen::VectorXd u;                // nu: input applied to the plant over the step
  // The mode's reference at t_k: the position η^r (3) in the quadrotor modes, the state (4) in
  // the Pendubot mode.
  Eigen::VectorXd reference;
  Eigen::Matrix3Xd predicted;            // 3 x (N+1): predicted positions (quadrotor modes)
  Eigen::Matrix3Xd predicted_reference;  // 3 x (N+1): reference at the shooting nodes
  bool solved = false;   // an RTI step ran (false: an LQR step, or the run has not started)
  RtiStats stats{};      // of that RTI step; stats.total_us = prepare + feedback
  std::uint32_t events = 0;  // ModeEvent flags
  // [m] the vehicle sphere's least distance to an obstacle, a wall or the floor at t_k
  // (negative: in contact; core/modes/score.hpp); +∞ where the mode does not measure it.
  double clearance = std::numeric_limits<double>::infinity();

  // Mixed initiative only.
  PilotCommand pilot;    // the pilot's command ν^r
  PilotCommand applied;  // the MPC's stage-1 (φ, θ, Ω): what the pilot's command became
  double lambda = 0.0;   // PH index used in this step
  LambdaReason reason;   // what decided λ (SPEC §10 "Why λ fell")
  bool has_joy = false;  // joy holds the raw device input behind the pilot's command
  JoyInput joy;

  std::array<Channel, kMaxChannels> channels{};
  int num_channels = 0;

  // The instructor's commands (SPEC §10) that took effect at this step, in the order applied
  // (Mode::instruct), and what the commands keep in force during it.
  std::array<InstructorCommand, kMaxCommandsPerStep> commands{};
  int num_commands = 0;
  InstructorInForce instructor;

  // Sets channel i (i < kMaxChannels) and extends num_channels to cover it.
  void set_channel(int i, const char* name, const char* unit, double value) {
    channels[std::size_t(i)] = Channel{name, unit, value};
    if (num_channels <= i) num_channels = i + 1;
  }
};

// Name → value in report order (`mixpilot fly --report` writes them as a JSON object).
using Metrics = std::vector<std::pair<std::string, double>>;

// Why Mode::restore() refused a snapshot, or ok.
enum class RestoreStatus {
  ok,
  empty,           // nothing was saved into the snapshot
  other_kind,      // it was saved from a mode of another kind
  other_scenario,  // from another scenario, or one of another shape (length, horizon, delays)
  pilot,           // this mode's pilot source cannot continue from the saved one
  remote_vehicle,  // a remote vehicle flies this mode or flew the saved one: it cannot go back
  assistance,      // saved from a probe into an assisted flight, or the other way (SPEC §10)
  no_pilot,        // take_over(): this mode has no pilot to take the flight over
};
// The reason in words ("the snapshot is of another kind of mode"; "" for ok).
const char* to_string(RestoreStatus status);

// A mode's whole state at one step, saved by Mode::save() and put back by Mode::restore(). The
// caller owns it; it outlives the mode if need be. The first save into it sizes it (and allocates);
// saving a flight of the same scenario into it again allocates nothing.
class ModeSnapshot {
 public:
  // The part only the mode kind knows (each *_mode.cpp derives its own).
  struct State {
    virtual ~State() = default;
  };

  bool empty() const { return !state_; }
  ModeKind kind() const { return kind_; }
  const std::string& scenario_name() const { return scenario_name_; }
  std::int64_t step() const { return step_; }  // steps_done() when saved: the next step

 private:
  friend class Mode;
  ModeKind kind_ = ModeKind::mixed_initiative;
  std::string scenario_name_;
  std::int64_t steps_total_ = 0;
  std::int64_t step_ = 0;
  std::size_t next_forced_ = 0, next_miss_ = 0;  // replay_timing()'s cursors
  std::size_t next_command_ = 0;                 // replay_commands()' cursor
  std::unique_ptr<State> state_;
};

class Mode {
 public:
  virtual ~Mode() = default;

  virtual ModeKind kind() const = 0;
  virtual const std::string& scenario_name() const = 0;
  virtual double dt() const = 0;  // control period [s]
  virtual std::int64_t steps_total() const = 0;
  virtual std::int64_t steps_done() const = 0;

  // One control period: the controller, then the plant over Δt. Allocates nothing. Returns
  // false, doing nothing, once the run is over; telemetry() then describes the last step.
  [[nodiscard]] virtual bool step() = 0;
  virtual bool finished() const = 0;
  // The run ended because the vehicle was lost (non-finite state, or far outside its world).
  virtual bool lost() const = 0;
  virtual double lost_at() const = 0;  // [s] when, or −1

  // The last step's telemetry (before the first step: the initial state, solved = false).
  virtual const Telemetry& telemetry() const = 0;
  // The mode's metrics so far (the score in mixed initiative). Allocates: not for the loop.
  virtual Metrics metrics() const = 0;
  // What the mode shows of itself: its world, the view and the plots (core/modes/mode_view.hpp).
  // Allocates: not for the loop.
  virtual ModeView view() const = 0;
  // Who flies and what a user may pick instead (mode_view.hpp). Default: the controller flies.
  virtual ModeIdentity identity() const { return {}; }
  // The metrics of a replay whose RTI solves took `recorded_solve_us` [µs] per step when they
  // were flown: where the metrics hold timing fields they describe the recorded flight, not this
  // replay, so a flight and every replay of it agree to the bit on any machine. Default:
  // metrics().
  virtual Metrics replayed_metrics(const std::vector<double>& recorded_solve_us) const {
    (void)recorded_solve_us;
    return metrics();
  }
  // A few human-readable lines about the run so far, for the terminal. The first names the
  // scenario and mode; the front end that prints it puts its own label before it
  // ("mixpilot replay: ...").
  virtual std::string summary() const = 0;

  // Real-time runs (SPEC §4): a control step whose RTI solve takes longer than `deadline_us`
  // of wall time is discarded as a fallback and raises kEventOverrun. 0 (the default): no
  // deadline, so runs not paced by a clock stay deterministic.
  virtual void set_deadline_us(double deadline_us) = 0;
  // The mode's NMPC, for tools that watch the QPs it solves (RtiSolver::set_qp_observer:
  // mixpilot-bench's closed-loop QP sets); null when it flies none (an LQR law).
  virtual RtiSolver* rti_solver() { return nullptr; }
  // Flies the vehicle behind `link` (core/modes/vehicle_link.hpp) instead of the simulated
  // plant: after setup, before the first step. false: this mode has no remote vehicle.
  [[nodiscard]] virtual bool set_vehicle(VehicleLink* link) {
    (void)link;
    return false;
  }
  // Mixed initiative (SPEC §10 "Instructor bounds"): λ kept within `bounds` from the next step
  // on, below the input's own cap. false, changing nothing: this mode has no λ, or the bounds
  // are not valid (AuthorityBounds::valid()). Part of the flight: a snapshot saves them.
  [[nodiscard]] virtual bool set_authority_bounds(const AuthorityBounds& bounds) {
    (void)bounds;
    return false;
  }
  virtual AuthorityBounds authority_bounds() const { return {}; }

  // The instructor (SPEC §10, core/modes/instructor.hpp): `c` takes effect from the next step
  // on, which carries it in its telemetry (Telemetry::commands), so a recording holds it at
  // that step. Called between steps, on the thread that steps the mode (the session drains its
  // command inbox there); allocates nothing. Per kind:
  //   bounds       set_authority_bounds() (mixed initiative)
  //   gust         the simulated plant gets the world-frame force for `duration` from the next
  //                substep on; the controller's model knows nothing of it (quadrotor modes)
  //   extra delay  `delay` more between vehicle and controller (each mode says what it delays),
  //                until another extra delay replaces it (0 removes it)
  //   input loss   the pilot's input lost for `duration`, then recovered as SPEC §6 recovers a
  //                lost device (mixed initiative)
  //   marker, pause, resume, end   recorded only: the session pauses, resumes and ends
  // A command that cannot be applied changes nothing and says why; `busy` when the step holds
  // kMaxCommandsPerStep commands already (try again after the step).
  [[nodiscard]] InstructorStatus instruct(const InstructorCommand& c);
  // Whether this flight takes commands of `kind` (applied) or why not, without applying one:
  // what a script is checked against before the flight.
  virtual InstructorStatus accepts(InstructorCommandKind kind) const {
    switch (kind) {
      case InstructorCommandKind::bounds: return InstructorStatus::no_authority;
      case InstructorCommandKind::gust: return InstructorStatus::fixed_base;
      case InstructorCommandKind::extra_delay: return InstructorStatus::no_link;
      case InstructorCommandKind::input_loss: return InstructorStatus::no_pilot;
      default: return InstructorStatus::applied;
    }
  }
  // Commands taken for the next step so far.
  int commands_pending() const { return pending_count_; }
  // A replay: the recorded commands (ascending steps), each applied by instruct() as its step
  // starts, so the replayed steps carry and obey them as the recorded ones did.
  void replay_commands(std::vector<StepCommand> commands) {
    scheduled_ = std::move(commands);
    next_command_ = 0;
  }

  // The states its remote vehicle sends, for the link to check ({}: it has none).
  virtual VehicleStateSpec remote_state() const { return {}; }

  // A paced run (core/runtime/realtime_runner.hpp), before each step: how late the step
  // starts after its schedule and the wall-clock period it has [µs]. The step is then marked
  // kEventDeadlineMiss when its control input is ready after that period, or computing it took
  // longer than Δt (an overrun of the solve is always one). 0, 0 (the default): not paced.
  void set_pacing(double late_us, double period_us) {
    late_us_ = late_us;
    period_us_ = period_us;
  }

  // A replay of a flight that ended early (interrupted, or cut short): step() does nothing
  // from step `steps` on, while the mode keeps the flight's planned length, so its metrics
  // (progress against the whole reference, for one) are those of the flight as it was flown.
  void stop_after(std::int64_t steps) { stop_after_ = steps; }

  // A replay: what depended on the wall clock in the recorded flight, as it happened there.
  // The RTI solves of steps `overruns` are overruns (their fallbacks are reproduced bit for
  // bit) and steps `misses` missed their deadline (ascending step indices each).
  void replay_timing(std::vector<std::int64_t> overruns, std::vector<std::int64_t> misses = {}) {
    forced_overruns_ = std::move(overruns);
    forced_misses_ = std::move(misses);
    next_forced_ = next_miss_ = 0;
  }

  // Snapshots. save() copies everything the next step() reads into `snapshot`: the plant and
  // its delay lines, the sensor and estimators, the random generators, the controllers' warm
  // starts (the RTI iterates and multipliers, the QP's warm start), the safety net, the pilot
  // source's state, the metrics so far, the telemetry, the step counter. restore() puts it
  // back, into this mode or another one made from the same scenario (and the same pilot, or one
  // that takes over from any: a recording), and the steps from there on are bit for bit those
  // the saved flight flew from that step on. Neither allocates once the snapshot is sized (by
  // its first save); step() is untouched by them. What the caller sets, not the flight, is
  // neither saved nor restored: the deadline, the pacing, stop_after() and replay_timing()'s
  // lists (their cursors are restored, so give a fresh mode the same lists). restore() refuses,
  // changing nothing, a snapshot of another kind of mode or scenario (RestoreStatus).
  void save(ModeSnapshot& snapshot) const;
  [[nodiscard]] RestoreStatus restore(const ModeSnapshot& snapshot);
  // Fly from here (SPEC §10): the flight saved in `snapshot` goes on from its step k as a new
  // flight, with this mode's own pilot source taking over from the present
  // (PilotSource::take_over: an emulated pilot cold-starts its NMPC from the state at k, a
  // device reads from now) instead of continuing the saved source, and with the metrics
  // started afresh at k: the new flight is scored on its own steps. Everything else — plant,
  // sensor, estimators, the controller's warm start, the safety net, the telemetry, the step
  // counter — is restore()'s, with the same checks, so step k starts from the saved state bit
  // for bit. Allocates nothing once the snapshot is sized. A mode without a pilot has nothing to
  // take over: RestoreStatus::no_pilot.
  [[nodiscard]] RestoreStatus take_over(const ModeSnapshot& snapshot);

 protected:
  // The kind's part of save() and restore(). save_state() makes `state` when it is null (the
  // first save into a snapshot, or one of another kind) and copies into it; restore_state() is
  // given a state that this kind saved from a mode with the same scenario name and length,
  // checks the rest of its shape and copies it back, or refuses changing nothing.
  virtual void save_state(std::unique_ptr<ModeSnapshot::State>& state) const = 0;
  [[nodiscard]] virtual RestoreStatus restore_state(const ModeSnapshot::State& state) = 0;
  // take_over()'s part, given a state restore_state() would take. Default: no pilot.
  [[nodiscard]] virtual RestoreStatus take_over_state(const ModeSnapshot::State& state) {
    (void)state;
    return RestoreStatus::no_pilot;
  }
  // A mode that flies other modes in turn (a branch's replay: its parent's, then its own)
  // saves and restores the one flying as its own, and paces it as it is paced.
  static void save_state_of(const Mode& mode, std::unique_ptr<ModeSnapshot::State>& state) {
    mode.save_state(state);
  }
  [[nodiscard]] static RestoreStatus restore_state_of(Mode& mode,
                                                      const ModeSnapshot::State& state) {
    return mode.restore_state(state);
  }
  void pace_like_this(Mode& mode) const { mode.set_pacing(late_us_, period_us_); }

  // The instructor's commands in step(): begin_commands(k) first thing in step k (the replayed
  // commands of step k are applied), end_commands(telemetry) once the step's telemetry is set
  // (its commands and what is in force). Allocate nothing.
  void begin_commands(std::int64_t k);
  void end_commands(Telemetry& s);
  // The effects of instruct() that a mode kind provides (the defaults refuse: a mode without a
  // free-flying simulated plant, a link or a pilot — the Pendubot). Called with values in range.
  [[nodiscard]] virtual InstructorStatus apply_gust(const Eigen::Vector3d& force, double duration) {
    (void)force;
    (void)duration;
    return InstructorStatus::fixed_base;
  }
  [[nodiscard]] virtual InstructorStatus apply_extra_delay(double delay) {
    (void)delay;
    return InstructorStatus::no_link;
  }
  [[nodiscard]] virtual InstructorStatus apply_input_loss(double duration) {
    (void)duration;
    return InstructorStatus::no_pilot;
  }
  // What the commands keep in force during step k (the bounds are the base's to fill in).
  virtual InstructorInForce in_force(std::int64_t k) const {
    (void)k;
    return {};
  }

  // Whether restore() and take_over() can take `s` at all: saved, of this kind, scenario and
  // length (ok), or why not.
  RestoreStatus fits(const ModeSnapshot& s) const;
  // Whether a replay stops before step k (stop_after()).
  bool stopped_at(std::int64_t k) const { return stop_after_ >= 0 && k >= stop_after_; }
  // Whether step k's solve is a recorded overrun (asked with increasing k).
  bool forced_overrun(std::int64_t k) { return take(forced_overruns_, next_forced_, k); }
  // kEventDeadlineMiss for step k whose control input took `compute_us` from the step's start,
  // or whose solve overran its deadline (asked once per step, with increasing k), else 0.
  std::uint32_t deadline_event(std::int64_t k, double compute_us, bool overrun) {
    const bool recorded = take(forced_misses_, next_miss_, k);
    const bool late = period_us_ > 0.0 &&
                      (late_us_ + compute_us > period_us_ || compute_us > 1e6 * dt());
    return recorded || late || overrun ? kEventDeadlineMiss : 0u;
  }

 private:
  static bool take(const std::vector<std::int64_t>& steps, std::size_t& next, std::int64_t k) {
    // Forward as the steps go; back after a snapshot of an earlier step was restored.
    while (next > 0 && steps[next - 1] >= k) --next;
    while (next < steps.size() && steps[next] < k) ++next;
    return next < steps.size() && steps[next] == k;
  }

  std::vector<std::int64_t> forced_overruns_, forced_misses_;
  std::size_t next_forced_ = 0, next_miss_ = 0;
  std::vector<StepCommand> scheduled_;  // replay_commands()
  std::size_t next_command_ = 0;
  std::array<InstructorCommand, kMaxCommandsPerStep> pending_{};  // for the next step
  int pending_count_ = 0;
  double late_us_ = 0.0, period_us_ = 0.0;
  std::int64_t stop_after_ = -1;
};

}  // namespace mixpilot
