#include "core/modes/pendubot_mode.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

#include "core/numerics/stats.hpp"

namespace mixpilot {

namespace {

double quantize(double q, int counts) {
  const double step = 2.0 * std::numbers::pi / counts;
  return step * (std::floor(q / step) + 0.5);  // whole counts; the cell centre is unbiased
}

// ‖wrap(q1, q2)‖: the distance of the angles from up-up.
double angle_norm(const Eigen::Vector4d& x) {
  return std::hypot(wrap_angle(x(0)), wrap_angle(x(1)));
}

bool finite_non_negative(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return v.allFinite() && (v.array() >= 0.0).all();
}

}  // namespace

SetupResult PendubotMode::check_settings() const {
  const PendubotScenario& sc = scenario_;
  const PendubotOcpSettings& oc = sc.controller;
  const OcpTrajectory& ref = sc.reference.trajectory;
  if (ref.u.empty() || ref.x.size() != ref.u.size() + 1)
    return SetupResult::failure(
        "no swing-up reference (controller.reference: n + 1 states, n inputs)");
  for (const auto& x : ref.x)
    if (x.size() != 4) return SetupResult::failure("the reference's states must have 4 entries");
  for (const auto& u : ref.u)
    if (u.size() != 1) return SetupResult::failure("the reference's inputs must have 1 entry");
  if (!(oc.dt > 0.0) || !std::isfinite(sc.duration) || !(std::llround(sc.duration / oc.dt) >= 1))
    return SetupResult::failure("controller.dt must be positive and duration at least one step");
  if (!sc.plant.initial_state.allFinite())
    return SetupResult::failure("plant.initial_state must be finite");
  const double rate = sc.plant.rate_hz;
  if (!std::isfinite(rate) || !(std::llround(oc.dt * rate) >= 1))
    return SetupResult::failure("plant.rate_hz must give at least one substep per control step");
  if (!(oc.u_max > 0.0) || !std::isfinite(oc.u_max))
    return SetupResult::failure("controller.u_max must be positive");
  if (!finite_non_negative(oc.weights) || !(oc.weights(4) > 0.0) ||
      !finite_non_negative(oc.terminal_weights))
    return SetupResult::failure(
        "controller.weights and terminal_weights must be finite and non-negative, the input "
        "weight positive");
  const PendubotScenario::Lqr& l = sc.lqr;
  if (l.enabled && (!finite_non_negative(l.q) || !(l.r > 0.0) || !(l.enter_angle >= 0.0) ||
                    !(l.enter_velocity >= 0.0) || !(l.exit_angle > l.enter_angle)))
    return SetupResult::failure(
        "lqr: q must be finite and non-negative, r positive, exit_angle > enter_angle >= 0");
  const PendubotScenario::Sensor& e = sc.sensor;
  if (e.quantization && (e.counts_q1 < 1 || e.counts_q2 < 1 || !(e.velocity_cutoff_hz >= 0.0) ||
                         (e.estimator != "difference" && e.estimator != "observer")))
    return SetupResult::failure(
        "sensor: counts must be positive, velocity_cutoff_hz >= 0, estimator \"difference\" or "
        "\"observer\"");
  return {};
}

SetupResult PendubotMode::setup(PendubotScenario scenario) {
  scenario_ = std::move(scenario);
  ok_ = false;
  run_.finished = true;  // until setup succeeds
  run_.step = steps_total_ = 0;
  problem_.reset();
  lqr_ = PendubotLqr{};
  run_.telemetry = Telemetry{};
  run_.telemetry.mode = ModeKind::pendubot_swingup;
  if (SetupResult r = check_settings(); !r) return r;
  const PendubotOcpSettings& oc = scenario_.controller;
  problem_ = std::make_unique<PendubotSwingup>(oc);
  RtiSettings rti_settings;
  rti_settings.qp_solver = oc.qp_solver;
  if (SetupResult r = rti_.setup(problem_->ocp(), rti_settings); !r)
    return SetupResult::failure("the swing-up NMPC cannot be set up: " + r.reason());
  if (scenario_.lqr.enabled) {
    lqr_ = pendubot_lqr(problem_->model(), oc.dt, scenario_.lqr.q, scenario_.lqr.r);
    if (!lqr_.converged)
      return SetupResult::failure("the LQR's discrete Riccati equation does not converge");
  }
  warm_start();

  steps_total_ = std::llround(scenario_.duration / oc.dt);
  substeps_ = int(std::llround(oc.dt * scenario_.plant.rate_hz));
  h_ = oc.dt / substeps_;
  ref_steps_ = int(scenario_.reference.trajectory.u.size());
  const double fc = scenario_.sensor.velocity_cutoff_hz;
  lowpass_ = fc > 0 ? 1.0 - std::exp(-2.0 * std::numbers::pi * fc * oc.dt) : 1.0;
  observer_ = scenario_.sensor.estimator == "observer";

  run_.x = scenario_.plant.initial_state;
  run_.xm = run_.x;
  run_.xw = run_.x;
  run_.q_prev = Eigen::Vector2d(quantize(run_.x(0), scenario_.sensor.counts_q1),
                                quantize(run_.x(1), scenario_.sensor.counts_q2));
  run_.v_filt.setZero();
  run_.x0 = Eigen::VectorXd::Zero(4);
  run_.u_prev = 0.0;
  run_.lqr_active = false;
  run_.safety.reset();

  run_.max_abs_u = run_.worst_velocity_violation = run_.err2 = run_.lqr_time = 0.0;
  run_.velocity_violations = run_.err_n = run_.nmpc_steps = run_.lqr_entries = 0;
  run_.lqr_entry_time = -1.0;
  run_.last_outside = -1;
  record_angle_norm();
  run_.rti_us.clear();
  run_.rti_us.reserve(std::size_t(steps_total_));

  run_.telemetry.x = run_.x;
  run_.telemetry.x_measured = run_.xm;
  run_.telemetry.u = Eigen::VectorXd::Zero(1);
  run_.telemetry.reference = Eigen::VectorXd::Zero(4);
  set_telemetry(0.0, false, 0.0);
  ok_ = true;
  run_.finished = false;
  return {};
}

// The NMPC's first linearization point: the reference itself (its last input then 0).
void PendubotMode::warm_start() {
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  OcpTrajectory& traj = rti_.trajectory();
  const int N = scenario_.controller.N;
  const std::size_t last = ref.x.size() - 1;
  for (std::size_t i = 0; i <= std::size_t(N); ++i) traj.x[i] = ref.x[std::min(i, last)];
  for (std::size_t i = 0; i < std::size_t(N); ++i) {
    if (i < ref.u.size()) {
      traj.u[i] = ref.u[i];
    } else {
      traj.u[i].setZero();
    }
  }
}

// x̂_k from x_k: the exact state, the encoder angles with low-passed differenced velocities, or
// the α-β observer (model prediction over Δt with u_{k−1}, corrected by the encoder angles).
void PendubotMode::measure() {
  const PendubotScenario::Sensor& sn = scenario_.sensor;
  const double dt = scenario_.controller.dt;
  if (sn.quantization) {
    const Eigen::Vector2d q(quantize(run_.x(0), sn.counts_q1), quantize(run_.x(1), sn.counts_q2));
    if (observer_) {
      if (run_.step == 0) {
        run_.xm = Eigen::Vector4d(q(0), q(1), 0.0, 0.0);
      } else {
        problem_->integrator().step<double>(run_.xm, models::Pendubot::Input(run_.u_prev), dt, xn_);
        const Eigen::Vector2d e = q - xn_.head<2>();
        run_.xm.head<2>() = xn_.head<2>() + sn.observer_alpha * e;
        run_.xm.tail<2>() = xn_.tail<2>() + (sn.observer_beta / dt) * e;
      }
    } else {
      const Eigen::Vector2d v_raw = (q - run_.q_prev) / dt;
      if (run_.step > 0) run_.v_filt += lowpass_ * (v_raw - run_.v_filt);
      run_.q_prev = q;
      run_.xm = Eigen::Vector4d(q(0), q(1), run_.v_filt(0), run_.v_filt(1));
    }
  } else {
    run_.xm = run_.x;
  }
  run_.xw = run_.xm;
  run_.xw(0) = wrap_angle(run_.xm(0));
  run_.xw(1) = wrap_angle(run_.xm(1));
}

// The switch rule (core/modes/pendubot_mode.hpp) on x̂_k; true when the controller changed.
bool PendubotMode::switch_controller() {
  const PendubotScenario::Lqr& l = scenario_.lqr;
  const Eigen::Vector4d& xw = run_.xw;
  const double u_lqr = -lqr_.K.dot(xw);
  const double a = xw.head<2>().norm();
  if (l.enabled && !run_.lqr_active && a <= l.enter_angle &&
      xw.tail<2>().norm() <= l.enter_velocity && std::abs(u_lqr) <= scenario_.controller.u_max) {
    run_.lqr_active = true;
    ++run_.lqr_entries;
    if (run_.lqr_entry_time < 0) run_.lqr_entry_time = double(run_.step) * scenario_.controller.dt;
    return true;
  }
  if (run_.lqr_active && a > l.exit_angle) {
    run_.lqr_active = false;
    PendubotSwingup::constant_guess(rti_.trajectory(), xw);  // restart towards up-up
    return true;
  }
  return false;
}

// u_k: the LQR law or one RTI step, finite and inside |u| ≤ u_max.
double PendubotMode::control() {
  double u = 0.0;
  if (run_.lqr_active) {
    u = -lqr_.K.dot(run_.xw);
    run_.lqr_time += scenario_.controller.dt;
    run_.telemetry.solved = false;
    run_.telemetry.stats = RtiStats{};
    run_.telemetry.stats.fallbacks = rti_.stats().fallbacks;
  } else {
    u = nmpc();
    // The plan spent after fallbacks in a row: the LQR near the top, no torque elsewhere (the
    // links then swing down and settle instead of being driven by a stale plan).
    if (run_.safety.update(run_.telemetry.stats.status != RtiStatus::success))
      u = run_.xw.head<2>().norm() <= scenario_.lqr.exit_angle ? -lqr_.K.dot(run_.xw) : 0.0;
  }
  if (!std::isfinite(u)) u = 0.0;
  const double u_max = scenario_.controller.u_max;
  u = std::clamp(u, -u_max, u_max);  // guards rounding only: the QP bounds u
  run_.max_abs_u = std::max(run_.max_abs_u, std::abs(u));
  run_.u_prev = u;
  return u;
}

// One RTI step from x̂_k: angles unwrapped as measured while tracking the reference, wrapped
// once it is over (the target is then up-up).
double PendubotMode::nmpc() {
  const int k = int(run_.step);
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  const bool tracking = k < ref_steps_;
  run_.x0 = tracking ? run_.xm : run_.xw;
  if (!tracking && k == ref_steps_) {
    // Re-express the warm start around the wrapped angles.
    for (auto& xi : rti_.trajectory().x) {
      xi(0) += run_.xw(0) - run_.xm(0);
      xi(1) += run_.xw(1) - run_.xm(1);
    }
  }
  problem_->set_reference(rti_.data(), ref, k);
  rti_.prepare();
  if (forced_overrun(run_.step)) rti_.force_overrun_next();
  rti_.feedback(run_.x0);
  const double u = rti_.control()(0);
  rti_.shift();
  run_.telemetry.solved = true;
  run_.telemetry.stats = rti_.stats();
  run_.rti_us.push_back(rti_.stats().total_us);
  ++run_.nmpc_steps;
  if (tracking) {
    run_.err2 += (run_.x.head<2>() - ref.x[std::size_t(k)].head<2>()).squaredNorm();
    ++run_.err_n;
  }
  return u;
}

// The plant over Δt: RK4 substeps with u held. Returns the largest excess of a substep's
// velocities over their bounds (≤ 0: none). The substeps run on locals (the state stays in
// registers, not reloaded through `this`): on members the compiler contracts the RK4 arithmetic
// into FMAs differently, and the last bits of every run change.
double PendubotMode::integrate(double u) {
  const IntegratorErk4<models::Pendubot>& erk4 = problem_->integrator();
  const double b1 = scenario_.controller.velocity_bound(0);
  const double b2 = scenario_.controller.velocity_bound(1);
  const double h = h_;
  State x = run_.x, xn;
  double worst = 0.0;
  for (int j = 0; j < substeps_; ++j) {
    erk4.step<double>(x, models::Pendubot::Input(u), h, xn);
    x = xn;
    worst = std::max({worst, std::abs(x(2)) - b1, std::abs(x(3)) - b2});
  }
  run_.x = x;
  if (worst > 0) {
    ++run_.velocity_violations;
    run_.worst_velocity_violation = std::max(run_.worst_velocity_violation, worst);
  }
  return worst;
}

// ‖wrap(q)‖ of the state now (index step), for the swing-up time and the final norm.
void PendubotMode::record_angle_norm() {
  run_.angle_norm = angle_norm(run_.x);
  if (run_.angle_norm > scenario_.angle_tolerance) run_.last_outside = run_.step;
}

bool PendubotMode::step() {
  if (run_.finished || stopped_at(run_.step)) return false;
  begin_commands(run_.step);
  const auto started = std::chrono::steady_clock::now();
  measure();
  const bool switched = switch_controller();
  const double u = control();
  const double compute_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - started).count();
  const State x_k = run_.x;
  const double worst = integrate(u);
  Telemetry& s = run_.telemetry;
  s.x = x_k;
  set_telemetry(u, switched, worst);
  s.events |= deadline_event(run_.step, compute_us, s.solved && s.stats.overrun);
  end_commands(s);
  ++run_.step;
  record_angle_norm();
  run_.finished = run_.step >= steps_total_;
  return true;
}

