#include "core/modes/tracking.hpp"

#include "core/numerics/dare.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <Eigen/Dense>

#include "core/control/crazyflie_tracking.hpp"
#include "core/nlp/rti.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/toml_read.hpp"
#include "core/nlp/trajectory_io.hpp"

namespace mixpilot {

// ---------------------------------------------------------------------------------------------
// Reference

OcpTrajectory helix_reference(const TrackingHelix& hx, double dt, const models::Crazyflie& model) {
  const int n = std::max(1, int(std::lround(hx.length / dt)));
  OcpTrajectory ref;
  ref.x.assign(std::size_t(n) + 1, Eigen::VectorXd::Zero(models::Crazyflie::nx));
  ref.u.assign(std::size_t(n), model.hover_input());
  const double cx = -hx.radius * std::cos(hx.phase), cy = -hx.radius * std::sin(hx.phase);
  for (int i = 0; i <= n; ++i) {
    const double t = i * dt, a = hx.phase + hx.angular_rate * t;
    Eigen::VectorXd& x = ref.x[std::size_t(i)];
    x.head<3>() << cx + hx.radius * std::cos(a), cy + hx.radius * std::sin(a),
        hx.start_height + hx.climb_rate * t;
    x(3) = 1.0;  // q = identity: body velocity = world velocity
    if (i < n) {
      x.segment<3>(7) << -hx.radius * hx.angular_rate * std::sin(a),
          hx.radius * hx.angular_rate * std::cos(a), hx.climb_rate;
    }
  }
  return ref;
}

// ---------------------------------------------------------------------------------------------
// Scenario

namespace {

using namespace toml_read;  // NOLINT: the reading vocabulary of this file

const char* unit_closed_check(double v) { return unit_closed(v); }

// Whole number of `unit`s in v (to rounding).
bool whole(double v) { return std::abs(v - std::round(v)) <= 1e-9 * std::max(1.0, std::abs(v)); }

std::string resolve_file(const std::string& file, const std::string& source_name) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  if (p.is_absolute()) return file;
  const fs::path beside = fs::path(source_name).parent_path() / p;
  std::error_code ec;
  if (fs::exists(beside, ec)) return beside.string();
  return file;  // relative to the working directory (the repository, when run from it)
}

TrackingScenario read_tracking(const toml::table& root, const std::string& source_name,
                               Diagnostics& d) {
  TrackingScenario sc;
  Section s(d, &root, "", Pos{1, 1});
  s.string("name", sc.name, true);
  std::string mode, model;
  s.choice("mode", mode, {"crazyflie_tracking"}, true);
  s.choice("model", model, {"crazyflie"}, true);
  s.num("duration", sc.duration, positive);

  Section c = s.sub("controller");
  std::string kind;
  if (c.choice("kind", kind, {"nmpc", "lqr"}))
    sc.controller.kind = kind == "lqr" ? TrackingControllerKind::lqr : TrackingControllerKind::nmpc;
  c.integer("N", sc.controller.N, int_positive);
  const bool dt_ok = c.num("dt", sc.controller.dt, positive) || !c.table() || !c.table()->get("dt");
  c.boolean("compensation", sc.controller.compensation);
  c.finish();

  Section pl = s.sub("plant");
  const bool rate_ok =
      pl.num("rate_hz", sc.plant.rate_hz, at_least_1000) || !pl.table() || !pl.table()->get("rate_hz");
  const bool rtt_ok = pl.num("rtt", sc.plant.rtt, non_negative) || !pl.table() || !pl.table()->get("rtt");
  pl.num("measurement_fraction", sc.plant.measurement_fraction, unit_closed_check);
  pl.vec("start", sc.plant.start);
  pl.finish();
  // Whole substeps per control period and per round trip (core/modes/tracking.hpp, delay model).
  if (dt_ok && rate_ok && !whole(sc.controller.dt * sc.plant.rate_hz)) {
    d.add(pl.pos("rate_hz"), pl.path("rate_hz"),
          "expected a rate giving a whole number of substeps per control step, got controller.dt "
          "* rate_hz = " + fmt(sc.controller.dt * sc.plant.rate_hz));
  }
  if (rtt_ok && rate_ok && !whole(sc.plant.rtt * sc.plant.rate_hz)) {
    d.add(pl.pos("rtt"), pl.path("rtt"),
          "expected a whole number of plant substeps (1/rate_hz), got rtt * rate_hz = " +
              fmt(sc.plant.rtt * sc.plant.rate_hz));
  }

  Section r = s.sub("reference");
  std::string rk = "smooth_step";
  r.choice("kind", rk, {"smooth_step", "helix"});
  sc.reference.kind = rk == "helix" ? TrackingReferenceKind::helix : TrackingReferenceKind::smooth_step;
  const bool file_given = r.string("file", sc.reference.file);
  TrackingHelix& hx = sc.reference.helix;
  r.num("radius", hx.radius, non_negative);
  r.num("start_height", hx.start_height);
  r.num("climb_rate", hx.climb_rate);
  r.num("angular_rate", hx.angular_rate);
  r.num("phase", hx.phase);
  const bool length_ok = r.num("length", hx.length, positive) || !r.table() || !r.table()->get("length");
  const models::Crazyflie cf{};
  if (sc.reference.kind == TrackingReferenceKind::smooth_step) {
    for (const char* k : {"radius", "start_height", "climb_rate", "angular_rate", "phase", "length"}) {
      if (r.table() && r.table()->get(k))
        d.add(r.pos(k), r.path(k), "only for kind = \"helix\" (this reference is a smooth_step)");
    }
    if (!file_given && !(r.table() && r.table()->get("file"))) {
      d.add(r.pos(), r.path("file"),
            "missing required key for kind = \"smooth_step\" (expected the path of a trajectory CSV)");
    } else if (file_given) {
      sc.reference.file = resolve_file(sc.reference.file, source_name);
      std::string err;
      const auto f = read_trajectory_csv(sc.reference.file, err);
      if (!f) {
        d.add(r.pos("file"), r.path("file"), "expected a readable trajectory CSV: " + err);
      } else if (f->trajectory.x.empty() || f->trajectory.x[0].size() != cf.nx ||
                 f->trajectory.u.empty() || f->trajectory.u[0].size() != cf.nu) {
        d.add(r.pos("file"), r.path("file"),
              "expected a Crazyflie trajectory (13 states, 4 inputs), in " + sc.reference.file);
      } else if (dt_ok && std::abs(f->dt - sc.controller.dt) > 1e-9) {
        d.add(r.pos("file"), r.path("file"),
              "expected nodes every controller.dt = " + fmt(sc.controller.dt) + " s, got " +
                  fmt(f->dt) + " s in " + sc.reference.file);
      } else {
        sc.reference_trajectory = f->trajectory;
      }
    }
  } else {
    if (file_given) d.add(r.pos("file"), r.path("file"), "only for kind = \"smooth_step\"");
    if (length_ok && dt_ok && !whole(hx.length / sc.controller.dt)) {
      d.add(r.pos("length"), r.path("length"),
            "expected a whole number of controller.dt, got length / dt = " +
                fmt(hx.length / sc.controller.dt));
    } else if (length_ok && dt_ok) {
      sc.reference_trajectory = helix_reference(hx, sc.controller.dt, cf);
    }
  }
  r.finish();
  s.finish();
  return sc;
}

}  // namespace

