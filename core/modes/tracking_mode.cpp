#include "core/modes/tracking_mode.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/numerics/stats.hpp"

namespace mixpilot {

namespace {

// Channel slots of the tracking telemetry.
enum TrackingChannel {
  kTrackingError,
  kRtt,
  kPredictorTime,
  kControllerTime,
  kRotorSpeed1,  // .. kRotorSpeed1 + 3
  kRotorSpeedBound = kRotorSpeed1 + 4,
  kCompensation,
  kRttSample,
  kHorizon,
};


constexpr const char* kRotorSpeedNames[4] = {"rotor speed 1", "rotor speed 2", "rotor speed 3",
                                             "rotor speed 4"};

double microseconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
}

// ‖p − p_ref‖ on 3-vectors: the error of a sample and of the telemetry, evaluated alike.
double position_error(const Eigen::Vector3d& p, const Eigen::Vector3d& p_ref) {
  return (p - p_ref).norm();
}

}  // namespace

SetupResult TrackingMode::setup(TrackingScenario scenario) {
  scenario_ = std::move(scenario);
  ok_ = run_.lost = false;
  run_.finished = true;  // until setup succeeds
  run_.lost_at = -1.0;
  run_.step = steps_total_ = 0;
  problem_.reset();
  rti_.reset();
  const TrackingControllerSettings& c = scenario_.controller;
  const TrackingPlantSettings& pl = scenario_.plant;
  const OcpTrajectory& ref = scenario_.reference_trajectory;
  if (ref.x.empty() || ref.u.empty()) return SetupResult::failure("no reference trajectory");
  if (!(c.dt > 0.0) || !(pl.rate_hz > 0.0) || !(scenario_.duration > 0.0))
    return SetupResult::failure("controller.dt, plant.rate_hz and duration must be positive");
  s_ = std::max(1L, std::lround(c.dt * pl.rate_hz));
  h_ = c.dt / double(s_);
  n_r_ = std::lround(pl.rtt * pl.rate_hz);
  n_m_ = std::lround(pl.measurement_fraction * double(n_r_));
  n_c_ = n_r_ - n_m_;
  if (n_r_ < 0 || n_m_ < 0 || n_c_ < 0)
    return SetupResult::failure("plant.rtt must be >= 0 and plant.measurement_fraction in [0, 1]");
  steps_total_ = std::max(1L, std::lround(scenario_.duration / c.dt));
  last_x_ = long(ref.x.size()) - 1;
  last_u_ = long(ref.u.size()) - 1;

  model_ = models::Crazyflie{};
  if (c.kind == TrackingControllerKind::nmpc) {
    problem_ = std::make_unique<CrazyflieTracking>(c.N, c.dt, model_);
    rti_ = std::make_unique<RtiSolver>();
    if (SetupResult r = rti_->setup(problem_->ocp()); !r)
      return SetupResult::failure("the tracking NMPC cannot be set up: " + r.reason());
    problem_->hover_guess(rti_->trajectory(), pl.start);
    problem_->set_reference(rti_->data(), ref, 0);  // for the telemetry before the first step
  }
  // The LQR law, or the NMPC's safe controller (core/modes/safety_net.hpp).
  if (SetupResult r = lqr_.setup(model_, c.dt); !r) return r;
  run_.safety.reset();
  predictor_.setup(model_, int(s_), h_, int(n_r_), int(std::lround(VehicleFeed::kMaxRtt / h_)));
  // A remote vehicle's predictions reach as far as the simulated delay's do.
  remote_.setup(model_, c.dt, int(s_), predictor_.max_substeps(),
                2 * std::size_t(steps_total_) + 2,
                VehicleWorld::ball(pl.start, tracking_defaults::kLostRadius),
                "it left the world");
  run_.lost_reason = "";

  x_init_ = model_.hover_state(pl.start);
  using Simulated = SimulatedVehicle<models::Crazyflie>;
  Simulated::Settings plant;
  plant.substeps = int(s_);
  plant.h = h_;
  plant.command_delay = n_c_;
  plant.measurement_delay = n_m_;
  plant.max_extra_delay = std::lround(kMaxExtraDelay / h_);
  plant.idle = Simulated::Idle::rests;
  simulated_.setup(model_, plant, x_init_);
  run_.j = 0;
  run_.j_lost = -1;
  run_.y = run_.x0 = x_init_;
  run_.u = model_.hover_input();

  ref_start_ = ref.x.front().head<3>();
  ref_target_ = ref.x.back().head<3>();
  const Eigen::Vector3d step = ref_target_ - ref_start_;
  step_len_ = step.norm();
  step_dir_ = step_len_ > 0 ? Eigen::Vector3d(step / step_len_) : Eigen::Vector3d::Zero();
  run_.max_error = run_.final_error = run_.max_progress = run_.max_input_violation = 0.0;
  run_.err2.clear();
  // Remote: a sample per state received, at most about two per step.
  run_.err2.reserve(2 * std::size_t(steps_total_) + 2);
  run_.last_outside = -1;
  run_.solve_us.clear();
  run_.solve_us.reserve(std::size_t(steps_total_));
  run_.predict_us.clear();
  run_.predict_us.reserve(std::size_t(steps_total_));
  if (n_c_ == 0) sample(0, x_init_);  // boundary 0 is σ = t_0

  init_telemetry();
  ok_ = true;
  run_.finished = false;
  return {};
}

