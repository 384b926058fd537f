#include "core/modes/obstacles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/toml_read.hpp"

namespace mixpilot {

const char* to_string(ObstacleForm form) {
  return form == ObstacleForm::lcl ? "lcl" : "squared";
}

// ---------------------------------------------------------------------------------------------
// World

Eigen::Vector3d ThrownBall::position_at(double t) const {
  const double tau = std::max(0.0, t - throw_time);
  Eigen::Vector3d p = position + tau * velocity;
  p.z() -= 0.5 * gravity * tau * tau;
  return p;
}

Eigen::Vector3d ThrownBall::velocity_at(double t) const {
  if (t < throw_time) return Eigen::Vector3d::Zero();
  Eigen::Vector3d v = velocity;
  v.z() -= gravity * (t - throw_time);
  return v;
}

Eigen::Vector3d ObstacleWorld::position(int j, double t) const {
  const int ns = int(spheres.size());
  return j < ns ? spheres[j] : balls[j - ns].position_at(t);
}

Eigen::Vector3d ObstacleWorld::predict(int j, double t_now, double tau) const {
  const int ns = int(spheres.size());
  if (j < ns) return spheres[j];
  // From the ball's current state: at rest stays at rest; in flight, ballistic.
  const ThrownBall& b = balls[j - ns];
  const Eigen::Vector3d p = b.position_at(t_now);
  if (t_now < b.throw_time) return p;
  Eigen::Vector3d q = p + tau * b.velocity_at(t_now);
  q.z() -= 0.5 * b.gravity * tau * tau;
  return q;
}

// ---------------------------------------------------------------------------------------------
// OCP (SPEC §5.3)

ObstacleAvoidanceOcp::ObstacleAvoidanceOcp(int num_obstacles,
                                           const ObstacleControllerSettings& settings,
                                           const models::Crazyflie& model)
    : settings_(settings),
      num_obstacles_(num_obstacles),
      integrator_(model),
      output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi::LinSpaced(nu, 0, nu - 1)),
      terminal_output_(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi()),
      constraint_(num_obstacles, settings.form),
      stage_weights_(stage_weights()),
      terminal_weights_(terminal_weights()) {
  ocp_.integrator = &integrator_;
  ocp_.N = settings.N;
  ocp_.dt = settings.dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::LinSpaced(nu, 0, nu - 1);
  ocp_.lbu = Eigen::VectorXd::Constant(nu, model.p.omega_min);
  ocp_.ubu = Eigen::VectorXd::Constant(nu, model.p.omega_max);
  if (num_obstacles > 0) {
    // g_j ≥ 0 (lcl: ‖p − o‖ − d_C; squared: ‖p − o‖² − d_C²), no upper side (d_M = ∞).
    ocp_.np = ObstacleConstraint::kParamsPerObstacle * num_obstacles;
    ocp_.constraint = &constraint_;
    ocp_.lg = Eigen::VectorXd::Zero(num_obstacles);
    ocp_.ug = Eigen::VectorXd::Constant(num_obstacles, qp_defaults::kInfBound);
    for (int j = 0; j < num_obstacles; ++j) {
      ocp_.soft_constraints.push_back(SoftConstraint{j, settings.slack_l2, settings.slack_l2,
                                                     settings.slack_l1_lower,
                                                     settings.slack_l1_upper});
    }
  }
}

Eigen::VectorXd ObstacleAvoidanceOcp::stage_weights() {
  Eigen::VectorXd w(nx + nu);
  w << 30, 30, 60,                // p
      0.1, 0.1, 0.1, 0.1,         // q
      2, 3, 5,                    // v_b
      3, 3, 3,                    // ω
      0.05, 0.05, 0.05, 0.05;     // Ω
  return w;
}

Eigen::VectorXd ObstacleAvoidanceOcp::terminal_weights() { return stage_weights().head(nx); }

void ObstacleAvoidanceOcp::set_hover_target(OcpStageData& data,
                                            const Eigen::Vector3d& position) const {
  Eigen::VectorXd y(nx + nu);
  y << model().hover_state(position), model().hover_input();
  for (int i = 0; i < ocp_.N; ++i) {
    data.yref[i] = y;
    data.W[i] = stage_weights_.asDiagonal();
  }
  data.yref[ocp_.N] = y.head(nx);
  data.W[ocp_.N] = terminal_weights_.asDiagonal();
}

