#include "core/scenario/scenario_toml.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include "core/base/input_file.hpp"
#include "core/base/toml_read.hpp"

namespace mixpilot {
namespace {

using namespace toml_read;  // NOLINT: the reading vocabulary of this file


void read_controller(Section s, MiControllerSettings& c, Diagnostics& d) {
  const bool n_ok = s.integer("N", c.N, kHorizon) || !s.table() || !s.table()->get("N");
  s.num("dt", c.dt, kControlDt);
  s.boolean("safety_constraints", c.safety_constraints);
  std::string form;
  if (s.choice("obstacle_form", form, {"lcl", "squared"})) {
    c.obstacle_form = form == "lcl" ? ObstacleForm::lcl : ObstacleForm::squared;
  }
  s.integer("max_constrained_obstacles", c.max_constrained_obstacles,
            IntRange{0, std::int64_t(kMaxObstacles)});
  s.num("vehicle_radius", c.vehicle_radius, closed(0, 10));
  s.num("slack_l1", c.slack_l1, closed(0, 1e12));
  s.num("slack_l2", c.slack_l2, closed(1e-6, 1e12));  // keeps the slack Hessian positive definite

  Section w = s.sub("weights");
  w.vec("q_eta", c.weights.q_eta, weight());
  w.num("q_nu", c.weights.q_nu, weight());
  w.vec("q_e", c.weights.q_e, weight());
  w.num("r", c.weights.r, pos_weight());  // the only input weight: the Riccati input pivots need it
  w.finish();

  Section ph = s.sub("ph");
  ph.num("r", c.ph.r, closed(1e-6, 1e3));
  const bool nb_given = ph.integer("N_b", c.ph.N_b, kHorizon);
  ph.num("mu1", c.ph.mu1, open_interval(0, 1));
  ph.num("mu2", c.ph.mu2, closed(0, 1));
  ph.num("theta2", c.ph.theta2, closed(1e-6, 1e6));
  ph.num("zeta", c.ph.zeta, left_open(0, 1));
  ph.num("initial_lambda", c.ph.initial_lambda, closed(0, 1));
  ph.finish();
  if (n_ok && c.ph.N_b > c.N && (nb_given || !ph.table() || !ph.table()->get("N_b"))) {
    d.add(ph.pos("N_b"), ph.path("N_b"),
          "expected at most controller.N = " + std::to_string(c.N) + ", got " +
              std::to_string(c.ph.N_b));
  }
  s.finish();
}

PilotProfile read_pilot(Section s, const std::string& name) {
  PilotProfile p;
  p.name = name;
  s.vec("q1", p.q1, weight());
  s.vec("q2", p.q2, weight());
  s.vec("q3", p.q3, weight());
  s.vec("q4", p.q4, weight());
  s.num("q5", p.q5, weight());
  s.num("r1", p.r1, pos_weight());
  s.integer("N", p.N, kHorizon);
  s.num("reaction_delay", p.reaction_delay, kDelay);
  s.num("max_tilt", p.max_tilt, open_interval(0, std::numbers::pi / 2));
  s.finish();
  return p;
}

// First time in [0, duration] at which the helix comes closer than `margin` to a face of the
// box [lo, hi] (or leaves it), if any. The coordinates are sinusoids and a line: sampling at
// ≤ 1 mrad of phase misses at most ~R·5e-7 m of excursion.
std::optional<double> helix_breach(const HelixReference& h, double duration,
                                   const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                   double margin) {
  const auto outside = [&](double t) {
    const Eigen::Vector3d p = h.position(t);
    return (p.array() < lo.array() + margin).any() || (p.array() > hi.array() - margin).any();
  };
  const int n = std::max(1000, int(std::ceil(std::abs(h.angular_rate) * duration / 1e-3)));
  for (int i = 0; i <= n; ++i) {
    double t = duration * i / n;
    if (!outside(t)) continue;
    // Bisect down to the crossing between the last sample inside and this one.
    double in = i > 0 ? duration * (i - 1) / n : 0.0;
    if (i == 0) return 0.0;
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (in + t);
      (outside(mid) ? t : in) = mid;
    }
    return t;
  }
  return std::nullopt;
}

// The face of the box [lo, hi] nearest to `p`, for messages.
const char* nearest_face(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                         const Eigen::Vector3d& hi) {
  const double floor = p.z() - lo.z(), ceiling = hi.z() - p.z();
  const double wall = std::min({p.x() - lo.x(), hi.x() - p.x(), p.y() - lo.y(), hi.y() - p.y()});
  if (floor <= ceiling && floor <= wall) return "floor";
  return ceiling <= wall ? "ceiling" : "walls";
}

std::string vec_text(const Eigen::Vector3d& v) {
  return '[' + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + ']';
}

// A computed (not user-typed) quantity, to the millimetre / millisecond.
std::string approx(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// One [[arena.obstacles]] sphere: inside the arena (when the arena itself is valid) and smaller
// than half its diagonal (a sphere reaching past every corner leaves nothing to fly in).
Obstacle read_obstacle(Section o, const Arena& arena, bool box_ok, Diagnostics& d) {
  Obstacle ob;
  const bool c_ok = o.vec("center", ob.center, kPosition, true);
  const bool r_ok = o.num("radius", ob.radius, left_open(0, 100), true);
  o.finish();
  if (c_ok && box_ok &&
      ((ob.center.array() < arena.min.array()).any() ||
       (ob.center.array() > arena.max.array()).any())) {
    d.add(o.pos("center"), o.path("center"),
          "expected a point inside the arena " + vec_text(arena.min) + " .. " +
              vec_text(arena.max) + ", got " + vec_text(ob.center));
  }
  const double half_diagonal = 0.5 * (arena.max - arena.min).norm();
  if (r_ok && box_ok && ob.radius >= half_diagonal) {
    d.add(o.pos("radius"), o.path("radius"),
          "value outside " + open_interval(0, half_diagonal).text() +
              " (half the arena's diagonal), got " + fmt(ob.radius));
  }
  return ob;
}

Scenario read_scenario(const toml::table& root, Diagnostics& d) {
  Scenario sc;
  Section s(d, &root, "", Pos{1, 1});
  s.string("name", sc.name, true);
  const bool mode_ok = s.choice("mode", sc.mode, {"mixed_initiative"}, true);
  const bool model_ok = s.choice("model", sc.model, {"mikrokopter", "crazyflie", "pendubot"}, true);
  if (mode_ok && model_ok && sc.mode == "mixed_initiative" && sc.model != "mikrokopter") {
    d.add(s.pos("model"), "model",
          "expected \"mikrokopter\" for mode \"mixed_initiative\" (SPEC 5.4), got \"" + sc.model +
              '"');
  }
  const bool duration_ok = s.num("duration", sc.duration, kDuration) || !root.get("duration");
  const bool pilot_given = s.string("pilot", sc.default_pilot);

  read_controller(s.sub("controller"), sc.controller, d);

  Section ref = s.sub("reference");
  Eigen::Vector2d center = sc.reference.center;
  if (ref.vec("center", center, kPosition)) sc.reference.center = center;
  ref.num("radius", sc.reference.radius, closed(0, 1e3));
  ref.num("start_height", sc.reference.start_height, kPosition);
  ref.num("climb_rate", sc.reference.climb_rate, kClimbRate);
  ref.num("angular_rate", sc.reference.angular_rate, kAngularRate);
  ref.num("phase", sc.reference.phase, kPhase);
  ref.finish();

  Section arena = s.sub("arena");
  // Both corners read (and reported) before they are compared.
  const bool min_ok =
      arena.vec("min", sc.arena.min, kPosition) || !arena.table() || !arena.table()->get("min");
  const bool max_ok =
      arena.vec("max", sc.arena.max, kPosition) || !arena.table() || !arena.table()->get("max");
  bool box_ok = min_ok && max_ok;
  if (box_ok && !(sc.arena.min.array() < sc.arena.max.array()).all()) {
    d.add(arena.pos("max"), arena.path("max"),
          "expected every component above arena.min = " + vec_text(sc.arena.min) + ", got " +
              vec_text(sc.arena.max));
    box_ok = false;
  }
  if (const toml::node* obs = arena.take("obstacles", false, "")) {
    const toml::array* a = obs->as_array();
    if (!a || !a->is_array_of_tables()) {
      d.add(pos_of(obs->source()), arena.path("obstacles"),
            "expected an array of tables ([[arena.obstacles]]), got " + describe(*obs));
    } else if (a->size() > kMaxObstacles) {
      d.add(pos_of(obs->source()), arena.path("obstacles"),
            outside("the number of obstacles", double(a->size()), closed(0, kMaxObstacles)));
    } else {
      for (std::size_t i = 0; i < a->size(); ++i) {
        const toml::node& e = *a->get(i);
        sc.arena.obstacles.push_back(read_obstacle(
            Section(d, e.as_table(), arena.path("obstacles") + '[' + std::to_string(i) + ']',
                    pos_of(e.source())),
            sc.arena, box_ok, d));
      }
    }
  }
  arena.finish();
  // The reference must stay flyable: a pilot anywhere in the ball B around it, in a vehicle of
  // its radius, must not touch the walls, floor or ceiling (the score counts that contact as a
  // collision, and the controller's soft walls would fight the reference).
  if (box_ok && duration_ok) {
    if (const auto b = reference_too_close_to_walls(sc, sc.duration)) {
      d.add(ref.pos(), "reference",
            "expected a helix at least " + approx(b->margin) +
                " m (controller.ph.r + controller.vehicle_radius) inside the arena over [0, "
                "duration], but it comes closer to the arena's " + b->face + " at t = " +
                approx(b->t) + " s, at (" + approx(b->at.x()) + ", " + approx(b->at.y()) + ", " +
                approx(b->at.z()) + ")");
    }
  }

  // [pilots.<name>]: one table per profile; TOML itself rejects a name given twice.
  Section pilots = s.sub("pilots");
  if (pilots.table()) {
    for (auto&& [k, v] : *pilots.table()) {
      const std::string name(k.str());
      if (!v.is_table()) {
        d.add(pos_of(v.source()), pilots.path(name),
              "expected a table of pilot weights ([pilots." + name + "]), got " + describe(v));
        continue;
      }
      sc.pilots[name] = read_pilot(Section(d, v.as_table(), pilots.path(name), pos_of(v.source())),
                                   name);
    }
  }
  // "reckless" (full-tilt inputs, no NMPC) is always available; its max_tilt may be overridden.
  if (!sc.pilots.count("reckless")) sc.pilots["reckless"] = PilotProfile{.name = "reckless"};
  if (!sc.pilots.count(sc.default_pilot)) {
    std::string names;
    for (const auto& [n, p] : sc.pilots) names += (names.empty() ? "" : ", ") + ('"' + n + '"');
    d.add(pilot_given ? s.pos("pilot") : Pos{1, 1}, "pilot",
          "expected the name of a profile in [pilots] (" + names + "), got \"" +
              sc.default_pilot + '"' + (pilot_given ? "" : " (the default)"));
  }

  Section plant = s.sub("plant");
  const bool rate_given = plant.num("rate_hz", sc.plant.rate_hz, kPlantRate);
  plant.num("input_delay", sc.plant.input_delay, kDelay);
  plant.num("position_noise", sc.plant.position_noise, closed(0, 10));
  std::int64_t seed = std::int64_t(sc.plant.seed);
  if (plant.integer("seed", seed, IntRange{0, std::numeric_limits<std::int64_t>::max()}))
    sc.plant.seed = std::uint64_t(seed);
  plant.finish();
  // The plant takes a whole number of RK4 substeps per control step.
  const double substeps = sc.controller.dt * sc.plant.rate_hz;
  if (sc.plant.rate_hz >= 1000 && sc.controller.dt > 0 &&
      std::abs(substeps - std::round(substeps)) > 1e-9 * substeps) {
    d.add(rate_given ? plant.pos("rate_hz") : plant.pos(), plant.path("rate_hz"),
          "expected a rate giving a whole number of substeps per control step, got controller.dt "
          "* rate_hz = " + fmt(substeps));
  }

  if (duration_ok && sc.controller.dt > 0 && sc.plant.rate_hz > 0) {
    check_run_size(d, s.pos("duration"), sc.duration, sc.controller.dt, sc.plant.rate_hz);
  }

  s.finish();
  return sc;
}


}  // namespace

std::optional<Scenario> parse_scenario(std::string_view text, const std::string& source_name,
                                       std::string& error) {
  auto sc = parse_document<Scenario>(text, source_name, error,
                                    [](const toml::table& root, Diagnostics& d) {
                                      return read_scenario(root, d);
                                    });
  if (sc) sc->source_text = std::string(text);
  return sc;
}

std::optional<Scenario> load_scenario(const std::string& path, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_scenario(text, path, error);
}

bool read_text_file(const std::string& path, std::string& text, std::string& error) {
  return read_input_file(path, kMaxTextFileBytes, text, error);
}

std::optional<ReferenceBreach> reference_too_close_to_walls(const Scenario& sc,
                                                           double duration) {
  const double margin = sc.controller.ph.r + sc.controller.vehicle_radius;
  const auto t = helix_breach(sc.reference, duration, sc.arena.min, sc.arena.max, margin);
  if (!t) return std::nullopt;
  const Eigen::Vector3d p = sc.reference.position(*t);
  return ReferenceBreach{*t, p, nearest_face(p, sc.arena.min, sc.arena.max), margin};
}

std::optional<std::string> scenario_mode(std::string_view text, const std::string& source_name,
                                         std::string& error) {
  Diagnostics d(source_name);
  toml::table root;
  if (!parse_toml(text, source_name, d, root)) {
    error = d.str();
    return std::nullopt;
  }
  Section s(d, &root, "", Pos{1, 1});
  std::string mode;
  // Every mode a scenario can name (core/modes/mode.hpp's ModeKind), so an unknown one is
  // reported where it is written.
  if (!s.choice("mode", mode,
                {"mixed_initiative", "pendubot_swingup", "crazyflie_tracking", "obstacle_avoidance"},
                true)) {
    error = d.str();
    return std::nullopt;
  }
  return mode;
}

}  // namespace mixpilot