std::optional<TrackingScenario> parse_tracking_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error) {
  return parse_document<TrackingScenario>(text, source_name, error, [&](const toml::table& root, Diagnostics& d) {
    return read_tracking(root, source_name, d);
  });
}

std::optional<TrackingScenario> load_tracking_scenario(const std::string& path, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_tracking_scenario(text, path, error);
}

// ---------------------------------------------------------------------------------------------
// Predictor

namespace {
// ⌊a / b⌋ for b > 0.
long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
}  // namespace

void DelayPredictor::setup(const models::Crazyflie& model, int substeps_per_period, double h,
                           int rtt_substeps) {
  erk4_ = IntegratorErk4<models::Crazyflie>(model);
  s_ = std::max(1, substeps_per_period);
  h_ = h;
  n_r_ = std::max(0, rtt_substeps);
  sent_.assign(std::size_t((n_r_ + s_ - 1) / s_ + 1), Input::Zero());
  k_ = 0;
}

void DelayPredictor::reset() { k_ = 0; }

void DelayPredictor::record_sent(const Input& u) {
  sent_[std::size_t(k_ % long(sent_.size()))] = u;
  ++k_;
}

void DelayPredictor::predict(const State& measured, State& predicted) const {
  // Substeps σ_j = j·h for j in [k·s − n_r, k·s); before j = 0 the vehicle rests.
  const long end = k_ * s_;
  State x = measured, xn;
  for (long j = std::max(0L, end - n_r_); j < end; ++j) {
    const long m = floor_div(j, s_);  // the command in effect on this substep (m < k)
    erk4_.step<double>(x, sent_[std::size_t(m % long(sent_.size()))], h_, xn);
    x = xn;
  }
  predicted = x;
}

