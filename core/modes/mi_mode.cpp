#include "core/modes/mi_mode.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/control/pilot_emulated.hpp"

namespace mixpilot {

namespace {

// Channel slots of the mixed-initiative telemetry.
enum MiChannel {
  kLambda,
  kDeviation,
  kBallRadius,
  kRollPilot,
  kRollMpc,
  kPitchPilot,
  kPitchMpc,
  kRotorSpeedMax,
  kRotorSpeedBound,
  kRtiTime,
  kPredictedDeviation,
  kClearance,
  kRttEstimate,
  kRttSample,
};


}  // namespace

SetupResult MiMode::setup(Scenario scenario, std::unique_ptr<PilotSource> pilot) {
  scenario_ = std::move(scenario);
  pilot_ = std::move(pilot);
  run_.finished = true;  // until setup succeeds
  if (!pilot_) return SetupResult::failure("no pilot source");
  if (scenario_.mode != "mixed_initiative" || scenario_.model != "mikrokopter")
    return SetupResult::failure("only mode 'mixed_initiative' on model 'mikrokopter' is supported");
  dt_ = scenario_.controller.dt;
  const double substeps = scenario_.plant.rate_hz * dt_;
  substeps_ = int(std::lround(substeps));
  if (substeps_ < 1 || std::abs(substeps - substeps_) > 1e-9)
    return SetupResult::failure("plant.rate_hz × controller.dt must be a whole number of substeps");
  model_ = models::MikroKopter{};
  if (SetupResult r = controller_.setup(model_, scenario_.controller, scenario_.arena,
                                        scenario_.reference);
      !r)
    return SetupResult::failure("the controller settings do not form a valid OCP: " + r.reason());
  if (SetupResult r = hover_.setup(model_, scenario_.controller.weights, dt_); !r)
    return SetupResult::failure("the safe controller cannot be set up: " + r.reason());
  run_.safety.reset();
  run_.command = model_.hover_input();
  run_.x = model_.hover_state(scenario_.reference.position(0.0));
  controller_.reset(run_.x);
  // The input delay in whole control periods; hover until the first command acts.
  using Simulated = SimulatedVehicle<models::MikroKopter>;
  Simulated::Settings plant;
  plant.substeps = substeps_;
  plant.h = dt_ / substeps_;
  plant.command_delay = std::lround(scenario_.plant.input_delay / dt_) * substeps_;
  plant.idle = Simulated::Idle::hovers;
  plant.position_noise = scenario_.plant.position_noise;
  plant.seed = scenario_.plant.seed;
  plant.max_extra_delay = std::lround(kMaxExtraDelay / plant.h);
  simulated_.setup(model_, plant, models::MikroKopter::State(run_.x));
  scorer_.setup(scenario_);
  run_.step = 0;
  steps_total_ = std::int64_t(std::lround(scenario_.duration / dt_));
  const int max_substeps = int(std::lround(VehicleFeed::kMaxRtt / (dt_ / substeps_)));
  remote_.setup(model_, dt_, substeps_, max_substeps, 2 * std::size_t(steps_total_) + 2,
                VehicleWorld::box(scenario_.arena.min, scenario_.arena.max,
                                  mi_defaults::kLostMargin),
                "it left the arena");
  run_.lost_reason = "";
  run_.finished = steps_total_ <= 0;
  run_.lost = false;
  run_.lost_at = -1.0;
  run_.loss_until = -1;
  run_.loss_rule = false;

  Telemetry& s = run_.telemetry;
  s = Telemetry{};
  s.mode = ModeKind::mixed_initiative;
  s.x = run_.x;
  s.x_measured = run_.x;
  s.u = model_.hover_input();
  s.reference = Eigen::VectorXd::Zero(3);
  set_reference(0.0);
  s.predicted = controller_.predicted_positions();
  s.predicted_reference = controller_.reference_positions();
  s.pilot.rotor_speed.setConstant(model_.hover_speed());
  s.applied = s.pilot;
  preview_first_step();
  return {};
}

bool MiMode::set_authority_bounds(const AuthorityBounds& bounds) {
  if (!bounds.valid()) return false;
  controller_.set_bounds(bounds);
  preview_first_step();
  return true;
}

void MiMode::preview_first_step() {
  if (run_.step != 0) return;
  Telemetry& s = run_.telemetry;
  // The pilot's input is not known yet: its cap (SPEC §6) shows from the first step on.
  const MiController::NextLambda next = controller_.next_lambda();
  s.lambda = next.lambda;
  s.reason = next.reason;
  s.instructor.bounds = controller_.bounds();
  set_channels();
}

// Lost: a non-finite state, or farther than mi_defaults::kLostMargin outside the arena.
bool MiMode::left_the_world() const {
  if (!run_.x.allFinite()) return true;
  const Arena& a = scenario_.arena;
  const Eigen::Vector3d p = run_.x.head<3>();
  return (p - p.cwiseMax(a.min).cwiseMin(a.max)).norm() > mi_defaults::kLostMargin;
}

// η^r(t), element by element: GCC 12 takes Eigen's packet copy of a Vector3d into a VectorXd
// for an out-of-bounds read (-Warray-bounds).
void MiMode::set_reference(double t) {
  const Eigen::Vector3d p = scenario_.reference.position(t);
  for (int i = 0; i < 3; ++i) run_.telemetry.reference(i) = p(i);
}

// The controller's view of the state: the true state, positions with noise if configured.
void MiMode::measure(double t) {
  Telemetry& s = run_.telemetry;
  s.step = run_.step;
  s.t = t;
  s.x = run_.x;
  models::MikroKopter::State y;
  simulated_.measure(run_.step, y);
  for (int i = 0; i < models::MikroKopter::nx; ++i) s.x_measured(i) = y(i);
}

// A remote vehicle's newest state (the last one known until one arrives), predicted over the
// estimated round-trip time; lost when it left the world (the arena's margin as
// left_the_world() measures it too) or the feed gave up on it.
void MiMode::measure_remote(double t) {
  using Remote = LinkedVehicle<models::MikroKopter>;
  Telemetry& s = run_.telemetry;
  s.step = run_.step;
  s.t = t;
  models::MikroKopter::State y = run_.x;
  const Remote::Reading r = remote_.read(run_.step, y);
  for (int i = 0; i < models::MikroKopter::nx; ++i) run_.x(i) = y(i);
  if (r.status == Remote::Status::left_world || left_the_world()) {
    run_.x = s.x;  // the last state known inside it
    run_.lost_reason = r.status == Remote::Status::left_world ? r.reason : "it left the arena";
  } else if (r.status == Remote::Status::lost) {
    run_.lost_reason = r.reason;
  }
  // What is known of the vehicle now: the state predicted to t_k, which the pilot sees, the
  // controller starts from and the score takes.
  y = run_.x;
  models::MikroKopter::State predicted;
  remote_.predict(y, predicted, r);
  for (int i = 0; i < models::MikroKopter::nx; ++i) run_.x(i) = predicted(i);
  s.x = run_.x;
  s.x_measured = run_.x;
}

void MiMode::set_channels() {
  Telemetry& s = run_.telemetry;
  const double deviation = (s.x.head<3>() - s.reference.head<3>()).norm();
  s.set_channel(kLambda, "lambda", "", s.lambda);
  s.set_channel(kDeviation, "deviation", "m", deviation);
  s.set_channel(kBallRadius, "ball radius r", "m", scenario_.controller.ph.r);
  s.set_channel(kRollPilot, "roll pilot", "rad", s.pilot.roll);
  s.set_channel(kRollMpc, "roll MPC", "rad", s.applied.roll);
  s.set_channel(kPitchPilot, "pitch pilot", "rad", s.pilot.pitch);
  s.set_channel(kPitchMpc, "pitch MPC", "rad", s.applied.pitch);
  s.set_channel(kRotorSpeedMax, "rotor speed max", "kHz", s.x.tail<4>().maxCoeff());
  s.set_channel(kRotorSpeedBound, "rotor speed bound", "kHz", model_.p.omega_max);
  s.set_channel(kRtiTime, "RTI time", "us", s.stats.total_us);
  // d_res of SPEC §5.4, which λ came from: the previous prediction's largest deviation.
  s.set_channel(kPredictedDeviation, "predicted deviation", "m", s.reason.d_res);
  // Of the vehicle sphere to the obstacles, walls and floor (the debrief's near misses).
  s.set_channel(kClearance, "clearance", "m", s.clearance);
  if (remote_.attached()) {
    s.set_channel(kRttEstimate, "RTT estimate", "s", remote_.rtt().estimate());
    s.set_channel(kRttSample, "RTT sample", "s", remote_.rtt().last_sample());
  }
}

bool MiMode::step() {
  if (run_.finished || stopped_at(run_.step)) return false;
  const auto started = std::chrono::steady_clock::now();
  begin_commands(run_.step);
  const double t = double(run_.step) * dt_;
  Telemetry& s = run_.telemetry;
  if (remote_.attached()) {
    measure_remote(t);
    if (*run_.lost_reason != '\0') {
      run_.lost = run_.finished = true;
      run_.lost_at = t;
      s.events = kEventLost;
      end_commands(s);
      remote_.finish();
      ++run_.step;
      return true;
    }
  } else {
    measure(t);
  }
  const InputState was = s.pilot.input;
  s.pilot.authority = 1.0;  // sources without a device leave these as they are
  s.pilot.input = InputState::ok;
  if (!pilot_->command(run_.step, t, run_.x, s.pilot)) {
    run_.finished = true;
    return false;
  }
  if (run_.loss_rule) lose_input(s.pilot);
  const JoyInput* joy = pilot_->joy();
  s.has_joy = joy != nullptr;
  if (joy) s.joy = *joy;
  if (forced_overrun(run_.step)) controller_.rti().force_overrun_next();
  controller_.step(t, s.x_measured, s.pilot);
  s.solved = true;
  s.lambda = controller_.lambda();
  s.reason = controller_.reason();
  s.applied = controller_.applied_command();
  set_reference(t);
  s.stats = controller_.rti().stats();
  s.predicted = controller_.predicted_positions();
  s.predicted_reference = controller_.reference_positions();
  // The MPC's plan spent: the safe controller holds the position where it took over, and the
  // pilot has no authority meanwhile.
  const bool safe = run_.safety.update(s.stats.status != RtiStatus::success);
  if (safe) {
    if (run_.safety.switched()) run_.hold = s.x_measured.head<3>();
    hover_.control(s.x_measured, run_.hold, run_.u_safe);
    s.lambda = 0.0;
    s.reason.cap = LambdaCap::safe_hold;
    run_.command = run_.u_safe;
  } else {
    run_.command = controller_.control();
  }
  const double compute_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - started).count();