// Step k's telemetry (x already holds x_k): x̂_k, u_k, the reference node k, events, channels.
void PendubotMode::set_telemetry(double u, bool switched, double worst_violation) {
  Telemetry& s = run_.telemetry;
  const OcpTrajectory& ref = scenario_.reference.trajectory;
  const std::size_t k = std::size_t(run_.step);
  s.step = run_.step;
  s.t = double(run_.step) * scenario_.controller.dt;
  s.x_measured = run_.xm;
  s.u(0) = u;
  if (k < ref.x.size()) {
    s.reference = ref.x[k];
  } else {
    s.reference.setZero();  // past the reference: up-up
  }
  s.events = 0;
  if (switched) s.events |= kEventSwitch;
  if (worst_violation > 0) s.events |= kEventViolation;
  if (s.solved && s.stats.status == RtiStatus::fallback) s.events |= kEventFallback;
  if (s.solved && s.stats.overrun) s.events |= kEventOverrun;
  if (!run_.lqr_active && run_.safety.engaged()) s.events |= kEventSafeHold;
  if (!run_.lqr_active && run_.safety.switched()) s.events |= kEventSwitch;
  set_channels();
}

void PendubotMode::set_channels() {
  Telemetry& s = run_.telemetry;
  const PendubotOcpSettings& oc = scenario_.controller;
  s.set_channel(kPendubotQ1, "q1", "rad", wrap_angle(s.x(0)));
  s.set_channel(kPendubotQ2, "q2", "rad", wrap_angle(s.x(1)));
  s.set_channel(kPendubotDq1, "dq1", "rad/s", s.x(2));
  s.set_channel(kPendubotDq2, "dq2", "rad/s", s.x(3));
  s.set_channel(kPendubotQ1Reference, "q1 reference", "rad", wrap_angle(s.reference(0)));
  s.set_channel(kPendubotQ2Reference, "q2 reference", "rad", wrap_angle(s.reference(1)));
  s.set_channel(kPendubotDq1Reference, "dq1 reference", "rad/s", s.reference(2));
  s.set_channel(kPendubotDq2Reference, "dq2 reference", "rad/s", s.reference(3));
  s.set_channel(kPendubotTorque, "torque", "N m", s.u(0));
  s.set_channel(kPendubotLqrActive, "LQR active", "", run_.lqr_active ? 1.0 : 0.0);
  s.set_channel(kPendubotAngleNorm, "angle norm", "rad",
                std::hypot(wrap_angle(s.x(0)), wrap_angle(s.x(1))));
  s.set_channel(kPendubotDq1Bound, "dq1 bound", "rad/s", oc.velocity_bound(0));
  s.set_channel(kPendubotDq2Bound, "dq2 bound", "rad/s", oc.velocity_bound(1));
  s.set_channel(kPendubotTorqueBound, "torque bound", "N m", oc.u_max);
}