void ObstacleAvoidanceOcp::set_reference(OcpStageData& data, const OcpTrajectory& ref,
                                         int k) const {
  const int last_u = int(ref.u.size()) - 1;
  const int last_x = int(ref.x.size()) - 1;
  for (int i = 0; i < ocp_.N; ++i) {
    data.yref[i].head(nx) = ref.x[std::min(k + i, last_x)];
    // Past the end the reference hovers: its last input would be the last move's, not hover's.
    if (k + i <= last_u)
      data.yref[i].tail(nu) = ref.u[k + i];
    else
      data.yref[i].tail(nu) = model().hover_input();
    data.W[i].diagonal() = stage_weights_;
  }
  data.yref[ocp_.N] = ref.x[std::min(k + ocp_.N, last_x)];
  data.W[ocp_.N].diagonal() = terminal_weights_;
}

void ObstacleAvoidanceOcp::set_obstacles(OcpStageData& data, const ObstacleWorld& world,
                                         double t) const {
  constexpr int kP = ObstacleConstraint::kParamsPerObstacle;
  for (int i = 0; i <= ocp_.N; ++i) {
    for (int j = 0; j < num_obstacles_; ++j) {
      data.p[i].segment<3>(kP * j) = world.predict(j, t, i * ocp_.dt);
      data.p[i](kP * j + 3) = settings_.clearance;
    }
  }
}

void ObstacleAvoidanceOcp::hover_guess(OcpTrajectory& traj,
                                       const Eigen::Vector3d& position) const {
  for (auto& x : traj.x) x = model().hover_state(position);
  for (auto& u : traj.u) u = model().hover_input();
}

// ---------------------------------------------------------------------------------------------
// Scenario files

namespace {

using namespace toml_read;  // NOLINT: the reading vocabulary of this file

std::string resolve(const std::string& source_name, const std::string& file) {
  const std::filesystem::path f(file);
  if (f.is_absolute()) return file;
  return (std::filesystem::path(source_name).parent_path() / f).lexically_normal().string();
}

ObstacleScenario read_obstacle_scenario(const toml::table& root, const std::string& source_name,
                                        Diagnostics& d) {
  ObstacleScenario sc;
  Section s(d, &root, "", Pos{1, 1});
  s.string("name", sc.name, true);
  std::string mode, model;
  s.choice("mode", mode, {"obstacle_avoidance"}, true);
  s.choice("model", model, {"crazyflie"}, true);  // SPEC §5.3
  s.num("duration", sc.duration, positive);

  ObstacleControllerSettings& c = sc.controller;
  Section ctl = s.sub("controller");
  ctl.integer("N", c.N, int_positive);
  const bool dt_ok = ctl.num("dt", c.dt, positive) || !ctl.table() || !ctl.table()->get("dt");
  std::string form;
  if (ctl.choice("constraint_form", form, {"lcl", "squared"}))
    c.form = form == "lcl" ? ObstacleForm::lcl : ObstacleForm::squared;
  ctl.num("clearance", c.clearance, positive);
  ctl.num("slack_l1_lower", c.slack_l1_lower, non_negative);
  ctl.num("slack_l1_upper", c.slack_l1_upper, non_negative);
  ctl.num("slack_l2", c.slack_l2, non_negative);
  ctl.finish();

  Section ref = s.sub("reference");
  if (ref.string("file", sc.reference_file, true)) {
    sc.reference_file = resolve(source_name, sc.reference_file);
    std::string error;
    const auto file = read_trajectory_csv(sc.reference_file, error);
    const Pos at = ref.pos("file");
    if (!file) {
      d.add(at, ref.path("file"), "expected a readable trajectory CSV: " + error);
    } else if (file->trajectory.x.empty() || file->trajectory.x[0].size() != 13 ||
               file->trajectory.u.empty() || file->trajectory.u[0].size() != 4) {
      d.add(at, ref.path("file"),
            "expected a Crazyflie trajectory (13 states, 4 inputs): " + sc.reference_file);
    } else if (dt_ok && std::abs(file->dt - c.dt) > 1e-9) {
      d.add(at, ref.path("file"),
            "expected a trajectory with the controller's dt = " + fmt(c.dt) + " s, got dt = " +
                fmt(file->dt) + " s in " + sc.reference_file);
    } else {
      sc.reference = *file;
    }
  }
  ref.finish();

  const auto tables = [&](std::string_view key, auto&& read_one) {
    const toml::node* n = s.take(key, false, "");
    if (!n) return;
    const toml::array* a = n->as_array();
    if (!a || !a->is_array_of_tables()) {
      d.add(pos_of(n->source()), std::string(key),
            "expected an array of tables ([[" + std::string(key) + "]]), got " + describe(*n));
      return;
    }
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& e = *a->get(i);
      read_one(Section(d, e.as_table(), std::string(key) + '[' + std::to_string(i) + ']',
                       pos_of(e.source())));
    }
  };
  tables("spheres", [&](Section o) {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    o.vec("center", center, finite, true);
    o.finish();
    sc.world.spheres.push_back(center);
  });
  tables("balls", [&](Section o) {
    ThrownBall b;
    o.vec("position", b.position, finite, true);
    o.vec("velocity", b.velocity, finite, true);
    o.num("throw_time", b.throw_time, non_negative);
    o.num("gravity", b.gravity, non_negative);
    o.finish();
    sc.world.balls.push_back(b);
  });