  if (remote_.attached()) {
    // The command leaves at once: the link is the delay line.
    s.u = run_.command;
    remote_.send(run_.step, models::MikroKopter::Input(s.u));
  } else {
    // The command enters the delay line; the rotors get the one sent input_delay ago.
    simulated_.send(run_.step, models::MikroKopter::Input(run_.command));
    s.u = simulated_.acting(long(run_.step) * substeps_);
  }
  s.events = s.stats.status == RtiStatus::fallback ? kEventFallback : 0u;
  if (s.stats.overrun) s.events |= kEventOverrun;
  if (safe) s.events |= kEventSafeHold;
  if (run_.safety.switched()) s.events |= kEventSwitch;
  s.events |= deadline_event(run_.step, compute_us, s.stats.overrun);
  if (s.pilot.input == InputState::lost && was != InputState::lost) s.events |= kEventInputLost;
  if (scorer_.add(s)) s.events |= kEventCollision;
  s.clearance = scorer_.clearance();
  set_channels();
  end_commands(s);

  if (remote_.attached()) {
    ++run_.step;
    if (run_.step >= steps_total_) {
      run_.finished = true;
      remote_.finish();
    }
    return true;
  }
  // The plant over the period, the input held (RK4 at the plant rate).
  const long end = long(run_.step + 1) * substeps_;
  simulated_.integrate_to(end);
  run_.x = simulated_.at(end);
  ++run_.step;
  if (left_the_world()) {
    if (!run_.x.allFinite()) run_.x = s.x;  // never hand a non-finite state to anyone
    run_.lost = run_.finished = true;
    run_.lost_at = double(run_.step) * dt_;
    s.events |= kEventLost;
  }
  if (run_.step >= steps_total_) run_.finished = true;
  return true;
}