struct PendubotMode::Saved final : ModeSnapshot::State {
  RtiState rti;  // the NMPC's warm start
  Run run;
};

void PendubotMode::save_state(std::unique_ptr<ModeSnapshot::State>& state) const {
  if (!state) state = std::make_unique<Saved>();
  Saved& s = static_cast<Saved&>(*state);  // Mode::save() replaced a state of another kind
  s.rti = rti_.state();
  s.run = run_;
}

RestoreStatus PendubotMode::restore_state(const ModeSnapshot::State& state) {
  const Saved& s = static_cast<const Saved&>(state);  // Mode::restore() checked the kind
  if (!ok_ || !rti_.fits(s.rti) || s.run.x0.size() != run_.x0.size())
    return RestoreStatus::other_scenario;
  rti_.restore(s.rti);
  run_ = s.run;
  return RestoreStatus::ok;
}

PendubotRun PendubotMode::result() const {
  PendubotRun r;
  r.ok = ok_;
  if (!ok_) return r;
  const double dt = scenario_.controller.dt;
  r.steps = int(run_.step);
  if (run_.last_outside < run_.step) r.swingup_time = double(int(run_.last_outside + 1)) * dt;
  r.final_angle_norm = run_.angle_norm;
  r.max_abs_u = run_.max_abs_u;
  r.velocity_violations = run_.velocity_violations;
  r.worst_velocity_violation = run_.worst_velocity_violation;
  r.tracking_rms = run_.err_n > 0 ? std::sqrt(run_.err2 / run_.err_n) : 0.0;
  r.rti_median_us = percentile(run_.rti_us, 0.5);
  r.rti_p99_us = percentile(run_.rti_us, 0.99);
  const std::vector<double>& rti_us = run_.rti_us;
  r.rti_max_us = rti_us.empty() ? 0.0 : *std::max_element(rti_us.begin(), rti_us.end());
  r.nmpc_steps = run_.nmpc_steps;
  r.fallbacks = rti_.stats().fallbacks;
  r.lqr_time = run_.lqr_time;
  r.lqr_entries = run_.lqr_entries;
  r.lqr_entry_time = run_.lqr_entry_time;
  return r;
}