// Before the first step: the vehicle at rest, x(σ = 0) = x0 = the initial state, the hover
// input; the NMPC's plan is its initial guess.
void TrackingMode::init_telemetry() {
  const int nodes = problem_ ? scenario_.controller.N + 1 : 0;
  run_.telemetry = Telemetry{};
  run_.telemetry.mode = ModeKind::crazyflie_tracking;
  run_.telemetry.x = x_init_;
  run_.telemetry.x_measured = x_init_;
  run_.telemetry.u = run_.u;
  run_.telemetry.reference = Eigen::VectorXd::Zero(3);
  run_.telemetry.predicted.setZero(3, nodes);
  run_.telemetry.predicted_reference.setZero(3, nodes);
  for (int i = 0; i < nodes; ++i) {
    run_.telemetry.predicted.col(i) = rti_->trajectory().x[std::size_t(i)].head<3>();
    run_.telemetry.predicted_reference.col(i) = rti_->data().yref[std::size_t(i)].head<3>();
  }
  set_telemetry();
  set_channels(0.0, 0.0);
}

// y = the state of boundary k·s − n_m (the initial state before the start), then x0: its
// prediction over τ_r, or y itself.
void TrackingMode::measure() {
  simulated_.measure(run_.step, run_.y);
  const auto t0 = std::chrono::steady_clock::now();
  if (scenario_.controller.compensation) {
    predictor_.predict(run_.y, run_.x0);
  } else {
    run_.x0 = run_.y;
  }
  run_.predict_us.push_back(microseconds_since(t0));
}

// u_k from x0: one RTI step (its plan kept for the telemetry before the shift), or the LQR law.
void TrackingMode::control() {
  const long k = long(run_.step);
  const OcpTrajectory& ref = scenario_.reference_trajectory;
  Telemetry& s = run_.telemetry;
  if (problem_) {
    RtiSolver& rti = *rti_;
    problem_->set_reference(rti.data(), ref, int(k));
    rti.prepare();
    if (forced_overrun(run_.step)) rti.force_overrun_next();
    rti.feedback(run_.x0);
    run_.u = rti.control();
    s.solved = true;
    s.stats = rti.stats();
    // The plan spent after fallbacks in a row: the LQR tracks the reference meanwhile.
    if (run_.safety.update(s.stats.status != RtiStatus::success)) {
      const Eigen::VectorXd& xr = ref.x[std::size_t(std::min(k, last_x_))];
      lqr_.control(run_.x0, State(xr), Input(ref.u[std::size_t(std::min(k, last_u_))]), run_.u);
    }
    for (int i = 0; i <= scenario_.controller.N; ++i) {
      s.predicted.col(i) = rti.trajectory().x[std::size_t(i)].head<3>();
      s.predicted_reference.col(i) = rti.data().yref[std::size_t(i)].head<3>();
    }
    rti.shift();
    run_.solve_us.push_back(s.stats.total_us);
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    const Eigen::VectorXd& xr = ref.x[std::size_t(std::min(k, last_x_))];
    lqr_.control(run_.x0, State(xr), Input(ref.u[std::size_t(std::min(k, last_u_))]), run_.u);
    const double us = microseconds_since(t0);
    s.solved = false;
    s.stats = RtiStats{};
    s.stats.total_us = us;
    run_.solve_us.push_back(us);
  }
}