struct MiMode::Saved final : ModeSnapshot::State {
  RtiState rti;                      // the MPC's warm start
  MiController::Outputs controller;  // λ for the next step, the last plan's outputs
  ScoreAccumulator::Sums score;
  Run run;
  SimulatedVehicle<models::MikroKopter>::Data vehicle;
  std::unique_ptr<PilotState> pilot;  // null: the source keeps nothing, or cannot go back
  bool remote = false;
  bool assisted = true;  // false: a probe (SPEC §10)
};

void MiMode::save_state(std::unique_ptr<ModeSnapshot::State>& state) const {
  if (!state) state = std::make_unique<Saved>();
  Saved& s = static_cast<Saved&>(*state);  // Mode::save() replaced a state of another kind
  s.rti = controller_.rti().state();
  s.controller = controller_.outputs();
  s.score = scorer_.sums();
  s.run = run_;
  s.vehicle = simulated_.data();
  if (pilot_) pilot_->save(s.pilot);
  s.remote = remote_.attached();
  s.assisted = controller_.assisted();
}

RestoreStatus MiMode::check_saved(const Saved& s) const {
  if (s.remote || remote_.attached()) return RestoreStatus::remote_vehicle;
  if (!controller_.rti().fits(s.rti) || !simulated_.fits(s.vehicle) ||
      s.controller.predicted.cols() != controller_.outputs().predicted.cols())
    return RestoreStatus::other_scenario;
  // λ pinned to 1 or not is the controller's setup, not its state: the steps would differ.
  if (s.assisted != controller_.assisted()) return RestoreStatus::assistance;
  if (!pilot_) return RestoreStatus::pilot;
  return RestoreStatus::ok;
}