Metrics PendubotMode::metrics() const {
  const PendubotRun run = result();
  const double duration = scenario_.duration;
  const double swingup = run.swingup_time.value_or(-1.0);
  return {
      {"duration_s", duration},
      {"swingup_time_s", swingup},
      {"hold_time_s", run.swingup_time ? duration - swingup : 0.0},
      {"final_angle_norm", run.final_angle_norm},
      {"max_abs_u", run.max_abs_u},
      {"velocity_violations", double(run.velocity_violations)},
      {"worst_velocity_violation", run.worst_velocity_violation},
      {"tracking_rms", run.tracking_rms},
      {"rti_median_us", run.rti_median_us},
      {"rti_p99_us", run.rti_p99_us},
      {"rti_max_us", run.rti_max_us},
      {"nmpc_steps", double(run.nmpc_steps)},
      {"fallbacks", double(run.fallbacks)},
      {"lqr_entry_time_s", run.lqr_entry_time},
      {"lqr_time_s", run.lqr_time},
      {"lqr_entries", double(run.lqr_entries)},
      {"quantization", scenario_.sensor.quantization ? 1.0 : 0.0},
  };
}

ModeView PendubotMode::view() const {
  ModeView v;
  v.view = ViewKind::arm_2d;
  const models::PendubotParams p;
  v.link1 = p.l1;
  v.link2 = p.l2;
  return v;
}