// u_k leaves: into the predictor's and the simulated vehicle's command rings.
void TrackingMode::send() {
  run_.max_input_violation =
      std::max({run_.max_input_violation, model_.p.omega_min - run_.u.minCoeff(),
                run_.u.maxCoeff() - model_.p.omega_max});
  predictor_.record_sent(run_.u);
  simulated_.send(run_.step, run_.u);
}

// Checks and samples the boundaries up to `end` (integrated already); false at the first one
// where the vehicle is lost: not finite, or outside the kLostRadius ball around its start.
bool TrackingMode::process_to(long end) {
  const Eigen::Vector3d& start = scenario_.plant.start;
  while (run_.j < end) {
    ++run_.j;
    const State& x = simulated_.at(run_.j);
    if (!x.allFinite() || (x.head<3>() - start).norm() > tracking_defaults::kLostRadius) {
      run_.j_lost = run_.j;
      return false;
    }
    if (run_.j >= n_c_ && (run_.j - n_c_) % s_ == 0) sample((run_.j - n_c_) / s_, x);
  }
  return true;
}

// Error sample m: x = x(σ = t_m) against p_ref(t_m) (the last node held).
void TrackingMode::sample(long m, const State& x) {
  const OcpTrajectory& ref = scenario_.reference_trajectory;
  add_sample(m, x.head<3>(), ref.x[std::size_t(std::min(m, last_x_))].head<3>());
}

// An error sample of a remote vehicle: x = x(σ) against p_ref(σ), linear between the nodes.
void TrackingMode::sample_at(double sigma, const State& x) {
  const OcpTrajectory& ref = scenario_.reference_trajectory;
  const double nodes = std::max(0.0, sigma / scenario_.controller.dt);
  const long i = std::min(long(nodes), last_x_), i1 = std::min(i + 1, last_x_);
  const double w = std::min(1.0, nodes - double(i));
  const Eigen::Vector3d pr =
      (1.0 - w) * ref.x[std::size_t(i)].head<3>() + w * ref.x[std::size_t(i1)].head<3>();
  add_sample(std::lround(nodes), x.head<3>(), pr);
}

void TrackingMode::add_sample(long m, const Eigen::Vector3d& p, const Eigen::Vector3d& pr) {
  if (run_.err2.size() == run_.err2.capacity()) return;  // never grow in the loop
  const double e = position_error(p, pr);
  run_.err2.push_back(e * e);
  run_.max_error = std::max(run_.max_error, e);
  run_.final_error = e;
  if (scenario_.reference.kind == TrackingReferenceKind::smooth_step) {
    run_.max_progress = std::max(run_.max_progress, (p - ref_start_).dot(step_dir_));
    if ((p - ref_target_).norm() > tracking_defaults::kSettleRadius) run_.last_outside = m;
  }
}

// What a state may hold before it is not one (input/net/peer_checks.hpp): positions well
// beyond any world, a quaternion's parts (unit, with the integrator's drift), speeds and rates
// no quadrotor reaches.
VehicleStateSpec TrackingMode::remote_state() const {
  VehicleStateSpec spec;
  spec.nx = models::Crazyflie::nx;
  const auto set = [&](int from, int n, double bound) {
    for (int i = from; i < from + n; ++i) spec.max_abs[std::size_t(i)] = bound;
  };
  set(0, 3, 1e4);
  set(3, 4, 2.0);
  set(7, 3, 1e3);
  set(10, 3, 1e4);
  return spec;
}

