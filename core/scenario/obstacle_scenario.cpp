#include "core/scenario/obstacle_scenario.hpp"

#include <cmath>
#include <filesystem>

#include "core/scenario/scenario_toml.hpp"
#include "core/base/toml_read.hpp"

namespace mixpilot {

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
  const bool duration_ok = s.num("duration", sc.duration, kDuration) || !root.get("duration");

  ObstacleControllerSettings& c = sc.controller;
  Section ctl = s.sub("controller");
  ctl.integer("N", c.N, kHorizon);
  const bool dt_ok = ctl.num("dt", c.dt, kControlDt) || !ctl.table() || !ctl.table()->get("dt");
  std::string form;
  if (ctl.choice("constraint_form", form, {"lcl", "squared"}))
    c.form = form == "lcl" ? ObstacleForm::lcl : ObstacleForm::squared;
  ctl.num("clearance", c.clearance, closed(1e-3, 10));
  ctl.num("slack_l1_lower", c.slack_l1_lower, closed(0, 1e12));
  ctl.num("slack_l1_upper", c.slack_l1_upper, closed(0, 1e12));
  ctl.num("slack_l2", c.slack_l2, closed(0, 1e12));
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
    if (a->size() > kMaxObstacles) {
      d.add(pos_of(n->source()), std::string(key),
            outside("the number of obstacles", double(a->size()), closed(0, kMaxObstacles)));
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
    o.vec("center", center, kPosition, true);
    o.finish();
    sc.world.spheres.push_back(center);
  });
  tables("balls", [&](Section o) {
    ThrownBall b;
    o.vec("position", b.position, kPosition, true);
    o.vec("velocity", b.velocity, closed(-1e3, 1e3), true);
    o.num("throw_time", b.throw_time, closed(0, 3600));
    o.num("gravity", b.gravity, closed(0, 100));
    o.finish();
    sc.world.balls.push_back(b);
  });

  Section plant = s.sub("plant");
  const bool rate_given = plant.num("rate_hz", sc.plant_rate_hz, kPlantRate);
  plant.finish();
  const double substeps = c.dt * sc.plant_rate_hz;
  if (sc.plant_rate_hz >= 1000 && c.dt > 0 &&
      std::abs(substeps - std::round(substeps)) > 1e-9 * substeps) {
    d.add(rate_given ? plant.pos("rate_hz") : plant.pos(), plant.path("rate_hz"),
          "expected a rate giving a whole number of substeps per control step, got "
          "controller.dt * rate_hz = " + fmt(substeps));
  }
  if (sc.world.spheres.size() + sc.world.balls.size() > kMaxObstacles) {
    d.add(s.pos("balls"), "balls",
          outside("the number of spheres and balls", double(sc.world.size()),
                  closed(0, kMaxObstacles)));
  }
  if (duration_ok && dt_ok && sc.plant_rate_hz > 0) {
    check_run_size(d, s.pos("duration"), sc.duration, c.dt, sc.plant_rate_hz);
  }
  s.finish();
  return sc;
}

}  // namespace

std::optional<ObstacleScenario> parse_obstacle_scenario(std::string_view text,
                                                        const std::string& source_name,
                                                        std::string& error) {
  return parse_document<ObstacleScenario>(
      text, source_name, error,
      [&](const toml::table& root, Diagnostics& d) {
        return read_obstacle_scenario(root, source_name, d);
      });
}

std::optional<ObstacleScenario> load_obstacle_scenario(const std::string& path,
                                                       std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_obstacle_scenario(text, path, error);
}

}  // namespace mixpilot