std::string PendubotMode::summary() const {
  const PendubotRun run = result();
  const PendubotScenario& sc = scenario_;
  const double swingup = run.swingup_time.value_or(-1.0);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s (pendubot_swingup): %.2f s, %s, NMPC N = %d at dt = %.0f ms%s\n", sc.name.c_str(),
                sc.duration, sc.sensor.quantization ? "encoders (quantized)" : "exact state",
                sc.controller.N, 1e3 * sc.controller.dt, sc.lqr.enabled ? " + LQR" : "");
  std::string out = buf;
  if (run.swingup_time) {
    std::snprintf(buf, sizeof buf, "  up-up (|angles| <= %.3f rad) from t = %.3f s, held %.3f s\n",
                  sc.angle_tolerance, swingup, sc.duration - swingup);
  } else {
    std::snprintf(buf, sizeof buf, "  did NOT reach and hold |angles| <= %.3f rad (final %.4f)\n",
                  sc.angle_tolerance, run.final_angle_norm);
  }
  out += buf;
  std::snprintf(buf, sizeof buf,
                "  max |u| %.4f N·m; velocity bound violations %d steps, worst %.4f rad/s; "
                "tracking RMS %.4f rad\n",
                run.max_abs_u, run.velocity_violations, run.worst_velocity_violation,
                run.tracking_rms);
  out += buf;
  std::snprintf(buf, sizeof buf,
                "  RTI median %.1f us, p99 %.1f us (%d steps), fallbacks %lld; LQR from t = %.3f s "
                "(%.3f s, %d entries); final |angles| %.2e rad\n",
                run.rti_median_us, run.rti_p99_us, run.nmpc_steps, (long long)run.fallbacks,
                run.lqr_entry_time, run.lqr_time, run.lqr_entries, run.final_angle_norm);
  out += buf;
  out += safe_hold_summary(run_.safety, scenario_.controller.dt,
                           "the LQR near the top (no torque elsewhere)");
  return out;
}