bool TrackingMode::set_vehicle(VehicleLink* link) {
  remote_.attach(link);
  return true;
}

void TrackingMode::lose(double at, const char* reason) {
  run_.lost = true;
  run_.lost_at = at;
  run_.lost_reason = reason;
}

bool TrackingMode::step() {
  if (run_.finished || stopped_at(run_.step)) return false;
  begin_commands(run_.step);
  if (remote_.attached()) return step_remote();
  const long k = long(run_.step);
  const auto started = std::chrono::steady_clock::now();
  measure();
  control();
  run_.compute_us = microseconds_since(started);
  send();
  // The plant to the next control boundary; after the last step on to K·s + n_c (sample K).
  const long end = (k + 1) * s_ + (k + 1 == steps_total_ ? n_c_ : 0);
  simulated_.integrate_to(std::max(end, k * s_ + n_c_));
  const bool alive = process_to(end);
  if (!alive) lose(double(run_.j_lost - n_c_) * h_, "it left the world");
  set_telemetry();
  Telemetry& s = run_.telemetry;
  s.events |= deadline_event(run_.step, run_.compute_us, s.solved && s.stats.overrun);
  set_channels(run_.predict_us.back(), run_.solve_us.back());
  end_commands(s);
  ++run_.step;
  run_.finished = run_.lost || run_.step >= steps_total_;
  return true;
}

InstructorStatus TrackingMode::apply_gust(const Eigen::Vector3d& force, double duration) {
  if (remote()) return InstructorStatus::remote_vehicle;
  simulated_.gust(force, std::lround(duration / h_));
  return InstructorStatus::applied;
}

InstructorStatus TrackingMode::apply_extra_delay(double delay) {
  if (remote()) return InstructorStatus::remote_vehicle;
  simulated_.set_extra_delay(std::lround(delay / h_));
  return InstructorStatus::applied;
}

// The gust as the controller's clock sees it: step k's state is boundary k·s + n_c.
InstructorInForce TrackingMode::in_force(std::int64_t k) const {
  InstructorInForce f;
  if (remote()) return f;
  const long left = simulated_.gust_left(long(k) * s_ + n_c_);
  if (left > 0) {
    f.gust = simulated_.data().gust;
    f.gust_left = double(left) * h_;
  }
  f.extra_delay = double(simulated_.extra_delay()) * h_;
  return f;
}

// Step k with a remote vehicle: the newest state (a round-trip and an error sample when it is
// new), the prediction over the estimated round-trip time, the controller, the command out.
bool TrackingMode::step_remote() {
  using Remote = LinkedVehicle<models::Crazyflie>;
  const long k = long(run_.step);
  const double t = double(k) * scenario_.controller.dt;
  run_.y = x_init_;  // before any state arrives
  const Remote::Reading r = remote_.read(k, run_.y);
  if (r.status == Remote::Status::left_world) {
    lose(t, r.reason);
    run_.y = x_init_;
  } else if (r.status == Remote::Status::lost) {
    lose(t, r.reason);
  } else if (r.fresh) {
    sample_at(r.sigma, run_.y);  // only states inside the world are scored
  }
  if (run_.lost) {
    run_.finished = true;
    remote_.finish();
    set_telemetry();
    run_.telemetry.x = run_.y;
    end_commands(run_.telemetry);
    ++run_.step;
    return true;
  }

  // What is known of the vehicle at t_k is the newest state predicted over its age; the
  // controller starts from it only with compensation, the telemetry always shows it (the
  // newest state itself is a round trip old: its error would be the delay's, not the loop's).
  const auto t0 = std::chrono::steady_clock::now();
  remote_.predict(run_.y, run_.predicted, r);
  run_.x0 = scenario_.controller.compensation ? run_.predicted : run_.y;
  run_.predict_us.push_back(scenario_.controller.compensation ? microseconds_since(t0) : 0.0);
  control();
  run_.compute_us = microseconds_since(t0);
  send();
  remote_.send(k, run_.u);

  set_telemetry();
  Telemetry& s = run_.telemetry;
  s.events |= deadline_event(run_.step, run_.compute_us, s.solved && s.stats.overrun);
  s.x = run_.predicted;
  set_channels(run_.predict_us.back(), run_.solve_us.back());
  end_commands(s);
  ++run_.step;
  run_.finished = run_.step >= steps_total_;
  if (run_.finished) remote_.finish();
  return true;
}