  Section plant = s.sub("plant");
  const bool rate_given = plant.num("rate_hz", sc.plant_rate_hz, at_least_1000);
  plant.finish();
  const double substeps = c.dt * sc.plant_rate_hz;
  if (sc.plant_rate_hz >= 1000 && c.dt > 0 &&
      std::abs(substeps - std::round(substeps)) > 1e-9 * substeps) {
    d.add(rate_given ? plant.pos("rate_hz") : plant.pos(), plant.path("rate_hz"),
          "expected a rate giving a whole number of substeps per control step, got "
          "controller.dt * rate_hz = " + fmt(substeps));
  }
  s.finish();
  return sc;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(std::ceil(q * double(v.size()))) - 1);
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

std::optional<ObstacleScenario> parse_obstacle_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error) {
  return parse_document<ObstacleScenario>(text, source_name, error, [&](const toml::table& root, Diagnostics& d) {
    return read_obstacle_scenario(root, source_name, d);
  });
}

std::optional<ObstacleScenario> load_obstacle_scenario(const std::string& path,
                                                       std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_obstacle_scenario(text, path, error);
}

// ---------------------------------------------------------------------------------------------
// Closed loop

ObstacleRunResult run_obstacle_avoidance(const ObstacleScenario& scenario,
                                         const ObstacleRunOptions& options) {
  ObstacleControllerSettings settings = scenario.controller;
  if (options.form) settings.form = *options.form;
  const ObstacleWorld& world = scenario.world;
  const int no = world.size();
  ObstacleAvoidanceOcp problem(no, settings);
  RtiSolver rti;
  if (!rti.setup(problem.ocp())) return {};

  const OcpTrajectory& ref = scenario.reference.trajectory;
  const int last_x = int(ref.x.size()) - 1;
  const double dt = settings.dt;
  const double duration = options.duration.value_or(scenario.duration);
  const int steps = int(std::lround(duration / dt));
  const int substeps = int(std::lround(dt * scenario.plant_rate_hz));
  const double h = dt / substeps;
  const double d_c = settings.clearance;

  // Warm start: the reference itself (obstacle-free) from its first state.
  for (int i = 0; i <= settings.N; ++i) rti.trajectory().x[i] = ref.x[std::min(i, last_x)];
  for (int i = 0; i < settings.N; ++i) {
    if (i < int(ref.u.size()))
      rti.trajectory().u[i] = ref.u[i];
    else
      rti.trajectory().u[i] = problem.model().hover_input();
  }

  ObstacleRunResult res;
  res.form = settings.form;
  res.min_distance_m = std::numeric_limits<double>::infinity();
  res.min_distance_control_m = std::numeric_limits<double>::infinity();
  std::vector<double> rti_us;
  rti_us.reserve(std::size_t(steps));
  if (options.keep_trajectory) {
    res.positions.reserve(std::size_t(steps) + 1);
    res.step_us.reserve(std::size_t(steps));
    res.step_qp_iterations.reserve(std::size_t(steps));
    res.step_status.reserve(std::size_t(steps));
  }

  const auto& erk4 = problem.integrator();
  models::Crazyflie::State x = ref.x[0], xn;
  models::Crazyflie::Input u;
  double sq_tracking = 0.0;
  // Distance to every obstacle at time t; returns whether it violates d_C − 1 mm.
  const auto check = [&](double t) {
    bool violated = false;
    for (int j = 0; j < no; ++j) {
      const double dist = (x.head<3>() - world.position(j, t)).norm();
      if (dist < res.min_distance_m) {
        res.min_distance_m = dist;
        res.min_distance_time = t;
        res.closest_obstacle = j;
      }
      violated |= dist < d_c - obstacle_defaults::kViolationTolerance;
    }
    return violated;
  };
  const auto check_control = [&](double t) {
    for (int j = 0; j < no; ++j)
      res.min_distance_control_m =
          std::min(res.min_distance_control_m, (x.head<3>() - world.position(j, t)).norm());
  };
  if (check(0.0)) ++res.violations;
  check_control(0.0);

  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    problem.set_reference(rti.data(), ref, k);
    problem.set_obstacles(rti.data(), world, t);
    rti.prepare();
    rti.feedback(x);
    const RtiStats& st = rti.stats();
    rti_us.push_back(st.total_us);
    res.qp_iterations_max = std::max(res.qp_iterations_max, st.qp_iterations);
    u = rti.control();
    if (options.keep_trajectory) {
      res.positions.push_back(x.head<3>());
      res.step_us.push_back(st.total_us);
      res.step_qp_iterations.push_back(st.qp_iterations);
      res.step_status.push_back(int(st.status));
    }
    sq_tracking += (x.head<3>() - ref.x[std::min(k, last_x)].head<3>()).squaredNorm();

    bool violated = false;
    for (int s = 0; s < substeps; ++s) {  // plant: RK4 at rate_hz, input held
      erk4.step(x, u, h, xn);
      x = xn;
      violated |= check(t + (s + 1) * h);
    }
    if (violated) ++res.violations;
    check_control(t + dt);
    ++res.steps;
    if (!x.allFinite()) {
      res.lost = true;
      break;
    }
    rti.shift();
  }
  if (options.keep_trajectory) res.positions.push_back(x.head<3>());
  res.min_margin_m = res.min_distance_m - d_c;
  res.tracking_rms_m = res.steps > 0 ? std::sqrt(sq_tracking / res.steps) : 0.0;
  res.final_error_m = (x.head<3>() - ref.x[last_x].head<3>()).norm();
  res.rti_median_us = percentile(rti_us, 0.5);
  res.rti_p99_us = percentile(rti_us, 0.99);
  res.rti_max_us = rti_us.empty() ? 0.0 : *std::max_element(rti_us.begin(), rti_us.end());
  res.fallbacks = int(rti.stats().fallbacks);
  return res;
}