// ---------------------------------------------------------------------------------------------
// LQR

Eigen::Matrix<double, 12, 1> TrackingLqr::q_diagonal() {
  Eigen::Matrix<double, 12, 1> q;
  q << 12.24e3, 10.2e3, 9e5,   // p
      0.102, 0.102, 0.102,     // q_x, q_y, q_z
      71.4, 102, 408,          // v_b
      1.02e-3, 1.02e-3, 1.02e3;  // ω
  return q;
}

Eigen::Matrix<double, 12, 1> TrackingLqr::reduce(const State& x) {
  Eigen::Matrix<double, 12, 1> z;
  z << x.head<3>(), x.segment<9>(4);
  return z;
}

bool TrackingLqr::setup(const models::Crazyflie& model, double dt) {
  const IntegratorErk4<models::Crazyflie> erk4(model);
  const State xh = model.hover_state(Eigen::Vector3d::Zero());
  u_hover_ = model.hover_input();
  State xn;
  Eigen::Matrix<double, 13, 13> A13;
  Eigen::Matrix<double, 13, 4> B13;
  erk4.step(xh, u_hover_, dt, xn, A13, B13);
  // Rows and columns of q_w dropped: at hover ∂q_w/∂q_v = −q_v/q_w = 0.
  const int keep[12] = {0, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) A_(i, j) = A13(keep[i], keep[j]);
    B_.row(i) = B13.row(keep[i]);
  }
  const Eigen::MatrixXd Q = q_diagonal().asDiagonal();
  const Eigen::MatrixXd R = Eigen::MatrixXd::Identity(4, 4) * r_weight();
  Eigen::MatrixXd P;
  if (!solve_dare(A_, B_, Q, R, P)) return false;
  P_ = P;
  const Eigen::Matrix4d S = B_.transpose() * P_ * B_ + Eigen::Matrix4d::Identity() * r_weight();
  K_ = S.ldlt().solve(B_.transpose() * P_ * A_);
  const Mat12 res = A_.transpose() * P_ * A_ - P_ -
                    (A_.transpose() * P_ * B_) * S.ldlt().solve(B_.transpose() * P_ * A_) +
                    Mat12(Q);
  residual_ = res.lpNorm<Eigen::Infinity>() / P_.lpNorm<Eigen::Infinity>();
  u_min_ = model.p.omega_min;
  u_max_ = model.p.omega_max;
  return true;
}

void TrackingLqr::control(const State& x, const State& x_ref, const Input& u_ref, Input& u) const {
  u = u_ref - K_ * (reduce(x) - reduce(x_ref));
  u = u.cwiseMax(u_min_).cwiseMin(u_max_);
}

// ---------------------------------------------------------------------------------------------
// Closed loop

namespace {

double nth_of(std::vector<double> t, double q) {
  if (t.empty()) return 0.0;
  const std::size_t i = std::min(t.size() - 1, std::size_t(std::floor(q * double(t.size() - 1) + 0.5)));
  std::nth_element(t.begin(), t.begin() + std::ptrdiff_t(i), t.end());
  return t[i];
}

}  // namespace