// Step k's telemetry on the controller's clock: x(σ = t_k), boundary k·s + n_c (when the vehicle
// is lost before it, the last state inside the world), x0, u_k, p_ref(t_k).
void TrackingMode::set_telemetry() {
  const long k = long(run_.step);
  Telemetry& s = run_.telemetry;
  s.step = run_.step;
  s.t = double(k) * scenario_.controller.dt;
  long jx = k * s_ + n_c_;
  if (run_.j_lost >= 0 && jx >= run_.j_lost) jx = run_.j_lost - 1;
  s.x = simulated_.at(jx);
  s.x_measured = run_.x0;
  s.u = run_.u;
  const Eigen::VectorXd& xr = scenario_.reference_trajectory.x[std::size_t(std::min(k, last_x_))];
  for (int i = 0; i < 3; ++i) s.reference(i) = xr(i);
  s.events = 0;
  if (s.solved && s.stats.status == RtiStatus::fallback) s.events |= kEventFallback;
  if (s.solved && s.stats.overrun) s.events |= kEventOverrun;
  if (run_.safety.engaged()) s.events |= kEventSafeHold;
  if (run_.safety.switched()) s.events |= kEventSwitch;
  if (run_.lost) s.events |= kEventLost;
}

void TrackingMode::set_channels(double predictor_us, double controller_us) {
  Telemetry& s = run_.telemetry;
  const Eigen::Vector3d p = s.x.head<3>(), pr = s.reference.head<3>();
  s.set_channel(kTrackingError, "tracking error", "m", position_error(p, pr));
  s.set_channel(kRtt, remote() ? "RTT estimate" : "RTT", "s",
                remote() ? remote_.rtt().estimate() : scenario_.plant.rtt);
  s.set_channel(kPredictorTime, "predictor time", "us", predictor_us);
  s.set_channel(kControllerTime, nmpc() ? "RTI time" : "LQR time", "us", controller_us);
  for (int i = 0; i < 4; ++i) s.set_channel(kRotorSpeed1 + i, kRotorSpeedNames[i], "krpm", s.u(i));
  s.set_channel(kRotorSpeedBound, "rotor speed bound", "krpm", model_.p.omega_max);
  s.set_channel(kCompensation, "compensation", "", scenario_.controller.compensation ? 1.0 : 0.0);
  if (remote()) {
    s.set_channel(kRttSample, "RTT sample", "s", remote_.rtt().last_sample());
    s.set_channel(kHorizon, "prediction horizon", "s", remote_.feed().horizon_s());
  }
}

struct TrackingMode::Saved final : ModeSnapshot::State {
  bool nmpc = false;
  RtiState rti;  // the NMPC's warm start (empty for the LQR)
  CrazyflieDelayPredictor::Sent predictor;
  SimulatedVehicle<models::Crazyflie>::Data vehicle;
  Run run;
  bool remote = false;
};

void TrackingMode::save_state(std::unique_ptr<ModeSnapshot::State>& state) const {
  if (!state) state = std::make_unique<Saved>();
  Saved& s = static_cast<Saved&>(*state);  // Mode::save() replaced a state of another kind
  s.nmpc = rti_ != nullptr;
  if (rti_) s.rti = rti_->state();
  s.predictor = predictor_.sent();
  s.vehicle = simulated_.data();
  s.run = run_;
  s.remote = remote();
}

