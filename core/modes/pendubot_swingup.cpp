#include "core/modes/pendubot_swingup.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include <Eigen/Dense>

#include "core/nlp/rti.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/toml_read.hpp"

namespace mixpilot {

// ---------------------------------------------------------------------------------------------
// OCP (SPEC §5.1)

PendubotSwingup::PendubotSwingup(const PendubotOcpSettings& settings, const models::Pendubot& model)
    : settings_(settings),
      integrator_(model),
      output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi::LinSpaced(nu, 0, nu - 1)),
      terminal_output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi()) {
  ocp_.integrator = &integrator_;
  ocp_.N = settings.N;
  ocp_.dt = settings.dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::Zero(1);
  ocp_.lbu = Eigen::VectorXd::Constant(1, -settings.u_max);
  ocp_.ubu = Eigen::VectorXd::Constant(1, settings.u_max);
  ocp_.idxbx.resize(2);
  ocp_.idxbx << 2, 3;
  ocp_.lbx.resize(2);
  ocp_.lbx << -settings.velocity_bound(0), -settings.velocity_bound(1);
  ocp_.ubx.resize(2);
  ocp_.ubx << settings.velocity_bound(0), settings.velocity_bound(1);
  if (settings.soft_velocity_bounds) {
    for (int j = 0; j < 2; ++j) {
      SoftConstraint sc;
      sc.index = j;
      sc.Zl = sc.Zu = settings.slack_weight;
      ocp_.soft_state_bounds.push_back(sc);
    }
  }
}

void PendubotSwingup::set_reference(OcpStageData& data, const OcpTrajectory& ref, int k) const {
  const int last_u = int(ref.u.size()) - 1;
  const int last_x = int(ref.x.size()) - 1;
  const int N = ocp_.N;
  for (int i = 0; i < N; ++i) {
    const int j = k + i;
    data.yref[i].head<nx>() = ref.x[std::min(j, last_x)];
    data.yref[i](nx) = j <= last_u ? ref.u[j](0) : 0.0;  // past the end: hold up-up, u = 0
    data.W[i].diagonal() = settings_.weights;
  }
  data.yref[N] = ref.x[std::min(k + N, last_x)];
  data.W[N].diagonal() = settings_.terminal_weights;
}

void PendubotSwingup::set_up_target(OcpStageData& data) const {
  const int N = ocp_.N;
  for (int i = 0; i < N; ++i) {
    data.yref[i].setZero();
    data.W[i].diagonal() = settings_.weights;
  }
  data.yref[N].setZero();
  data.W[N].diagonal() = settings_.terminal_weights;
}

void PendubotSwingup::constant_guess(OcpTrajectory& traj, const State& x) {
  for (auto& xi : traj.x) xi = x;
  for (auto& ui : traj.u) ui.setZero();
}

// ---------------------------------------------------------------------------------------------
// Offline reference

void pendubot_energy_guess(const models::Pendubot& model, double dt, int N, double u_max,
                           OcpTrajectory& traj) {
  const IntegratorErk4<models::Pendubot> erk4(model);
  const double e_top = model.energy(models::Pendubot::up_up());
  traj.x.assign(N + 1, Eigen::VectorXd::Zero(4));
  traj.u.assign(N, Eigen::VectorXd::Zero(1));
  models::Pendubot::State x = models::Pendubot::down_down(), xn;
  traj.x[0] = x;
  for (int i = 0; i < N; ++i) {
    // Pump energy into link 1 (dE/dt = u q̇1), keep link 2 in line with link 1; start with a
    // push, since at rest q̇1 = 0.
    double u = 40.0 * (e_top - model.energy(x)) * x(2) - 0.2 * wrap_angle(x(1)) - 0.02 * x(3);
    if (std::abs(x(2)) < 0.05 && model.energy(x) < 0.05 * e_top) u = u_max;
    u = std::clamp(u, -u_max, u_max);
    erk4.step<double>(x, models::Pendubot::Input(u), dt, xn);
    x = xn;
    traj.u[i](0) = u;
    traj.x[i + 1] = x;
  }
}