void MiMode::put_back(const Saved& s) {
  controller_.rti().restore(s.rti);
  controller_.restore(s.controller);
  scorer_.restore(s.score);
  run_ = s.run;
  simulated_.restore(s.vehicle);
}

RestoreStatus MiMode::restore_state(const ModeSnapshot::State& state) {
  const Saved& s = static_cast<const Saved&>(state);  // Mode::restore() checked the kind
  if (const RestoreStatus r = check_saved(s); r != RestoreStatus::ok) return r;
  if (!pilot_->restore(s.pilot.get())) return RestoreStatus::pilot;
  put_back(s);
  return RestoreStatus::ok;
}

RestoreStatus MiMode::take_over_state(const ModeSnapshot::State& state) {
  const Saved& s = static_cast<const Saved&>(state);  // Mode::take_over() checked the kind
  if (const RestoreStatus r = check_saved(s); r != RestoreStatus::ok) return r;
  put_back(s);
  // SPEC §10: the new flight is scored on its own steps, from the snapshot's step on.
  scorer_.restart(run_.step);
  pilot_->take_over();
  // An instructor's input loss in force goes on with the new source, as that source does it.
  if (run_.loss_until >= 0) run_.loss_rule = !pilot_->lose_input(run_.loss_until);
  return RestoreStatus::ok;
}

InstructorStatus MiMode::apply_gust(const Eigen::Vector3d& force, double duration) {
  if (remote_.attached()) return InstructorStatus::remote_vehicle;
  simulated_.gust(force, std::lround(duration / simulated_.settings().h));
  return InstructorStatus::applied;
}

InstructorStatus MiMode::apply_extra_delay(double delay) {
  if (remote_.attached()) return InstructorStatus::remote_vehicle;
  simulated_.set_extra_delay(std::lround(delay / simulated_.settings().h));
  return InstructorStatus::applied;
}

InstructorStatus MiMode::apply_input_loss(double duration) {
  run_.loss_until = run_.step + std::max(1L, std::lround(duration / dt_));
  run_.loss_rule = !pilot_->lose_input(run_.loss_until);
  return InstructorStatus::applied;
}

