#include "core/scenario/pendubot_scenario.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include "core/scenario/scenario_toml.hpp"
#include "core/base/toml_read.hpp"

namespace mixpilot {

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
  const bool duration_ok = s.num("duration", sc.duration, kDuration) || !root.get("duration");
  s.num("angle_tolerance", sc.angle_tolerance, left_open(0, std::numbers::pi));

  Section c = s.sub("controller");
  PendubotOcpSettings& oc = sc.controller;
  c.integer("N", oc.N, kHorizon);
  c.num("dt", oc.dt, kControlDt);
  c.num("u_max", oc.u_max, left_open(0, 100));
  Eigen::Vector2d vb = oc.velocity_bound;
  if (c.vec("velocity_bound", vb, left_open(0, 1e3))) oc.velocity_bound = vb;
  c.num("slack_weight", oc.slack_weight, pos_weight());
  Eigen::Matrix<double, 5, 1> w = oc.weights;
  if (c.vec("weights", w, weight())) oc.weights = w;
  if (!pos_weight().contains(oc.weights(4))) {
    d.add(c.pos("weights"), c.path("weights") + "[4]",
          outside("the input weight", oc.weights(4), pos_weight()) +
              " (the Riccati input pivots need it)");
  }
  Eigen::Vector4d wn = oc.terminal_weights;
  if (c.vec("terminal_weights", wn, weight())) oc.terminal_weights = wn;
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
  if (l.vec("q", lq, weight())) sc.lqr.q = lq;
  l.num("r", sc.lqr.r, pos_weight());
  l.num("enter_angle", sc.lqr.enter_angle, left_open(0, std::numbers::pi));
  l.num("enter_velocity", sc.lqr.enter_velocity, left_open(0, 1e3));
  l.num("exit_angle", sc.lqr.exit_angle, left_open(0, 2 * std::numbers::pi));
  if (sc.lqr.exit_angle <= sc.lqr.enter_angle) {
    d.add(l.pos("exit_angle"), l.path("exit_angle"),
          "expected more than lqr.enter_angle = " + fmt(sc.lqr.enter_angle) +
              " (hysteresis), got " + fmt(sc.lqr.exit_angle));
  }
  l.finish();

  Section p = s.sub("plant");
  const bool rate_given = p.num("rate_hz", sc.plant.rate_hz, kPlantRate);
  Eigen::Vector4d x0 = sc.plant.initial_state;
  if (p.vec("initial_state", x0, closed(-1e3, 1e3))) sc.plant.initial_state = x0;
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
  e.integer("counts_q1", sc.sensor.counts_q1, IntRange{4, 1 << 24});
  e.integer("counts_q2", sc.sensor.counts_q2, IntRange{4, 1 << 24});
  e.num("velocity_cutoff_hz", sc.sensor.velocity_cutoff_hz, closed(0, 1e5));
  e.choice("estimator", sc.sensor.estimator, {"difference", "observer"});
  e.num("observer_alpha", sc.sensor.observer_alpha, open_interval(0, 1));
  e.num("observer_beta", sc.sensor.observer_beta, open_interval(0, 1));
  e.finish();
  if (duration_ok && oc.dt > 0 && sc.plant.rate_hz > 0) {
    check_run_size(d, s.pos("duration"), sc.duration, oc.dt, sc.plant.rate_hz);
  }
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

}  // namespace mixpilot
