#include "core/scenario/tracking_scenario.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/nlp/trajectory_io.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/base/toml_read.hpp"

namespace mixpilot {

namespace {

using namespace toml_read;  // NOLINT: the reading vocabulary of this file

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
  const bool duration_ok = s.num("duration", sc.duration, kDuration) || !root.get("duration");

  Section c = s.sub("controller");
  std::string kind;
  if (c.choice("kind", kind, {"nmpc", "lqr"}))
    sc.controller.kind = kind == "lqr" ? TrackingControllerKind::lqr : TrackingControllerKind::nmpc;
  c.integer("N", sc.controller.N, kHorizon);
  const bool dt_ok =
      c.num("dt", sc.controller.dt, kControlDt) || !c.table() || !c.table()->get("dt");
  c.boolean("compensation", sc.controller.compensation);
  c.finish();

  Section pl = s.sub("plant");
  const bool rate_ok =
      pl.num("rate_hz", sc.plant.rate_hz, kPlantRate) || !pl.table() || !pl.table()->get("rate_hz");
  const bool rtt_ok =
      pl.num("rtt", sc.plant.rtt, closed(0, 1)) || !pl.table() || !pl.table()->get("rtt");
  pl.num("measurement_fraction", sc.plant.measurement_fraction, closed(0, 1));
  pl.vec("start", sc.plant.start, kPosition);
  pl.finish();
  // Whole substeps per control period and per round trip (core/control/tracking.hpp, delay model).
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
  r.num("radius", hx.radius, closed(0, 1e3));
  r.num("start_height", hx.start_height, kPosition);
  r.num("climb_rate", hx.climb_rate, kClimbRate);
  r.num("angular_rate", hx.angular_rate, kAngularRate);
  r.num("phase", hx.phase, kPhase);
  const bool length_ok =
      r.num("length", hx.length, kDuration) || !r.table() || !r.table()->get("length");
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
  if (duration_ok && dt_ok && rate_ok) {
    check_run_size(d, s.pos("duration"), sc.duration, sc.controller.dt, sc.plant.rate_hz);
  }
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

}  // namespace mixpilot
