#include "core/modes/obstacle_mode.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "core/numerics/stats.hpp"

namespace mixpilot {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Channel slots of the obstacle-avoidance telemetry.
enum ObstacleChannel {
  kMinDistance,     // min over obstacles and this step's plant substeps of ‖p − o‖ (∞: none)
  kClearanceMargin, // that minus d_C: negative when the path cut the clearance sphere
  kTrackingError,   // ‖p_k − p_ref,k‖ at t_k
  kQpIterations,
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Setup

SetupResult ObstacleMode::setup(ObstacleScenario scenario, std::optional<ObstacleForm> form) {
  scenario_ = std::move(scenario);
  settings_ = scenario_.controller;
  if (form) settings_.form = *form;
  run_.finished = true;  // until setup succeeds
  ready_ = false;
  run_.lost = false;
  run_.lost_at = -1.0;
  run_.step = 0;
  steps_total_ = 0;
  problem_.emplace(scenario_.world.size(), settings_);
  if (SetupResult r = rti_.setup(problem_->ocp()); !r)
    return SetupResult::failure("controller: " + r.reason());
  if (SetupResult r = check_scenario(); !r) return r;
  if (SetupResult r = safe_lqr_.setup(model_, settings_.dt); !r)
    return SetupResult::failure("the safe controller: " + r.reason());
  run_.safety.reset();

  const OcpTrajectory& ref = scenario_.reference.trajectory;
  last_x_ = int(ref.x.size()) - 1;
  substeps_ = int(std::lround(settings_.dt * scenario_.plant_rate_hz));
  steps_total_ = std::lround(scenario_.duration / settings_.dt);
  run_.x = ref.x[0];
  SimulatedVehicle<models::Crazyflie>::Settings plant;
  plant.substeps = substeps_;
  plant.h = settings_.dt / substeps_;
  plant.max_extra_delay = std::lround(kMaxExtraDelay / plant.h);
  simulated_.setup(model_, plant, run_.x);
  warm_start();
  run_.rti_us.clear();
  run_.rti_us.reserve(std::size_t(std::max<std::int64_t>(steps_total_, 0)));
  run_.min_distance = kInf;
  run_.min_distance_time = 0.0;
  run_.closest_obstacle = -1;
  run_.min_distance_control = kInf;
  run_.violations = 0;
  run_.sq_tracking = 0.0;
  run_.qp_iterations_max = 0;

  reset_telemetry();
  bool violated = false;
  const double distance = check_distances(0.0, violated);
  if (violated) ++run_.violations;
  check_control_instant(0.0);
  set_channels(distance, (run_.x.head<3>() - ref.x[0].head<3>()).norm());
  ready_ = true;
  run_.finished = steps_total_ <= 0;
  return {};
}

// What the loader checks, for scenarios built in code: the loop indexes the reference and
// divides Δt into substeps.
SetupResult ObstacleMode::check_scenario() const {
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  if (ref.x.empty()) return SetupResult::failure("reference: no states");
  for (const Eigen::VectorXd& x : ref.x)
    if (x.size() != ObstacleAvoidanceOcp::nx)
      return SetupResult::failure("reference: expected Crazyflie states (13 entries)");
  for (const Eigen::VectorXd& u : ref.u)
    if (u.size() != ObstacleAvoidanceOcp::nu)
      return SetupResult::failure("reference: expected Crazyflie inputs (4 entries)");
  const double substeps = settings_.dt * scenario_.plant_rate_hz;
  if (!(std::lround(substeps) >= 1) || std::abs(substeps - std::round(substeps)) > 1e-9 * substeps)
    return SetupResult::failure("plant.rate_hz × controller.dt must be a whole number ≥ 1");
  return {};
}

// The reference itself (obstacle-free) from its first state; hover past its last input.
void ObstacleMode::warm_start() {
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  OcpTrajectory& traj = rti_.trajectory();
  for (int i = 0; i <= settings_.N; ++i) traj.x[i] = ref.x[std::min(i, last_x_)];
  for (int i = 0; i < settings_.N; ++i) {
    if (i < int(ref.u.size()))
      traj.u[i] = ref.u[i];
    else
      traj.u[i] = problem_->model().hover_input();
  }
}

// Sizes every telemetry member for the run: the initial state, the warm start as prediction.
void ObstacleMode::reset_telemetry() {
  Telemetry& s = run_.telemetry;
  s = Telemetry{};
  s.mode = ModeKind::obstacle_avoidance;
  s.x = run_.x;
  s.x_measured = run_.x;
  s.u = problem_->model().hover_input();
  s.reference = Eigen::VectorXd::Zero(3);
  s.predicted = Eigen::Matrix3Xd::Zero(3, settings_.N + 1);
  s.predicted_reference = Eigen::Matrix3Xd::Zero(3, settings_.N + 1);
  // Step 0 sets the same stage data again: this only shows its reference before the start.
  problem_->set_reference(rti_.data(), scenario_.reference.trajectory, 0);
  problem_->set_obstacles(rti_.data(), scenario_.world, 0.0);
  set_reference_position(0);
  set_predictions();
}

// ---------------------------------------------------------------------------------------------
// One control period

bool ObstacleMode::step() {
  if (run_.finished || stopped_at(run_.step)) return false;
  begin_commands(run_.step);
  const auto started = std::chrono::steady_clock::now();
  const int k = int(run_.step);
  const double t = k * settings_.dt;
  // The state the NMPC starts from: the true one, or the one the extra delay lets through.
  if (simulated_.extra_delay() > 0) simulated_.measure(run_.step, run_.y);
  else run_.y = run_.x;
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  problem_->set_reference(rti_.data(), ref, k);
  problem_->set_obstacles(rti_.data(), scenario_.world, t);
  rti_.prepare();
  if (forced_overrun(run_.step)) rti_.force_overrun_next();
  rti_.feedback(run_.y);
  const RtiStats& st = rti_.stats();
  run_.rti_us.push_back(st.total_us);
  run_.qp_iterations_max = std::max(run_.qp_iterations_max, st.qp_iterations);
  models::Crazyflie::Input u = rti_.control();
  // The plan spent after fallbacks in a row: hover-hold where the safe controller took over.
  const bool safe = run_.safety.update(st.status != RtiStatus::success);
  if (safe) {
    if (run_.safety.switched()) run_.hold = model_.hover_state(run_.y.head<3>());
    safe_lqr_.control(run_.y, run_.hold, model_.hover_input(), u);
  }
  const double compute_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - started).count();