namespace {

// One Ipopt solve of the reference OCP on (N, dt) from `traj`.
IpoptOcpResult solve_reference(const PendubotReferenceSettings& s, int N, double dt,
                               const models::Pendubot& model, OcpTrajectory& traj) {
  PendubotOcpSettings os;
  os.N = N;
  os.dt = dt;
  os.u_max = s.u_max;
  os.velocity_bound = s.velocity_bound;
  os.soft_velocity_bounds = false;
  os.weights << s.angle_weight, s.angle_weight, s.velocity_weight, s.velocity_weight,
      s.input_weight;
  // Stage costs are sums over intervals: scale with dt so both grids weigh the same integral.
  os.weights *= dt / s.dt;
  os.terminal_weights << s.terminal_weight, s.terminal_weight, 0.1 * s.terminal_weight,
      0.1 * s.terminal_weight;
  const PendubotSwingup problem(os, model);
  OcpStageData data(problem.ocp());
  problem.set_up_target(data);
  IpoptOcpSolver solver(s.ipopt);
  return solver.solve(problem.ocp(), data, models::Pendubot::down_down(), traj);
}

void linear_guess(int N, double dt, OcpTrajectory& traj) {
  traj.x.assign(N + 1, Eigen::VectorXd::Zero(4));
  traj.u.assign(N, Eigen::VectorXd::Zero(1));
  for (int i = 0; i <= N; ++i) {
    traj.x[i](0) = -std::numbers::pi * (1.0 - double(i) / N);
    traj.x[i](2) = std::numbers::pi / (N * dt);
  }
}

}  // namespace

PendubotReferenceResult compute_pendubot_reference(const PendubotReferenceSettings& s,
                                                   const models::Pendubot& model) {
  PendubotReferenceResult r;
  OcpTrajectory& fine = r.trajectory;
  const int f = s.coarse_factor;
  if (f > 1 && s.N % f == 0) {
    const int Nc = s.N / f;
    OcpTrajectory coarse;
    if (s.guess == 0) {
      linear_guess(Nc, s.dt * f, coarse);
    } else {
      pendubot_energy_guess(model, s.dt * f, Nc, s.u_max, coarse);
    }
    r.coarse = solve_reference(s, Nc, s.dt * f, model, coarse);
    fine.x.assign(s.N + 1, Eigen::VectorXd::Zero(4));
    fine.u.assign(s.N, Eigen::VectorXd::Zero(1));
    for (int i = 0; i <= s.N; ++i) {
      const int j = std::min(i / f, Nc - 1);
      const double w = double(i - j * f) / f;
      fine.x[i] = (1.0 - w) * coarse.x[j] + w * coarse.x[j + 1];
      if (i < s.N) fine.u[i] = coarse.u[j];
    }
  } else if (s.guess == 0) {
    linear_guess(s.N, s.dt, fine);
  } else {
    pendubot_energy_guess(model, s.dt, s.N, s.u_max, fine);
  }
  // Ipopt's variable bounds want an interior start.
  for (std::size_t i = 1; i < fine.x.size(); ++i) {
    for (int j = 0; j < 2; ++j) {
      const double b = 0.999 * s.velocity_bound(j);
      fine.x[i](2 + j) = std::clamp(fine.x[i](2 + j), -b, b);
    }
  }
  r.ipopt = solve_reference(s, s.N, s.dt, model, fine);
  for (const auto& u : fine.u) r.max_abs_u = std::max(r.max_abs_u, std::abs(u(0)));
  for (const auto& x : fine.x) {
    r.max_abs_velocity = r.max_abs_velocity.cwiseMax(x.tail<2>().cwiseAbs());
  }
  r.final_error = fine.x.back().cwiseAbs().maxCoeff();
  return r;
}

// ---------------------------------------------------------------------------------------------
// LQR