RestoreStatus TrackingMode::restore_state(const ModeSnapshot::State& state) {
  const Saved& s = static_cast<const Saved&>(state);  // Mode::restore() checked the kind
  if (s.remote || remote()) return RestoreStatus::remote_vehicle;
  if (!ok_ || s.nmpc != (rti_ != nullptr) || (rti_ && !rti_->fits(s.rti)) ||
      !predictor_.fits(s.predictor) || !simulated_.fits(s.vehicle) ||
      s.run.telemetry.predicted.cols() != run_.telemetry.predicted.cols())
    return RestoreStatus::other_scenario;
  if (rti_) rti_->restore(s.rti);
  predictor_.restore(s.predictor);
  simulated_.restore(s.vehicle);
  run_ = s.run;
  return RestoreStatus::ok;
}

TrackingResult TrackingMode::result() const {
  TrackingResult r;
  r.ok = ok_;
  r.lost = run_.lost;
  r.steps = int(run_.step);
  // Squares rounded one by one, then summed in order: a running sum would let the compiler
  // fuse each square into the addition (FMA) and round differently.
  double sum = 0.0;
  for (double e2 : run_.err2) sum += e2;
  r.tracking_rms_m = run_.err2.empty() ? 0.0 : std::sqrt(sum / double(run_.err2.size()));
  r.max_error_m = run_.max_error;
  r.final_error_m = run_.final_error;
  if (scenario_.reference.kind == TrackingReferenceKind::smooth_step) {
    r.overshoot_m = std::max(0.0, run_.max_progress - step_len_);
    r.settle_time_s = double(run_.last_outside + 1) * scenario_.controller.dt;
  }
  r.max_input_violation = run_.max_input_violation;
  r.solve_median_us = percentile(run_.solve_us, 0.5);
  r.solve_p99_us = percentile(run_.solve_us, 0.99);
  r.predictor_median_us =
      scenario_.controller.compensation ? percentile(run_.predict_us, 0.5) : 0.0;
  r.fallbacks = rti_ ? long(rti_->stats().fallbacks) : 0;
  r.rtt_substeps = int(n_r_);
  r.measurement_substeps = int(n_m_);
  r.command_substeps = int(n_c_);
  r.remote = remote();
  r.rtt_measured_s = remote_.feed().measured_median();
  r.rtt_estimated_s = remote_.rtt().estimate();
  r.rtt_samples = long(remote_.feed().sample_count());
  return r;
}

Metrics TrackingMode::metrics() const {
  const TrackingResult r = result();
  const bool rti = nmpc();
  Metrics m;
  m.emplace_back("tracking_rms_m", r.tracking_rms_m);
  m.emplace_back("max_error_m", r.max_error_m);
  m.emplace_back("final_error_m", r.final_error_m);
  if (scenario_.reference.kind == TrackingReferenceKind::smooth_step) {
    m.emplace_back("overshoot_m", r.overshoot_m);
    m.emplace_back("settle_time_s", r.settle_time_s);
  }
  m.emplace_back(rti ? "rti_median_us" : "lqr_median_us", r.solve_median_us);
  m.emplace_back(rti ? "rti_p99_us" : "lqr_p99_us", r.solve_p99_us);
  if (rti) m.emplace_back("fallbacks", double(r.fallbacks));
  m.emplace_back("predictor_median_us", r.predictor_median_us);
  m.emplace_back("max_input_violation", r.max_input_violation);
  // A remote vehicle's RTT is measured (the median of its samples) and estimated online.
  m.emplace_back("rtt_s", r.remote ? r.rtt_measured_s : scenario_.plant.rtt);
  if (r.remote) m.emplace_back("rtt_estimated_s", r.rtt_estimated_s);
  m.emplace_back("compensation", scenario_.controller.compensation ? 1.0 : 0.0);
  m.emplace_back("steps", double(r.steps));
  m.emplace_back("lost", r.lost ? 1.0 : 0.0);
  return m;
}