InstructorInForce MiMode::in_force(std::int64_t k) const {
  InstructorInForce f;
  if (!remote_.attached()) {
    const double h = simulated_.settings().h;
    const long left = simulated_.gust_left(long(k) * substeps_);
    if (left > 0) {
      f.gust = simulated_.data().gust;
      f.gust_left = double(left) * h;
    }
    f.extra_delay = double(simulated_.extra_delay()) * h;
  }
  f.input_loss_left = double(std::max<std::int64_t>(0, run_.loss_until - k)) * dt_;
  return f;
}

// SPEC §6's rule for a source without a device: lost before loss_until (a neutral command of no
// weight), then the authority ramps back linearly over kInputReturnS, counted in steps so it
// ends exactly then. A function of the step alone: a snapshot or a take-over continues it.
void MiMode::lose_input(PilotCommand& pilot) const {
  const std::int64_t k = run_.step;
  if (k < run_.loss_until) {
    pilot.roll = pilot.pitch = 0.0;
    pilot.rotor_speed.setConstant(model_.hover_speed());
    pilot.authority = 0.0;
    pilot.input = InputState::lost;
    return;
  }
  const double ramp = double(k - run_.loss_until + 1) * dt_;
  if (ramp >= kInputReturnS - 1e-9 * dt_) return;
  pilot.authority = std::min(pilot.authority, ramp / kInputReturnS);
  pilot.input = InputState::returning;
}

Metrics MiMode::metrics() const {
  Metrics m = to_metrics(score());
  if (remote_.attached()) {
    m.emplace_back("rtt_s", remote_.feed().measured_median());
    m.emplace_back("rtt_estimated_s", remote_.rtt().estimate());
  }
  return m;
}

ModeView MiMode::view() const {
  ModeView v;
  v.shared_authority = true;
  v.arena_min = scenario_.arena.min;
  v.arena_max = scenario_.arena.max;
  for (const Obstacle& o : scenario_.arena.obstacles) v.spheres.push_back({o.center, o.radius});
  const Scenario& sc = scenario_;
  v.reference = sample_path(sc.duration, [&sc](double t) { return sc.reference.position(t); });
  v.reference_at = [helix = sc.reference](double tau) { return helix.position(tau); };
  v.ball_radius = sc.controller.ph.r;
  v.vehicle_radius = sc.controller.vehicle_radius;
  v.hover_rotor_speed = model_.hover_speed();
  using R = SeriesRole;
  v.plots = {{"authority λ", {{"lambda", R::pilot}}},
             {"deviation |p − η_r| vs r",
              {{"deviation", R::pilot},
               {"predicted deviation", R::other},
               {"ball radius r", R::soft_limit}}},
             {"roll φ_h vs φ*₁", {{"roll pilot", R::pilot}, {"roll MPC", R::applied}}},
             {"pitch θ_h vs θ*₁", {{"pitch pilot", R::pilot}, {"pitch MPC", R::applied}}},
             {"rotor speed Ω vs bound",
              {{"rotor speed max", R::applied}, {"rotor speed bound", R::hard_limit}}},
             {"RTI time", {{"RTI time", R::timing}}}};
  return v;
}

ModeIdentity MiMode::identity() const {
  ModeIdentity id;
  id.pilot = pilot_->name();
  for (const auto& entry : scenario_.pilots) id.pilots.push_back(entry.first);
  id.seed = scenario_.plant.seed;
  id.probe = !controller_.assisted();
  return id;
}

Metrics MiMode::replayed_metrics(const std::vector<double>& recorded_solve_us) const {
  Score s = score();
  // The steps scored: all of them, or a branch's own from its take-over on (whose recording
  // holds those steps' solver statistics alone).
  const std::size_t n = std::min(recorded_solve_us.size(), scorer_.sums().lambda.size());
  // The deadline misses are replayed as recorded (replay_timing()).
  set_timing(s, std::vector<double>(recorded_solve_us.begin(), recorded_solve_us.begin() + std::ptrdiff_t(n)),
             s.deadline_misses);
  return to_metrics(s);
}