double wrap_angle(double a) {
  constexpr double kPi = std::numbers::pi;
  a = std::remainder(a, 2.0 * kPi);  // [−π, π]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

PendubotLqr pendubot_lqr(const models::Pendubot& model, double dt, const Eigen::Vector4d& q,
                         double r, int max_iterations) {
  PendubotLqr l;
  const IntegratorErk4<models::Pendubot> erk4(model);
  Eigen::Matrix<double, 4, 1> xn;
  Eigen::Matrix<double, 4, 4> A;
  Eigen::Matrix<double, 4, 1> B;
  erk4.step(models::Pendubot::up_up(), models::Pendubot::Input::Zero(), dt, xn, A, B);
  l.A = A;
  l.B = B;
  const Eigen::Matrix4d Q = q.asDiagonal();
  Eigen::Matrix4d P = Q;
  for (l.iterations = 1; l.iterations <= max_iterations; ++l.iterations) {
    const Eigen::RowVector4d BtPA = B.transpose() * P * A;
    const double s = r + B.dot(P * B);
    Eigen::Matrix4d Pn = Q + A.transpose() * P * A - BtPA.transpose() * BtPA / s;
    Pn = 0.5 * (Pn + Pn.transpose());
    const double change = (Pn - P).cwiseAbs().maxCoeff();
    P = Pn;
    if (change <= 1e-13 * P.cwiseAbs().maxCoeff()) {
      l.converged = true;
      break;
    }
  }
  l.P = P;
  l.K = (B.transpose() * P * A) / (r + B.dot(P * B));
  const Eigen::Matrix4d Acl = A - B * l.K;
  l.spectral_radius = Acl.eigenvalues().cwiseAbs().maxCoeff();
  return l;
}

// ---------------------------------------------------------------------------------------------
// Scenario

namespace {

using namespace toml_read;  // NOLINT: the reading vocabulary of this file

PendubotScenario read_pendubot(const toml::table& root, const std::string& source_name,
                               Diagnostics& d) {
  PendubotScenario sc;
  Section s(d, &root, "", Pos{1, 1});
  s.string("name", sc.name, true);
  std::string mode, model;
  s.choice("mode", mode, {"pendubot_swingup"}, true);
  s.choice("model", model, {"pendubot"}, true);
  s.num("duration", sc.duration, positive);
  s.num("angle_tolerance", sc.angle_tolerance, positive);

  Section c = s.sub("controller");
  PendubotOcpSettings& oc = sc.controller;
  c.integer("N", oc.N, int_positive);
  c.num("dt", oc.dt, positive);
  c.num("u_max", oc.u_max, positive);
  Eigen::Vector2d vb = oc.velocity_bound;
  if (c.vec("velocity_bound", vb, positive)) oc.velocity_bound = vb;
  c.num("slack_weight", oc.slack_weight, positive);
  Eigen::Matrix<double, 5, 1> w = oc.weights;
  if (c.vec("weights", w, non_negative)) oc.weights = w;
  if (oc.weights(4) <= 0) {
    d.add(c.pos("weights"), c.path("weights") + "[4]",
          "expected a positive input weight (the Riccati input pivots need it), got " +
              fmt(oc.weights(4)));
  }
  Eigen::Vector4d wn = oc.terminal_weights;
  if (c.vec("terminal_weights", wn, non_negative)) oc.terminal_weights = wn;
  const bool ref_given = c.string("reference", sc.reference_path, true);
  std::string qp;
  if (c.choice("qp_solver", qp, {"condensed_active_set", "condensed_dense", "riccati_ipm"})) {
    oc.qp_solver = qp == "riccati_ipm"       ? QpSolverKind::riccati_ipm
                   : qp == "condensed_dense" ? QpSolverKind::condensed_dense
                                             : QpSolverKind::condensed_active_set;
  }
  c.finish();

  Section l = s.sub("lqr");
  l.boolean("enabled", sc.lqr.enabled);
  Eigen::Vector4d lq = sc.lqr.q;
  if (l.vec("q", lq, non_negative)) sc.lqr.q = lq;
  l.num("r", sc.lqr.r, positive);
  l.num("enter_angle", sc.lqr.enter_angle, positive);
  l.num("enter_velocity", sc.lqr.enter_velocity, positive);
  l.num("exit_angle", sc.lqr.exit_angle, positive);
  if (sc.lqr.exit_angle <= sc.lqr.enter_angle) {
    d.add(l.pos("exit_angle"), l.path("exit_angle"),
          "expected more than lqr.enter_angle = " + fmt(sc.lqr.enter_angle) +
              " (hysteresis), got " + fmt(sc.lqr.exit_angle));
  }
  l.finish();

  Section p = s.sub("plant");
  const bool rate_given = p.num("rate_hz", sc.plant.rate_hz, at_least_1000);
  Eigen::Vector4d x0 = sc.plant.initial_state;
  if (p.vec("initial_state", x0)) sc.plant.initial_state = x0;
  p.finish();
  const double substeps = oc.dt * sc.plant.rate_hz;
  if (sc.plant.rate_hz >= 1000 && oc.dt > 0 &&
      std::abs(substeps - std::round(substeps)) > 1e-9 * substeps) {
    d.add(rate_given ? p.pos("rate_hz") : p.pos(), p.path("rate_hz"),
          "expected a rate giving a whole number of substeps per control step, got controller.dt "
          "* rate_hz = " + fmt(substeps));
  }

  Section e = s.sub("sensor");
  e.boolean("quantization", sc.sensor.quantization);
  e.integer("counts_q1", sc.sensor.counts_q1, int_positive);
  e.integer("counts_q2", sc.sensor.counts_q2, int_positive);
  e.num("velocity_cutoff_hz", sc.sensor.velocity_cutoff_hz, non_negative);
  e.choice("estimator", sc.sensor.estimator, {"difference", "observer"});
  e.num("observer_alpha", sc.sensor.observer_alpha, unit_open);
  e.num("observer_beta", sc.sensor.observer_beta, unit_open);
  e.finish();
  s.finish();

  // The reference file, relative to the scenario's folder; it must fit the controller.
  if (ref_given) {
    namespace fs = std::filesystem;
    fs::path rp(sc.reference_path);
    if (rp.is_relative()) rp = fs::path(source_name).parent_path() / rp;
    std::string error;
    const auto ref = read_trajectory_csv(rp.string(), error);
    if (!ref) {
      d.add(c.pos("reference"), c.path("reference"), "expected a readable trajectory CSV: " + error);
    } else if (ref->trajectory.x.empty() || ref->trajectory.x[0].size() != 4 ||
               ref->trajectory.u.empty() || ref->trajectory.u[0].size() != 1) {
      d.add(c.pos("reference"), c.path("reference"),
            "expected a Pendubot trajectory (4 states, 1 input): " + rp.string());
    } else if (std::abs(ref->dt - oc.dt) > 1e-9 * oc.dt) {
      d.add(c.pos("reference"), c.path("reference"),
            "expected a trajectory sampled at controller.dt = " + fmt(oc.dt) + " s, got dt = " +
                fmt(ref->dt) + " s in " + rp.string());
    } else {
      sc.reference = *ref;
    }
  }
  return sc;
}

}  // namespace

std::optional<PendubotScenario> parse_pendubot_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error) {
  return parse_document<PendubotScenario>(text, source_name, error, [&](const toml::table& root, Diagnostics& d) {
    return read_pendubot(root, source_name, d);
  });
}