ModeResult fly_obstacle_avoidance(const std::string& scenario_path, const ModeOptions& options) {
  ModeResult out;
  const auto sc = load_obstacle_scenario(scenario_path, out.error);
  if (!sc) return out;
  ObstacleRunOptions run_options;
  run_options.duration = options.duration;
  const ObstacleRunResult r = run_obstacle_avoidance(*sc, run_options);

  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: obstacle avoidance (SPEC 5.3), form %s, %zu spheres, %zu balls, %d steps "
                "of %.0f ms\n"
                "  min distance %.4f m (d_C %.3f m, margin %+.4f m) at t = %.3f s (obstacle %d), "
                "%.4f m at the control instants; violations %d\n"
                "  tracking rms %.3f m, final error %.3f m; RTI median %.0f us, p99 %.0f us, "
                "max %.0f us; fallbacks %d%s\n",
                sc->name.c_str(), to_string(r.form), sc->world.spheres.size(),
                sc->world.balls.size(), r.steps, 1e3 * sc->controller.dt, r.min_distance_m,
                sc->controller.clearance, r.min_margin_m, r.min_distance_time, r.closest_obstacle,
                r.min_distance_control_m, r.violations, r.tracking_rms_m, r.final_error_m,
                r.rti_median_us, r.rti_p99_us,
                r.rti_max_us, r.fallbacks, r.lost ? "\n  the vehicle was lost" : "");
  out.summary = buf;
  out.metrics = {
      {"min_distance_m", r.min_distance_m},
      {"min_margin_m", r.min_margin_m},
      {"min_distance_control_m", r.min_distance_control_m},
      {"clearance_m", sc->controller.clearance},
      {"violations", double(r.violations)},
      {"tracking_rms_m", r.tracking_rms_m},
      {"final_error_m", r.final_error_m},
      {"rti_median_us", r.rti_median_us},
      {"rti_p99_us", r.rti_p99_us},
      {"fallbacks", double(r.fallbacks)},
      {"form", r.form == ObstacleForm::lcl ? 0.0 : 1.0},
      {"steps", double(r.steps)},
  };
  out.ok = !r.lost;
  if (r.lost) out.error = scenario_path + ": the vehicle was lost (plant state not finite)";
  return out;
}

}  // namespace mixpilot