std::string MiMode::summary() const {
  const Score s = score();
  char buf[768];
  std::snprintf(buf, sizeof buf,
                "%s, pilot %s\n"
                "  flew %.1f s; RTI median %.0f us, p99 %.0f us, %d deadline misses, %lld "
                "fallbacks\n"
                "  lambda mean %.3f (min %.3f); assistance dependence D %.3f; deviation max "
                "%.3f m, rms %.3f m; in ball %.1f%%; progress %.1f%%\n"
                "  collisions %d; min clearance %.3f m; override %.4f rad rms; skill %.1f / 100\n",
                scenario_.name.c_str(), pilot_ ? pilot_->name().c_str() : "?", s.duration_s,
                s.rti_median_us, s.rti_p99_us, s.deadline_misses,
                static_cast<long long>(s.fallbacks), s.mean_lambda, s.min_lambda,
                s.assistance_dependence, s.max_deviation_m, s.rms_deviation_m,
                100.0 * s.time_in_ball, 100.0 * s.progress, s.collisions, s.min_clearance_m,
                s.override_rms, s.skill);
  std::string out = buf;
  if (s.input_lost_s > 0.0) {
    std::snprintf(buf, sizeof buf,
                  "  the pilot's input was lost for %.2f s in all: the planner flew meanwhile\n",
                  s.input_lost_s);
    out += buf;
  }
  out += safe_hold_summary(run_.safety, dt_, "a hover-hold controller");
  if (run_.lost && remote_.attached()) {
    std::snprintf(buf, sizeof buf, "  the remote vehicle was lost at t = %.3f s: %s\n",
                  run_.lost_at, run_.lost_reason);
    out += buf;
  } else if (run_.lost) {
    std::snprintf(buf, sizeof buf,
                  "  the vehicle was lost at t = %.3f s: it left the arena by more than %.1f m or "
                  "its state stopped being finite\n",
                  run_.lost_at, mi_defaults::kLostMargin);
    out += buf;
  }
  const VehicleFeed& feed = remote_.feed();
  if (remote_.attached() && feed.sample_count() == 0) {
    out += "  remote vehicle: no round trip measured\n";
  } else if (remote_.attached()) {
    std::snprintf(buf, sizeof buf, "  remote vehicle: RTT %.1f ms measured, %.1f ms estimated\n",
                  1e3 * feed.measured_median(), 1e3 * feed.rtt().estimate());
    out += buf;
  }
  return out;
}

std::unique_ptr<PilotSource> make_scenario_pilot(const Scenario& scenario, const std::string& name,
                                                 std::string& error) {
  const models::MikroKopter model;
  if (name == "reckless") {
    const auto it = scenario.pilots.find("reckless");
    const double tilt = it != scenario.pilots.end() ? it->second.max_tilt : PilotProfile{}.max_tilt;
    return std::make_unique<RecklessPilot>(model, scenario.arena, tilt);
  }
  const auto it = scenario.pilots.find(name);
  if (it == scenario.pilots.end()) {
    error = "unknown pilot '" + name + "': the scenario defines";
    for (const auto& [profile, _] : scenario.pilots) error += " " + profile;
    error += ", plus reckless and RECORDING.mcap";
    return nullptr;
  }
  auto pilot = std::make_unique<EmulatedPilot>();
  PilotProfile profile = it->second;
  profile.name = name;
  if (SetupResult r = pilot->setup(model, profile, scenario.reference, scenario.controller.dt);
      !r) {
    error = "pilot profile '" + name + "' does not form a valid OCP: " + r.reason();
    return nullptr;
  }
  return pilot;
}

// What a state may hold before it is not one (input/net/peer_checks.hpp): positions well
// beyond any world, speeds and rates no quadrotor reaches; Euler angles integrate freely, so
// only their size is bounded; rotor speeds a hundred times their limit.
VehicleStateSpec MiMode::remote_state() const {
  VehicleStateSpec spec;
  spec.nx = models::MikroKopter::nx;
  const auto set = [&](int from, int n, double bound) {
    for (int i = from; i < from + n; ++i) spec.max_abs[std::size_t(i)] = bound;
  };
  set(0, 3, 1e4);
  set(3, 3, 1e6);
  set(6, 3, 1e3);
  set(9, 3, 1e4);
  set(12, 4, 100 * model_.p.omega_max);
  return spec;
}

}  // namespace mixpilot