std::optional<PendubotScenario> load_pendubot_scenario(const std::string& path, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_pendubot_scenario(text, path, error);
}

// ---------------------------------------------------------------------------------------------
// Closed loop

namespace {

double quantize(double q, int counts) {
  const double step = 2.0 * std::numbers::pi / counts;
  return step * (std::floor(q / step) + 0.5);  // whole counts; the cell centre is unbiased
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, std::size_t(std::ceil(p * double(v.size()))) - 1);
  return v[std::max<std::size_t>(i, 0)];
}

}  // namespace

PendubotRun simulate_pendubot_swingup(const PendubotScenario& sc, bool log) {
  using Clock = std::chrono::steady_clock;
  const PendubotOcpSettings& oc = sc.controller;
  const PendubotSwingup problem(oc);
  const models::Pendubot& model = problem.model();
  const IntegratorErk4<models::Pendubot>& erk4 = problem.integrator();
  const OcpTrajectory& ref = sc.reference.trajectory;
  const PendubotLqr lqr = pendubot_lqr(model, oc.dt, sc.lqr.q, sc.lqr.r);

  RtiSolver rti;
  RtiSettings rti_settings;
  rti_settings.qp_solver = oc.qp_solver;
  if (!rti.setup(problem.ocp(), rti_settings)) return {};
  // Warm start from the reference itself.
  for (int i = 0; i <= oc.N; ++i) rti.trajectory().x[i] = ref.x[std::min<std::size_t>(i, ref.x.size() - 1)];
  for (int i = 0; i < oc.N; ++i) {
    rti.trajectory().u[i] = i < int(ref.u.size()) ? ref.u[i] : Eigen::VectorXd::Zero(1);
  }

  const int steps = int(std::llround(sc.duration / oc.dt));
  const int substeps = int(std::llround(oc.dt * sc.plant.rate_hz));
  const double h = oc.dt / substeps;
  const int ref_steps = int(ref.u.size());
  const double alpha =
      sc.sensor.velocity_cutoff_hz > 0 ? 1.0 - std::exp(-2.0 * std::numbers::pi *
                                                        sc.sensor.velocity_cutoff_hz * oc.dt)
                                       : 1.0;

  PendubotRun run;
  run.steps = steps;
  std::vector<double> rti_us;
  rti_us.reserve(std::size_t(steps));
  std::vector<double> angle_norm(std::size_t(steps) + 1);
  if (log) {
    run.t.reserve(std::size_t(steps) + 1);
    run.x.reserve(std::size_t(steps) + 1);
    run.u.reserve(std::size_t(steps) + 1);
    run.lqr.reserve(std::size_t(steps) + 1);
  }

  models::Pendubot::State x = sc.plant.initial_state, xn;
  Eigen::Vector4d xm = x;   // measured state
  Eigen::Vector2d q_prev(quantize(x(0), sc.sensor.counts_q1), quantize(x(1), sc.sensor.counts_q2));
  Eigen::Vector2d v_filt = Eigen::Vector2d::Zero();
  Eigen::VectorXd x0(4);
  bool lqr_active = false;
  const bool observer = sc.sensor.estimator == "observer";
  double u_prev = 0.0;
  double err2 = 0.0;
  int err_n = 0;
  const double b1 = oc.velocity_bound(0), b2 = oc.velocity_bound(1);

  for (int k = 0; k < steps; ++k) {
    // Sensor.
    if (sc.sensor.quantization && observer) {
      const Eigen::Vector2d q(quantize(x(0), sc.sensor.counts_q1),
                              quantize(x(1), sc.sensor.counts_q2));
      if (k == 0) {
        xm = Eigen::Vector4d(q(0), q(1), 0.0, 0.0);
      } else {
        erk4.step<double>(xm, models::Pendubot::Input(u_prev), oc.dt, xn);
        const Eigen::Vector2d e = q - xn.head<2>();
        xm.head<2>() = xn.head<2>() + sc.sensor.observer_alpha * e;
        xm.tail<2>() = xn.tail<2>() + (sc.sensor.observer_beta / oc.dt) * e;
      }
    } else if (sc.sensor.quantization) {
      const Eigen::Vector2d q(quantize(x(0), sc.sensor.counts_q1),
                              quantize(x(1), sc.sensor.counts_q2));
      const Eigen::Vector2d v_raw = (q - q_prev) / oc.dt;
      if (k > 0) v_filt += alpha * (v_raw - v_filt);
      q_prev = q;
      xm = Eigen::Vector4d(q(0), q(1), v_filt(0), v_filt(1));
    } else {
      xm = x;
    }
    Eigen::Vector4d xw = xm;
    xw(0) = wrap_angle(xm(0));
    xw(1) = wrap_angle(xm(1));
    angle_norm[std::size_t(k)] = std::hypot(wrap_angle(x(0)), wrap_angle(x(1)));

    // Switch rule (core/modes/pendubot_swingup.hpp).
    const double u_lqr = -lqr.K.dot(xw);
    const double a = xw.head<2>().norm();
    if (sc.lqr.enabled && !lqr_active && a <= sc.lqr.enter_angle &&
        xw.tail<2>().norm() <= sc.lqr.enter_velocity && std::abs(u_lqr) <= oc.u_max) {
      lqr_active = true;
      ++run.lqr_entries;
      if (run.lqr_entry_time < 0) run.lqr_entry_time = k * oc.dt;
    } else if (lqr_active && a > sc.lqr.exit_angle) {
      lqr_active = false;
      PendubotSwingup::constant_guess(rti.trajectory(), xw);  // restart towards up-up
    }

    double u = 0.0;
    if (lqr_active) {
      u = u_lqr;
      run.lqr_time += oc.dt;
    } else {
      // NMPC from the measurement; angles unwrapped as measured when tracking the reference,
      // wrapped once the reference is over (then the target is up-up).
      const bool tracking = k < ref_steps;
      x0 = tracking ? xm : xw;
      if (!tracking && k == ref_steps) {
        // Re-express the warm start around the wrapped angles.
        for (auto& xi : rti.trajectory().x) {
          xi(0) += xw(0) - xm(0);
          xi(1) += xw(1) - xm(1);
        }
      }
      problem.set_reference(rti.data(), ref, k);
      const auto t0 = Clock::now();
      rti.prepare();
      rti.feedback(x0);
      u = rti.control()(0);
      rti.shift();
      rti_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
      ++run.nmpc_steps;
      if (tracking) {
        err2 += (x.head<2>() - ref.x[std::size_t(k)].head<2>()).squaredNorm();
        ++err_n;
      }
    }
    if (!std::isfinite(u)) u = 0.0;
    u = std::clamp(u, -oc.u_max, oc.u_max);  // guards rounding only: the QP bounds u
    run.max_abs_u = std::max(run.max_abs_u, std::abs(u));
    u_prev = u;
    if (log) {
      run.t.push_back(k * oc.dt);
      run.x.push_back(x);
      run.u.push_back(u);
      run.lqr.push_back(lqr_active);
    }

    // Plant: RK4 substeps, input held.
    double worst = 0.0;
    for (int j = 0; j < substeps; ++j) {
      erk4.step<double>(x, models::Pendubot::Input(u), h, xn);
      x = xn;
      worst = std::max({worst, std::abs(x(2)) - b1, std::abs(x(3)) - b2});
    }
    if (worst > 0) {
      ++run.velocity_violations;
      run.worst_velocity_violation = std::max(run.worst_velocity_violation, worst);
    }
  }
  angle_norm[std::size_t(steps)] = std::hypot(wrap_angle(x(0)), wrap_angle(x(1)));
  if (log) {
    run.t.push_back(steps * oc.dt);
    run.x.push_back(x);
    run.u.push_back(0.0);
    run.lqr.push_back(lqr_active);
  }

  run.final_angle_norm = angle_norm.back();
  for (int k = steps; k >= 0 && angle_norm[std::size_t(k)] <= sc.angle_tolerance; --k) {
    run.swingup_time = k * oc.dt;
  }
  run.tracking_rms = err_n > 0 ? std::sqrt(err2 / err_n) : 0.0;
  run.rti_median_us = percentile(rti_us, 0.5);
  run.rti_p99_us = percentile(rti_us, 0.99);
  run.rti_max_us = rti_us.empty() ? 0.0 : *std::max_element(rti_us.begin(), rti_us.end());
  run.fallbacks = rti.stats().fallbacks;
  return run;
}

