// mixpilot vehicle: the plant of a scenario in its own process, flown over DDS by
// `mixpilot fly --vehicle dds` (SPEC §9): a stand-in for a real quadrotor on a radio link.
//
// The plant runs on the wall clock. A command received at t is applied at t + latency (the
// command link's one-way delay); the plant (the modes' simulated one, core/modes/
// simulated_vehicle.hpp's VehiclePlant) is integrated exactly to that instant with the
// command before it, and its state measured there goes out at t_apply + latency (the measurement
// link's delay), echoing the command's step and stamp with age 0. Without new commands a state
// goes out every other control period (every period before the first command), echoing the
// command in effect and its age, so the controller hears the vehicle. Before its first command
// the vehicle rests in hover at the scenario's start. Its world (core/modes/vehicle_feed.hpp's
// VehicleWorld) is the controller's, with the ground under the tracking mode's ball: leaving it,
// through the floor included, stops the plant there and every later state says so (status 1).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight.hpp"
#include "core/modes/simulated_vehicle.hpp"
#include "core/modes/vehicle_feed.hpp"
#include "core/modes/vehicle_link.hpp"
#include "core/numerics/types.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/tracking_scenario.hpp"
#include "input/net/dds.hpp"
#include "input/net/vehicle_endpoint.hpp"
#include "core/base/realtime_priority.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"

namespace mixpilot::cli {

namespace {

constexpr const char* kUsage =
    "usage: mixpilot vehicle --scenario FILE [--latency MS] [--domain N] [--wait S]\n"
    "                        [--timeout S]\n"
    "\n"
    "Runs the scenario's vehicle in this process, on the wall clock, for one flight by\n"
    "`mixpilot fly --scenario FILE --vehicle dds` (crazyflie_tracking and mixed_initiative\n"
    "scenarios): rotor commands in on rt/mixpilot/vehicle/command, states out on\n"
    "rt/mixpilot/vehicle/state, each echoing the newest command in effect so the controller can\n"
    "measure the round-trip time. DDS stays on this machine unless CYCLONEDDS_URI names another\n"
    "configuration (docs/network.md).\n"
    "\n"
    "  --scenario FILE  the scenario whose vehicle flies (model, start, plant rate)\n"
    "  --latency MS     one-way delay added each way, 0-1000 ms (default 0): commands act MS\n"
    "                   after they arrive, states leave MS after they are measured\n"
    "  --domain N       DDS domain id, 0-232 (default 0)\n"
    "  --wait S         wait up to S seconds for a controller (default 60)\n"
    "  --timeout S      end the flight when the controller is silent for S seconds (default 1)\n"
    "\n"
    "exit status: 0 the controller ended the flight, 1 bad input, no controller or it went\n"
    "silent, 2 usage, 130 interrupted\n";

// What the vehicle flies, from the scenario.
struct VehicleSpec {
  std::string name;
  std::string model;
  double dt = 0.015;      // control period [s]
  double h = 0.001;       // plant substep [s]
  Eigen::Vector3d start;  // hover position [m]
  double u_min = 0, u_max = 0;  // input bounds, where the rotors saturate
  VehicleWorld world;     // where it may fly
};

std::int64_t ns_of(double seconds) { return std::int64_t(std::llround(seconds * 1e9)); }

std::optional<double> parse_number(const std::string& v, double lo, double hi) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end || !(x >= lo && x <= hi)) return std::nullopt;
  return x;
}

struct Options {
  std::string scenario;
  double latency_s = 0.0;
  std::uint32_t domain = 0;
  double wait_s = 60.0;
  double timeout_s = 1.0;
};

enum class End { by_controller, controller_silent, no_controller, interrupted };