PendubotRun simulate_pendubot_swingup(const PendubotScenario& scenario, bool log) {
  PendubotMode mode;
  if (SetupResult r = mode.setup(scenario); !r) {
    PendubotRun run;
    run.error = r.reason();
    return run;
  }
  std::vector<double> t, u;
  std::vector<Eigen::Vector4d> x;
  std::vector<std::uint8_t> lqr;
  if (log) {
    const std::size_t n = std::size_t(mode.steps_total()) + 1;
    t.reserve(n);
    x.reserve(n);
    u.reserve(n);
    lqr.reserve(n);
  }
  while (mode.step()) {
    if (!log) continue;
    const Telemetry& s = mode.telemetry();
    t.push_back(s.t);
    x.push_back(s.x);
    u.push_back(s.u(0));
    lqr.push_back(s.channels[kPendubotLqrActive].value != 0.0);
  }
  if (log) {  // the final state
    t.push_back(double(mode.steps_done()) * mode.dt());
    x.push_back(mode.state());
    u.push_back(0.0);
    lqr.push_back(mode.lqr_active());
  }
  PendubotRun run = mode.result();
  run.t = std::move(t);
  run.x = std::move(x);
  run.u = std::move(u);
  run.lqr = std::move(lqr);
  return run;
}


}  // namespace mixpilot