  Telemetry& s = run_.telemetry;
  s.step = run_.step;
  s.t = t;
  s.x = run_.x;
  s.x_measured = run_.y;
  s.u = u;
  s.solved = true;
  s.stats = st;
  set_reference_position(k);
  set_predictions();
  const double sq_error = (run_.x.head<3>() - ref.x[std::min(k, last_x_)].head<3>()).squaredNorm();
  run_.sq_tracking += sq_error;

  bool violated = false;
  const double distance = plant_step(u, t, violated);
  if (violated) ++run_.violations;
  check_control_instant(t + settings_.dt);
  ++run_.step;
  s.events = st.status == RtiStatus::fallback ? kEventFallback : 0u;
  if (st.overrun) s.events |= kEventOverrun;
  if (safe) s.events |= kEventSafeHold;
  if (run_.safety.switched()) s.events |= kEventSwitch;
  s.events |= deadline_event(s.step, compute_us, st.overrun);
  if (violated) s.events |= kEventViolation;
  set_channels(distance, std::sqrt(sq_error));
  end_commands(s);
  if (!run_.x.allFinite()) {  // never hand a non-finite state to anyone
    run_.x = s.x;
    run_.lost = run_.finished = true;
    run_.lost_at = t;
    s.events |= kEventLost;
    return true;
  }
  rti_.shift();
  if (run_.step >= steps_total_) run_.finished = true;
  return true;
}

InstructorStatus ObstacleMode::apply_gust(const Eigen::Vector3d& force, double duration) {
  simulated_.gust(force, std::lround(duration / simulated_.settings().h));
  return InstructorStatus::applied;
}

InstructorStatus ObstacleMode::apply_extra_delay(double delay) {
  simulated_.set_extra_delay(std::lround(delay / simulated_.settings().h));
  return InstructorStatus::applied;
}

InstructorInForce ObstacleMode::in_force(std::int64_t k) const {
  InstructorInForce f;
  const double h = simulated_.settings().h;
  const long left = simulated_.gust_left(long(k) * substeps_);
  if (left > 0) {
    f.gust = simulated_.data().gust;
    f.gust_left = double(left) * h;
  }
  f.extra_delay = double(simulated_.extra_delay()) * h;
  return f;
}

// RK4 at the plant rate with u held over [t, t + Δt], the distances checked after every
// substep. Returns the smallest distance of the step; `violated` when one is below d_C − 1 mm.
double ObstacleMode::plant_step(const models::Crazyflie::Input& u, double t, bool& violated) {
  const double h = settings_.dt / substeps_;
  const long j0 = long(run_.step) * substeps_;
  simulated_.send(run_.step, u);
  double distance = kInf;
  for (int s = 0; s < substeps_; ++s) {
    simulated_.integrate_to(j0 + s + 1);
    run_.x = simulated_.at(j0 + s + 1);
    distance = std::min(distance, check_distances(t + (s + 1) * h, violated));
  }
  return distance;
}

// Distance of the vehicle to every obstacle at time t, into the run's minimum. Returns the
// smallest; sets `violated` when one is below d_C − 1 mm.
double ObstacleMode::check_distances(double t, bool& violated) {
  double smallest = kInf;
  for (int j = 0; j < scenario_.world.size(); ++j) {
    const double dist = (run_.x.head<3>() - scenario_.world.position(j, t)).norm();
    if (dist < run_.min_distance) {
      run_.min_distance = dist;
      run_.min_distance_time = t;
      run_.closest_obstacle = j;
    }
    smallest = std::min(smallest, dist);
    violated |= dist < settings_.clearance - obstacle_defaults::kViolationTolerance;
  }
  return smallest;
}

// The same at a control instant, where the constraint is imposed.
void ObstacleMode::check_control_instant(double t) {
  for (int j = 0; j < scenario_.world.size(); ++j)
    run_.min_distance_control = std::min(
        run_.min_distance_control, (run_.x.head<3>() - scenario_.world.position(j, t)).norm());
}

// η^r(t_k) = the reference position of step k (clamped to the last state), element by element
// (a fixed-size segment into a VectorXd: no temporary).
void ObstacleMode::set_reference_position(int k) {
  const Eigen::VectorXd& r = scenario_.reference.trajectory.x[std::min(k, last_x_)];
  for (int i = 0; i < 3; ++i) run_.telemetry.reference(i) = r(i);
}

// Predicted positions of the RTI trajectory and the reference positions at the N + 1 nodes.
void ObstacleMode::set_predictions() {
  const OcpTrajectory& traj = rti_.trajectory();
  const OcpStageData& data = rti_.data();
  for (int i = 0; i <= settings_.N; ++i) {
    run_.telemetry.predicted.col(i) = traj.x[i].head<3>();
    run_.telemetry.predicted_reference.col(i) = data.yref[i].head<3>();
  }
}

void ObstacleMode::set_channels(double step_min_distance, double tracking_error) {
  Telemetry& s = run_.telemetry;
  s.set_channel(kMinDistance, "min distance", "m", step_min_distance);
  s.set_channel(kClearanceMargin, "clearance margin", "m",
                step_min_distance - settings_.clearance);
  s.set_channel(kTrackingError, "tracking error", "m", tracking_error);
  s.set_channel(kQpIterations, "QP iterations", "", double(s.stats.qp_iterations));
}

// ---------------------------------------------------------------------------------------------
// Results

struct ObstacleMode::Saved final : ModeSnapshot::State {
  RtiState rti;  // the NMPC's warm start
  SimulatedVehicle<models::Crazyflie>::Data vehicle;
  Run run;
};

void ObstacleMode::save_state(std::unique_ptr<ModeSnapshot::State>& state) const {
  if (!state) state = std::make_unique<Saved>();
  Saved& s = static_cast<Saved&>(*state);  // Mode::save() replaced a state of another kind
  s.rti = rti_.state();
  s.vehicle = simulated_.data();
  s.run = run_;
}

RestoreStatus ObstacleMode::restore_state(const ModeSnapshot::State& state) {
  const Saved& s = static_cast<const Saved&>(state);  // Mode::restore() checked the kind
  if (!ready_ || !rti_.fits(s.rti) || !simulated_.fits(s.vehicle) ||
      s.run.telemetry.predicted.cols() != run_.telemetry.predicted.cols())
    return RestoreStatus::other_scenario;
  rti_.restore(s.rti);
  simulated_.restore(s.vehicle);
  run_ = s.run;
  return RestoreStatus::ok;
}

ObstacleRunResult ObstacleMode::result() const {
  ObstacleRunResult r;
  r.form = settings_.form;
  if (!ready_) {
    r.error = "not set up";
    return r;
  }
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  r.steps = int(run_.step);
  r.min_distance_m = run_.min_distance;
  r.min_margin_m = run_.min_distance - settings_.clearance;
  r.min_distance_control_m = run_.min_distance_control;
  r.min_distance_time = run_.min_distance_time;
  r.closest_obstacle = run_.closest_obstacle;
  r.violations = run_.violations;
  r.tracking_rms_m = r.steps > 0 ? std::sqrt(run_.sq_tracking / r.steps) : 0.0;
  r.final_error_m = (run_.x.head<3>() - ref.x[last_x_].head<3>()).norm();
  r.rti_median_us = percentile(run_.rti_us, 0.5);
  r.rti_p99_us = percentile(run_.rti_us, 0.99);
  const std::vector<double>& rti_us = run_.rti_us;
  r.rti_max_us = rti_us.empty() ? 0.0 : *std::max_element(rti_us.begin(), rti_us.end());
  r.fallbacks = int(rti_.stats().fallbacks);
  r.lost = run_.lost;
  r.qp_iterations_max = run_.qp_iterations_max;
  return r;
}

Metrics ObstacleMode::metrics() const {
  const ObstacleRunResult r = result();
  return {
      {"min_distance_m", r.min_distance_m},
      {"min_margin_m", r.min_margin_m},
      {"min_distance_control_m", r.min_distance_control_m},
      {"clearance_m", settings_.clearance},
      {"violations", double(r.violations)},
      {"tracking_rms_m", r.tracking_rms_m},
      {"final_error_m", r.final_error_m},
      {"rti_median_us", r.rti_median_us},
      {"rti_p99_us", r.rti_p99_us},
      {"fallbacks", double(r.fallbacks)},
      {"form", r.form == ObstacleForm::lcl ? 0.0 : 1.0},
      {"steps", double(r.steps)},
  };
}

ModeView ObstacleMode::view() const {
  ModeView v;
  const ObstacleWorld& w = scenario_.world;
  const double r = settings_.clearance;
  for (const auto& c : w.spheres) v.spheres.push_back({c, r});
  if (!w.balls.empty()) {
    const int first = int(w.spheres.size());
    v.moving = [world = w, first](double t, std::vector<Eigen::Vector3d>& centers) {
      centers.clear();
      for (int j = first; j < world.size(); ++j) centers.push_back(world.position(j, t));
    };
    v.moving_radius = r;
  }
  v.reference = positions_of(scenario_.reference.trajectory);
  fit_arena(v, v.reference, 1.0);
  return v;
}

std::string ObstacleMode::summary() const {
  const ObstacleRunResult r = result();
  char buf[768];
  std::snprintf(buf, sizeof buf,
                "%s (obstacle_avoidance, SPEC 5.3), form %s, %zu spheres, %zu balls, %d steps "
                "of %.0f ms\n"
                "  min distance %.4f m (d_C %.3f m, margin %+.4f m) at t = %.3f s (obstacle %d), "
                "%.4f m at the control instants; violations %d\n"
                "  tracking rms %.3f m, final error %.3f m; RTI median %.0f us, p99 %.0f us, "
                "max %.0f us; fallbacks %d%s\n",
                scenario_.name.c_str(), to_string(r.form), scenario_.world.spheres.size(),
                scenario_.world.balls.size(), r.steps, 1e3 * settings_.dt, r.min_distance_m,
                settings_.clearance, r.min_margin_m, r.min_distance_time, r.closest_obstacle,
                r.min_distance_control_m, r.violations, r.tracking_rms_m, r.final_error_m,
                r.rti_median_us, r.rti_p99_us, r.rti_max_us, r.fallbacks,
                r.lost ? "\n  the vehicle was lost" : "");
  return buf + safe_hold_summary(run_.safety, settings_.dt, "a hover-hold LQR");
}

// ---------------------------------------------------------------------------------------------
// Whole runs

ObstacleRunResult run_obstacle_avoidance(const ObstacleScenario& scenario,
                                         const ObstacleRunOptions& options) {
  ObstacleScenario sc = scenario;
  if (options.duration) sc.duration = *options.duration;
  ObstacleMode mode;
  if (SetupResult setup = mode.setup(std::move(sc), options.form); !setup) {
    ObstacleRunResult failed;
    failed.error = setup.reason();
    return failed;
  }
  std::vector<Eigen::Vector3d> positions;
  std::vector<double> step_us;
  std::vector<int> step_qp_iterations, step_status;
  if (options.keep_trajectory) {
    const std::size_t n = std::size_t(mode.steps_total());
    positions.reserve(n + 1);
    step_us.reserve(n);
    step_qp_iterations.reserve(n);
    step_status.reserve(n);
  }
  while (mode.step()) {
    if (!options.keep_trajectory) continue;
    const Telemetry& s = mode.telemetry();
    positions.push_back(s.x.head<3>());
    step_us.push_back(s.stats.total_us);
    step_qp_iterations.push_back(s.stats.qp_iterations);
    step_status.push_back(int(s.stats.status));
  }
  ObstacleRunResult r = mode.result();
  if (options.keep_trajectory) {
    positions.push_back(mode.state().head<3>());
    r.positions = std::move(positions);
    r.step_us = std::move(step_us);
    r.step_qp_iterations = std::move(step_qp_iterations);
    r.step_status = std::move(step_status);
  }
  return r;
}


}  // namespace mixpilot