TrackingResult run_tracking(const TrackingScenario& sc, TrackingLog* log) {
  using State = models::Crazyflie::State;
  using Input = models::Crazyflie::Input;
  TrackingResult res;
  const TrackingControllerSettings& c = sc.controller;
  const TrackingPlantSettings& pl = sc.plant;
  const OcpTrajectory& ref = sc.reference_trajectory;
  if (ref.x.empty() || ref.u.empty()) {
    res.error = "no reference trajectory";
    return res;
  }
  const models::Crazyflie model{};
  const IntegratorErk4<models::Crazyflie> erk4(model);
  const long s = std::max(1L, std::lround(c.dt * pl.rate_hz));  // substeps per period
  const double h = c.dt / double(s);
  const long n_r = std::lround(pl.rtt * pl.rate_hz);
  const long n_m = std::lround(pl.measurement_fraction * double(n_r));
  const long n_c = n_r - n_m;
  const long K = std::max(1L, std::lround(sc.duration / c.dt));
  res.rtt_substeps = int(n_r);
  res.measurement_substeps = int(n_m);
  res.command_substeps = int(n_c);

  // Controller.
  std::unique_ptr<CrazyflieTracking> problem;
  RtiSolver rti;
  TrackingLqr lqr;
  if (c.kind == TrackingControllerKind::nmpc) {
    problem = std::make_unique<CrazyflieTracking>(c.N, c.dt, model);
    if (!rti.setup(problem->ocp())) {
      res.error = "the tracking OCP is invalid";
      return res;
    }
    problem->hover_guess(rti.trajectory(), pl.start);
  } else if (!lqr.setup(model, c.dt)) {
    res.error = "the LQR's Riccati equation did not converge";
    return res;
  }
  DelayPredictor predictor;
  predictor.setup(model, int(s), h, int(n_r));

  // Plant: states at the last n_m + 1 substep boundaries, the last commands.
  const State x_init = model.hover_state(pl.start);
  std::vector<State> hist(std::size_t(n_m + 1), x_init);
  std::vector<Input> cmds(std::size_t((n_c + s - 1) / s + 2), Input::Zero());
  State x = x_init, xn;
  long j = 0;  // plant substep boundary

  // Error samples m = 0..K at boundaries m·s + n_c (σ = t_m).
  std::vector<double> err2;
  err2.reserve(std::size_t(K) + 1);
  std::vector<double> solve_us(static_cast<std::size_t>(K)), predict_us(static_cast<std::size_t>(K));
  if (log) {
    *log = TrackingLog{};
    log->t.reserve(std::size_t(K) + 1);
    log->p.reserve(std::size_t(K) + 1);
    log->p_ref.reserve(std::size_t(K) + 1);
    log->x_true.reserve(std::size_t(K) + 1);
    log->x0.reserve(std::size_t(K));
    log->u.reserve(std::size_t(K));
  }
  const long last_x = long(ref.x.size()) - 1;
  const long last_u = long(ref.u.size()) - 1;
  const Eigen::Vector3d start = ref.x.front().head<3>(), target = ref.x.back().head<3>();
  const bool step_ref = sc.reference.kind == TrackingReferenceKind::smooth_step;
  const Eigen::Vector3d step = target - start;
  const double step_len = step.norm();
  const Eigen::Vector3d dir = step_len > 0 ? Eigen::Vector3d(step / step_len) : Eigen::Vector3d::Zero();
  double max_progress = 0;
  long last_outside = -1;

  const auto sample = [&](long m) {
    const Eigen::Vector3d p = x.head<3>();
    const Eigen::Vector3d pr = ref.x[std::size_t(std::min(m, last_x))].head<3>();
    const double e = (p - pr).norm();
    err2.push_back(e * e);
    res.max_error_m = std::max(res.max_error_m, e);
    res.final_error_m = e;
    if (step_ref) {
      max_progress = std::max(max_progress, (p - start).dot(dir));
      if ((p - target).norm() > tracking_defaults::kSettleRadius) last_outside = m;
    }
    if (log) {
      log->t.push_back(double(m) * c.dt);
      log->p.push_back(p);
      log->p_ref.push_back(pr);
      log->x_true.push_back(x);
    }
  };
  // Simulates the plant to boundary `end`; false when the vehicle is lost.
  const auto advance_to = [&](long end) {
    while (j < end) {
      const long m = floor_div(j - n_c, s);  // command on the rotors during this substep
      if (m >= 0) {
        erk4.step<double>(x, cmds[std::size_t(m % long(cmds.size()))], h, xn);
        x = xn;
      }
      ++j;
      hist[std::size_t(j % long(hist.size()))] = x;
      if (!x.allFinite() || (x.head<3>() - pl.start).norm() > tracking_defaults::kLostRadius)
        return false;
      if ((j - n_c) % s == 0 && j >= n_c) sample((j - n_c) / s);
    }
    return true;
  };

  if (n_c == 0) sample(0);
  State y, x0;
  Input u;
  bool alive = true;
  long k = 0;
  for (; k < K && alive; ++k) {
    // Measurement: the state of boundary k·s − n_m (the initial state before the start).
    const long b = k * s - n_m;
    y = b <= 0 ? x_init : hist[std::size_t(b % long(hist.size()))];
    const auto t0 = std::chrono::steady_clock::now();
    if (c.compensation) {
      predictor.predict(y, x0);
    } else {
      x0 = y;
    }
    const auto t1 = std::chrono::steady_clock::now();
    predict_us[std::size_t(k)] = std::chrono::duration<double, std::micro>(t1 - t0).count();
    if (problem) {
      problem->set_reference(rti.data(), ref, int(k));
      rti.prepare();
      rti.feedback(x0);
      u = rti.control();
      rti.shift();
      solve_us[std::size_t(k)] = rti.stats().total_us;
    } else {
      const auto l0 = std::chrono::steady_clock::now();
      const Eigen::VectorXd& xr = ref.x[std::size_t(std::min(k, last_x))];
      lqr.control(x0, State(xr), Input(ref.u[std::size_t(std::min(k, last_u))]), u);
      solve_us[std::size_t(k)] =
          std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - l0).count();
    }
    res.max_input_violation =
        std::max({res.max_input_violation, model.p.omega_min - u.minCoeff(),
                  u.maxCoeff() - model.p.omega_max});
    predictor.record_sent(u);
    cmds[std::size_t(k % long(cmds.size()))] = u;
    if (log) {
      log->x0.push_back(x0);
      log->u.push_back(u);
    }
    alive = advance_to((k + 1) * s);
  }
  if (alive) alive = advance_to(K * s + n_c);  // the last command's effect, to sample m = K
  res.lost = !alive;
  res.steps = int(k);
  solve_us.resize(std::size_t(k));
  predict_us.resize(std::size_t(k));

  double sum = 0;
  for (double e : err2) sum += e;
  res.tracking_rms_m = err2.empty() ? 0.0 : std::sqrt(sum / double(err2.size()));
  if (step_ref) {
    res.overshoot_m = std::max(0.0, max_progress - step_len);
    res.settle_time_s = double(last_outside + 1) * c.dt;
  }
  res.solve_median_us = nth_of(solve_us, 0.5);
  res.solve_p99_us = nth_of(solve_us, 0.99);
  res.predictor_median_us = c.compensation ? nth_of(predict_us, 0.5) : 0.0;
  res.fallbacks = problem ? long(rti.stats().fallbacks) : 0;
  res.ok = true;
  return res;
}