ModeView TrackingMode::view() const {
  ModeView v;
  v.reference = positions_of(scenario_.reference_trajectory);
  fit_arena(v, v.reference, 0.75);
  return v;
}

std::string TrackingMode::summary() const {
  const TrackingResult r = result();
  const bool rti = nmpc();
  const bool step = scenario_.reference.kind == TrackingReferenceKind::smooth_step;
  char buf[512];
  if (r.remote && r.rtt_samples == 0) {
    std::snprintf(buf, sizeof buf, "remote vehicle, no round trip measured");
  } else if (r.remote) {
    std::snprintf(buf, sizeof buf, "remote vehicle, RTT %.1f ms measured, %.1f ms estimated",
                  1e3 * r.rtt_measured_s, 1e3 * r.rtt_estimated_s);
  } else {
    std::snprintf(buf, sizeof buf, "RTT %.0f ms", 1e3 * scenario_.plant.rtt);
  }
  const std::string rtt_text = buf;
  std::snprintf(buf, sizeof buf,
                "%s (crazyflie_tracking, %s, %s, %s, compensation %s)\n"
                "  %d steps; tracking RMS %.4f m, max %.4f m, final %.4f m",
                scenario_.name.c_str(), rti ? "NMPC" : "LQR", step ? "smooth step" : "helix",
                rtt_text.c_str(), scenario_.controller.compensation ? "on" : "off",
                r.steps, r.tracking_rms_m, r.max_error_m, r.final_error_m);
  std::string out = buf;
  if (run_.err2.empty()) {
    // A remote vehicle whose states never acknowledged a command gave no error to measure.
    std::snprintf(buf, sizeof buf,
                  "%s (crazyflie_tracking, %s, %s, %s, compensation %s)\n"
                  "  %d steps; tracking not measured: no state of the vehicle followed a command",
                  scenario_.name.c_str(), rti ? "NMPC" : "LQR", step ? "smooth step" : "helix",
                  rtt_text.c_str(), scenario_.controller.compensation ? "on" : "off", r.steps);
    out = buf;
  } else if (step) {
    std::snprintf(buf, sizeof buf, "; overshoot %.4f m, settled at %.2f s", r.overshoot_m,
                  r.settle_time_s);
    out += buf;
  }
  const std::string fallbacks = rti ? ", " + std::to_string(r.fallbacks) + " fallbacks" : "";
  std::snprintf(buf, sizeof buf, "\n  %s median %.0f us, p99 %.0f us%s; predictor median %.1f us%s\n",
                rti ? "RTI" : "LQR", r.solve_median_us, r.solve_p99_us, fallbacks.c_str(),
                r.predictor_median_us, r.lost ? "\n  the vehicle was lost: " : "");
  out += buf;
  if (r.lost) {
    out.pop_back();
    out += run_.lost_reason;
    out += "\n";
  }
  out += safe_hold_summary(run_.safety, scenario_.controller.dt, "the LQR");
  return out;
}

TrackingResult run_tracking(const TrackingScenario& scenario, TrackingLog* log) {
  TrackingMode mode;
  if (SetupResult r = mode.setup(scenario); !r) {
    TrackingResult res;
    res.error = r.reason();
    return res;
  }
  if (log) {
    *log = TrackingLog{};
    const std::size_t n = std::size_t(mode.steps_total());
    log->t.reserve(n);
    log->p.reserve(n);
    log->p_ref.reserve(n);
    log->x_true.reserve(n);
    log->x0.reserve(n);
    log->u.reserve(n);
  }
  while (mode.step()) {
    if (!log) continue;
    const Telemetry& s = mode.telemetry();
    log->t.push_back(s.t);
    log->p.push_back(s.x.head<3>());
    log->p_ref.push_back(s.reference.head<3>());
    log->x_true.push_back(s.x);
    log->x0.push_back(s.x_measured);
    log->u.push_back(s.u);
  }
  return mode.result();
}


}  // namespace mixpilot