ModeResult fly_pendubot_swingup(const std::string& path, const ModeOptions& options) {
  ModeResult r;
  auto sc = load_pendubot_scenario(path, r.error);
  if (!sc) return r;
  if (options.duration) sc->duration = *options.duration;
  const PendubotRun run = simulate_pendubot_swingup(*sc);

  const double swingup = run.swingup_time.value_or(-1.0);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "pendubot_swingup %s: %.2f s, %s, NMPC N = %d at dt = %.0f ms%s\n", sc->name.c_str(),
                sc->duration, sc->sensor.quantization ? "encoders (quantized)" : "exact state",
                sc->controller.N, 1e3 * sc->controller.dt, sc->lqr.enabled ? " + LQR" : "");
  r.summary = buf;
  if (run.swingup_time) {
    std::snprintf(buf, sizeof buf, "  up-up (|angles| <= %.3f rad) from t = %.3f s, held %.3f s\n",
                  sc->angle_tolerance, swingup, sc->duration - swingup);
  } else {
    std::snprintf(buf, sizeof buf, "  did NOT reach and hold |angles| <= %.3f rad (final %.4f)\n",
                  sc->angle_tolerance, run.final_angle_norm);
  }
  r.summary += buf;
  std::snprintf(buf, sizeof buf,
                "  max |u| %.4f N·m; velocity bound violations %d steps, worst %.4f rad/s; "
                "tracking RMS %.4f rad\n",
                run.max_abs_u, run.velocity_violations, run.worst_velocity_violation,
                run.tracking_rms);
  r.summary += buf;
  std::snprintf(buf, sizeof buf,
                "  RTI median %.1f us, p99 %.1f us (%d steps), fallbacks %lld; LQR from t = %.3f s "
                "(%.3f s, %d entries); final |angles| %.2e rad\n",
                run.rti_median_us, run.rti_p99_us, run.nmpc_steps, (long long)run.fallbacks,
                run.lqr_entry_time, run.lqr_time, run.lqr_entries, run.final_angle_norm);
  r.summary += buf;

  r.metrics = {
      {"duration_s", sc->duration},
      {"swingup_time_s", swingup},
      {"hold_time_s", run.swingup_time ? sc->duration - swingup : 0.0},
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
      {"quantization", sc->sensor.quantization ? 1.0 : 0.0},
  };
  r.ok = true;
  return r;
}

}  // namespace mixpilot
