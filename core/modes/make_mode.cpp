#include "core/modes/make_mode.hpp"

#include <cmath>
#include <cstdio>
#include <utility>

#include "core/modes/mi_mode.hpp"
#include "core/modes/obstacle_mode.hpp"
#include "core/modes/pendubot_mode.hpp"
#include "core/modes/tracking_mode.hpp"
#include "core/scenario/obstacle_scenario.hpp"
#include "core/scenario/pendubot_scenario.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/tracking_scenario.hpp"

namespace mixpilot {

namespace {

// Seconds to the millisecond, without trailing zeros ("113.907", "300").
std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", std::floor(s * 1000.0) / 1000.0);
  std::string t(buf);
  while (t.back() == '0') t.pop_back();
  if (t.back() == '.') t.pop_back();
  return t;
}

std::unique_ptr<Mode> make_mi_mode(std::string_view text, const std::string& source_name,
                                   ModeRequest& request, std::string& error) {
  std::optional<Scenario> scenario = parse_scenario(text, source_name, error);
  if (!scenario) return nullptr;
  if (request.duration) {
    // The same rule as the file's own duration: the reference keeps the ball and the vehicle
    // clear of the arena's walls, floor and ceiling.
    if (const auto b = reference_too_close_to_walls(*scenario, *request.duration)) {
      char margin[96];
      std::snprintf(margin, sizeof margin,
                    "%.3f m (the ball's radius %.3f m and the vehicle's %.3f m)", b->margin,
                    scenario->controller.ph.r, scenario->controller.vehicle_radius);
      error = source_name + ": a session of " + seconds_text(*request.duration) +
              " s flies the reference closer than " + margin + " to the arena's " + b->face +
              " at t = " + seconds_text(b->t) + " s; this scenario allows at most " +
              seconds_text(b->t) + " s";
      return nullptr;
    }
    scenario->duration = *request.duration;
  }
  std::unique_ptr<PilotSource> pilot = std::move(request.pilot_source);
  if (!pilot) {
    const std::string& name =
        request.pilot_name.empty() ? scenario->default_pilot : request.pilot_name;
    pilot = make_scenario_pilot(*scenario, name, error);
    if (!pilot) return nullptr;
  }
  scenario->controller.assist = request.assist;
  auto mode = std::make_unique<MiMode>();
  if (SetupResult r = mode->setup(std::move(*scenario), std::move(pilot)); !r) {
    error = source_name + ": " + r.reason();
    return nullptr;
  }
  if (!mode->set_authority_bounds(request.bounds)) {
    error = source_name + ": the mode refused its authority bounds";
    return nullptr;
  }
  return mode;
}

// A mode whose scenario struct comes from `parse` and which flies on its own.
template <class M, class Parse>
std::unique_ptr<Mode> make_solo_mode(std::string_view text, const std::string& source_name,
                                     const ModeRequest& request, Parse parse,
                                     std::string& error) {
  auto scenario = parse(text, source_name, error);
  if (!scenario) return nullptr;
  if (request.duration) scenario->duration = *request.duration;
  auto mode = std::make_unique<M>();
  if (SetupResult r = mode->setup(std::move(*scenario)); !r) {
    error = source_name + ": " + r.reason();
    return nullptr;
  }
  return mode;
}

std::unique_ptr<Mode> make_kind(ModeKind kind, std::string_view text,
                                const std::string& source_name, ModeRequest& request,
                                std::string& error);

}  // namespace

std::unique_ptr<Mode> make_mode(std::string_view text, const std::string& source_name,
                                ModeRequest request, std::string& error) {
  const std::optional<std::string> name = scenario_mode(text, source_name, error);
  if (!name) return nullptr;
  const std::optional<ModeKind> kind = mode_kind_from_string(*name);
  if (!kind) {
    error = source_name + ": mode \"" + *name + "\" is not one of " + mode_kind_names();
    return nullptr;
  }
  if (*kind != ModeKind::mixed_initiative && (request.pilot_source || !request.pilot_name.empty())) {
    error = source_name + ": a pilot flies only mixed_initiative scenarios, this one is " + *name;
    return nullptr;
  }
  if (!request.bounds.valid()) {
    error = source_name + ": authority bounds floor " + std::to_string(request.bounds.floor) +
            ", ceiling " + std::to_string(request.bounds.ceiling) +
            " are not 0 <= floor <= ceiling <= 1";
    return nullptr;
  }
  if (*kind != ModeKind::mixed_initiative && request.bounds != AuthorityBounds{}) {
    error = source_name + ": authority bounds are for mixed_initiative scenarios (a pilot shares "
            "the authority λ with the planner), this one is " + *name;
    return nullptr;
  }
  if (*kind != ModeKind::mixed_initiative && request.assist == Assistance::off) {
    error = source_name + ": a probe flight (assistance off) is for mixed_initiative scenarios, "
            "this one is " + *name;
    return nullptr;
  }
  std::unique_ptr<Mode> mode = make_kind(*kind, text, source_name, request, error);
  if (mode && mode->steps_total() < 1) {
    error = source_name + ": a duration of " + std::to_string(request.duration.value_or(0.0)) +
            " s is shorter than one control step of " + std::to_string(mode->dt()) + " s";
    return nullptr;
  }
  return mode;
}

namespace {

std::unique_ptr<Mode> make_kind(ModeKind kind, std::string_view text,
                                const std::string& source_name, ModeRequest& request,
                                std::string& error) {
  switch (kind) {
    case ModeKind::mixed_initiative: return make_mi_mode(text, source_name, request, error);
    case ModeKind::obstacle_avoidance:
      return make_solo_mode<ObstacleMode>(text, source_name, request, parse_obstacle_scenario,
                                          error);
    case ModeKind::crazyflie_tracking:
      return make_solo_mode<TrackingMode>(text, source_name, request, parse_tracking_scenario,
                                          error);
    case ModeKind::pendubot_swingup:
      return make_solo_mode<PendubotMode>(text, source_name, request, parse_pendubot_scenario,
                                          error);
  }
  error = source_name + ": mode \"" + to_string(kind) + "\" has no class";
  return nullptr;
}

}  // namespace

std::unique_ptr<Mode> load_mode(const std::string& path, ModeRequest request, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return nullptr;
  return make_mode(text, path, std::move(request), error);
}

}  // namespace mixpilot