// ---------------------------------------------------------------------------------------------
// Mode runner

ModeResult fly_crazyflie_tracking(const std::string& path, const ModeOptions& options) {
  ModeResult out;
  std::optional<TrackingScenario> sc = load_tracking_scenario(path, out.error);
  if (!sc) return out;
  if (options.duration) sc->duration = *options.duration;
  const TrackingResult r = run_tracking(*sc);
  if (!r.ok) {
    out.error = path + ": " + r.error;
    return out;
  }
  const bool nmpc = sc->controller.kind == TrackingControllerKind::nmpc;
  const bool step = sc->reference.kind == TrackingReferenceKind::smooth_step;
  auto& m = out.metrics;
  m.emplace_back("tracking_rms_m", r.tracking_rms_m);
  m.emplace_back("max_error_m", r.max_error_m);
  m.emplace_back("final_error_m", r.final_error_m);
  if (step) {
    m.emplace_back("overshoot_m", r.overshoot_m);
    m.emplace_back("settle_time_s", r.settle_time_s);
  }
  m.emplace_back(nmpc ? "rti_median_us" : "lqr_median_us", r.solve_median_us);
  m.emplace_back(nmpc ? "rti_p99_us" : "lqr_p99_us", r.solve_p99_us);
  if (nmpc) m.emplace_back("fallbacks", double(r.fallbacks));
  m.emplace_back("predictor_median_us", r.predictor_median_us);
  m.emplace_back("max_input_violation", r.max_input_violation);
  m.emplace_back("rtt_s", sc->plant.rtt);
  m.emplace_back("compensation", sc->controller.compensation ? 1.0 : 0.0);
  m.emplace_back("steps", double(r.steps));
  m.emplace_back("lost", r.lost ? 1.0 : 0.0);

  char buf[512];
  std::snprintf(buf, sizeof buf,
                "mixpilot fly: %s (crazyflie_tracking, %s, %s, RTT %.0f ms, compensation %s)\n"
                "  %d steps; tracking RMS %.4f m, max %.4f m, final %.4f m",
                sc->name.c_str(), nmpc ? "NMPC" : "LQR", step ? "smooth step" : "helix",
                1e3 * sc->plant.rtt, sc->controller.compensation ? "on" : "off", r.steps,
                r.tracking_rms_m, r.max_error_m, r.final_error_m);
  out.summary = buf;
  if (step) {
    std::snprintf(buf, sizeof buf, "; overshoot %.4f m, settled at %.2f s", r.overshoot_m,
                  r.settle_time_s);
    out.summary += buf;
  }
  std::snprintf(buf, sizeof buf, "\n  %s median %.0f us, p99 %.0f us%s; predictor median %.1f us%s\n",
                nmpc ? "RTI" : "LQR", r.solve_median_us, r.solve_p99_us,
                nmpc ? (", " + std::to_string(r.fallbacks) + " fallbacks").c_str() : "",
                r.predictor_median_us, r.lost ? "\n  the vehicle was lost" : "");
  out.summary += buf;
  out.ok = true;
  return out;
}

}  // namespace mixpilot