// The plant of `Model` on the wall clock, with the latency lines of both links.
template <class Model>
int fly_vehicle(const Model& model, const VehicleSpec& spec, const Options& o) {
  using State = typename Model::State;
  using Input = typename Model::Input;
  std::string error;
  net::use_loopback_unless_configured();
  // A vehicle's firmware is real time: this loop and the DDS threads it starts run under
  // SCHED_FIFO where the system allows (the scope lasts the flight).
  const RealtimeThreadsScope realtime;
  net::VehicleEndpoint link;
  if (!link.open(o.domain, net::CommandCheck::Limits{Model::nu, spec.dt, spec.u_min, spec.u_max,
                                                     VehicleFeed::kMaxRtt},
                 error)) {
    std::fprintf(stderr, "mixpilot vehicle: %s\n", error.c_str());
    return kExitError;
  }
  const VehiclePlant<Model> plant(model);
  State x = model.hover_state(spec.start);
  Input u = model.hover_input();
  std::int64_t cmd_step = -1, cmd_stamp = 0, applied_ns = 0;
  std::uint8_t status = 0;
  const char* left_how = nullptr;  // how it left its world
  std::int64_t left_at = 0;

  struct Inbound {
    std::int64_t due, step, stamp;
    Input u;
  };
  struct Outbound {
    std::int64_t due, measured, step, stamp;
    double age;
    std::uint8_t status;
    State x;
  };
  std::deque<Inbound> inbound;
  std::deque<Outbound> outbound;
  const std::int64_t latency = ns_of(o.latency_s);
  const std::int64_t h = ns_of(spec.h);
  std::int64_t t_plant = vehicle_clock_ns();  // the plant's state x is at this instant

  // Integrates to `to` with the command in effect (the vehicle rests before the first).
  const auto advance = [&](std::int64_t to) {
    if (cmd_step < 0 || status != 0) {
      t_plant = std::max(t_plant, to);
      return;
    }
    if (const char* outside = plant.advance(x, u, t_plant, to, h, spec.world)) {
      status = 1;  // left its world: the last state inside stays
      left_how = outside;
      left_at = t_plant;
      t_plant = to;
    }
  };
  const auto measure = [&](std::int64_t at) {
    outbound.push_back(Outbound{at + latency, at, cmd_step, cmd_stamp,
                                cmd_step >= 0 ? 1e-9 * double(at - applied_ns) : 0.0, status, x});
  };

  std::printf("mixpilot vehicle: %s (%s) in DDS domain %u, latency %.0f ms each way, %s; "
              "waiting for a controller (fly --vehicle dds)\n",
              spec.name.c_str(), spec.model.c_str(), unsigned(o.domain), 1e3 * o.latency_s,
              realtime.granted() ? "SCHED_FIFO" : "normal priority");
  std::fflush(stdout);
  catch_interrupts();
  const std::int64_t started = vehicle_clock_ns();
  const std::int64_t period = ns_of(spec.dt);
  std::int64_t last_measured = started - period, last_heard = started, first_applied = -1;
  std::int64_t applied = 0;
  std::uint64_t rejected_at_heard = 0;  // the link's rejections when a command was last taken
  bool end_asked = false;
  End end = End::by_controller;
  std::vector<net::VehicleCommand> taken;
  for (;;) {
    std::int64_t now = vehicle_clock_ns();
    std::int64_t next = now + ns_of(0.02);
    if (!inbound.empty()) next = std::min(next, inbound.front().due);
    if (!outbound.empty()) next = std::min(next, outbound.front().due);
    next = std::min(next, last_measured + (cmd_step < 0 ? period : 2 * period));
    taken.clear();
    link.wait(next - now, taken);
    now = vehicle_clock_ns();
    for (const net::VehicleCommand& c : taken) {
      last_heard = now;
      rejected_at_heard = link.rejected();
      if (c.end) {
        end_asked = true;
        continue;
      }
      Inbound in{now + latency, c.step, c.stamp_ns, Input::Zero()};
      for (int i = 0; i < Model::nu; ++i) in.u(i) = c.u[std::size_t(i)];
      // The rotors saturate where the model's bounds are.
      in.u = in.u.cwiseMax(spec.u_min).cwiseMin(spec.u_max);
      inbound.push_back(in);
    }
    while (!inbound.empty() && inbound.front().due <= now) {
      const Inbound& in = inbound.front();
      advance(in.due);
      u = in.u;
      cmd_step = in.step;
      cmd_stamp = in.stamp;
      applied_ns = in.due;
      if (first_applied < 0) {
        first_applied = in.due;
        t_plant = in.due;
      }
      ++applied;
      measure(in.due);
      last_measured = in.due;
      inbound.pop_front();
    }
    if (!end_asked && now - last_measured >= (cmd_step < 0 ? period : 2 * period)) {
      advance(now);
      measure(now);
      last_measured = now;
    }
    while (!outbound.empty() && outbound.front().due <= now) {
      const Outbound& s = outbound.front();
      link.publish(net::VehicleStateOut{s.measured, s.step, s.stamp, s.age, s.status, s.x.data(),
                                        Model::nx});
      outbound.pop_front();
    }
    if (interrupted()) {
      end = End::interrupted;
      break;
    }
    if (end_asked && inbound.empty() && outbound.empty()) break;
    if (first_applied >= 0 && now - last_heard > ns_of(o.timeout_s)) {
      end = End::controller_silent;
      break;
    }
    if (first_applied < 0 && now - started > ns_of(o.wait_s)) {
      end = End::no_controller;
      break;
    }
  }
  const net::VehicleEndpointStats st = link.stats();
  const double flown = first_applied >= 0 ? 1e-9 * double(t_plant - first_applied) : 0.0;
  std::printf("  %lld commands applied over %.2f s, %llu states sent; rejected: %llu bad value, "
              "%llu bad size, %llu stale, %llu of another controller (%u heard)\n",
              (long long)applied, flown, (unsigned long long)st.states_sent,
              (unsigned long long)st.bad_value, (unsigned long long)st.bad_size,
              (unsigned long long)st.stale, (unsigned long long)st.other_publisher,
              unsigned(st.publishers));
  std::printf("  final position (%.3f, %.3f, %.3f) m\n", x(0), x(1), x(2));
  if (status == 1)
    std::printf("  the vehicle left its world at t = %.2f s (%s); every state after said so\n",
                1e-9 * double(left_at - first_applied), left_how);
  if (!st.last_rejection.empty())
    std::printf("  the newest command rejected: %s\n", st.last_rejection.c_str());
  // Commands that arrived and were all rejected are not silence: say which and why.
  const std::uint64_t rejected_since = st.rejected() - rejected_at_heard;
  switch (end) {
    case End::by_controller:
      std::printf("  the controller ended the flight\n");
      return kExitOk;
    case End::controller_silent:
      if (rejected_since > 0) {
        std::fprintf(stderr,
                     "mixpilot vehicle: no command taken for %.2f s: %llu commands arrived and "
                     "were rejected (the newest as %s): flight over\n",
                     o.timeout_s, (unsigned long long)rejected_since, st.last_rejection.c_str());
      } else {
        std::fprintf(stderr,
                     "mixpilot vehicle: the controller went silent for %.2f s: flight over\n",
                     o.timeout_s);
      }
      return kExitError;
    case End::no_controller:
      if (st.rejected() > 0) {
        std::fprintf(stderr,
                     "mixpilot vehicle: no command taken within %.0f s: %llu arrived and were "
                     "rejected (the newest as %s)\n",
                     o.wait_s, (unsigned long long)st.rejected(), st.last_rejection.c_str());
      } else {
        std::fprintf(stderr, "mixpilot vehicle: no controller within %.0f s\n", o.wait_s);
      }
      return kExitError;
    case End::interrupted:
      std::printf("  interrupted\n");
      return kExitInterrupted;
  }
  return kExitOk;
}

}  // namespace

int vehicle_command(int argc, char** argv) {
  Options o;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return option_value("vehicle", argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    } else if (a == "--scenario") {
      o.scenario = value();
    } else if (a == "--latency") {
      const std::string v = value();
      const auto ms = parse_number(v, 0.0, 1000.0);
      if (!ms) usage_error("vehicle", "--latency expects milliseconds from 0 to 1000, got '" + v + "'");
      o.latency_s = *ms * 1e-3;
    } else if (a == "--domain") {
      o.domain = parse_domain("vehicle", value());
    } else if (a == "--wait" || a == "--timeout") {
      const std::string v = value();
      const auto s = parse_number(v, a == "--wait" ? 0.0 : 0.05, 3600.0);
      if (!s) usage_error("vehicle", a + " expects seconds (up to 3600), got '" + v + "'");
      (a == "--wait" ? o.wait_s : o.timeout_s) = *s;
    } else {
      usage_error("vehicle", "unknown argument '" + a + "'");
    }
  }
  if (o.scenario.empty()) usage_error("vehicle", "--scenario FILE is required");
  std::string text, error;
  if (!read_text_file(o.scenario, text, error)) {
    std::fprintf(stderr, "mixpilot vehicle: %s\n", error.c_str());
    return kExitError;
  }
  const std::optional<std::string> mode = scenario_mode(text, o.scenario, error);
  if (!mode) {
    std::fprintf(stderr, "mixpilot vehicle: %s\n", error.c_str());
    return kExitError;
  }
  if (*mode == "crazyflie_tracking") {
    const auto sc = parse_tracking_scenario(text, o.scenario, error);
    if (!sc) {
      std::fprintf(stderr, "mixpilot vehicle: %s\n", error.c_str());
      return kExitError;
    }
    const models::Crazyflie model;
    const VehicleSpec spec{sc->name,
                           "crazyflie",
                           sc->controller.dt,
                           1.0 / sc->plant.rate_hz,
                           sc->plant.start,
                           model.p.omega_min,
                           model.p.omega_max,
                           VehicleWorld::ball(sc->plant.start, tracking_defaults::kLostRadius,
                                              -VehicleWorld::kGroundMargin)};
    return fly_vehicle(model, spec, o);
  }
  if (*mode == "mixed_initiative") {
    const auto sc = parse_scenario(text, o.scenario, error);
    if (!sc) {
      std::fprintf(stderr, "mixpilot vehicle: %s\n", error.c_str());
      return kExitError;
    }
    const models::MikroKopter model;
    const VehicleSpec spec{
        sc->name,
        "mikrokopter",
        sc->controller.dt,
        1.0 / sc->plant.rate_hz,
        sc->reference.position(0.0),
        model.p.tau_min,
        model.p.tau_max,
        VehicleWorld::box(sc->arena.min, sc->arena.max, mi_defaults::kLostMargin)};
    return fly_vehicle(model, spec, o);
  }
  std::fprintf(stderr, "mixpilot vehicle: %s: mode '%s' has no remote vehicle; it flies "
               "crazyflie_tracking and mixed_initiative scenarios\n", o.scenario.c_str(),
               mode->c_str());
  return kExitError;
}

}  // namespace mixpilot::cli
