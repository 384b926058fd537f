// mixpilot command-line entry point.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "core/integrator_erk4.hpp"
#include "core/version.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"

namespace {

constexpr const char* kUsage =
    "usage: mixpilot <command> [options]\n"
    "\n"
    "commands:\n"
    "  demo        headless open-loop simulation of each dynamic model, with a short summary\n"
    "\n"
    "options:\n"
    "  -h, --help      show this help\n"
    "  --version       print the version\n";

using namespace mixpilot;

// Simulates `seconds` of the model from x0 under constant u with ERK4 at dt.
template <class M>
typename M::State simulate(const M& model, typename M::State x, const typename M::Input& u,
                           double dt, double seconds) {
  const IntegratorErk4<M> erk4(model);
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int k = 0; k < steps; ++k) {
    typename M::State xn;
    erk4.step(x, u, dt, xn);
    x = xn;
  }
  return x;
}

int run_demo() {
  std::printf("%s: headless model check (open loop, ERK4)\n\n", version());
  std::printf("%-12s %-44s %s\n", "model", "experiment", "result");

  {
    const models::Pendubot pb;
    const models::Pendubot::State x0(-std::acos(-1.0) + 1.2, 0.8, 0.0, 0.0);
    const auto x = simulate(pb, x0, models::Pendubot::Input::Zero().eval(), 1e-3, 10.0);
    std::printf("%-12s %-44s energy drift %.1e (relative)\n", "pendubot",
                "free swing from rest, u = 0, 10 s @ 1 ms",
                std::abs(pb.energy(x) - pb.energy(x0)) / pb.energy(x0));
  }
  {
    const models::Crazyflie cf;
    const auto x0 = cf.hover_state({0.0, 0.0, 0.4});
    const auto x = simulate(cf, x0, cf.hover_input(), 0.015, 10.0);
    std::printf("%-12s %-44s drift %.1e m, |q| - 1 = %.0e\n", "crazyflie",
                "hover at 15.78 krpm, 10 s @ 15 ms", (x - x0).head<3>().norm(),
                x.segment<4>(3).norm() - 1.0);
    auto u = cf.hover_input();
    u *= 1.01;  // 2% more thrust: climbs at ≈ 0.02 g
    const auto xc = simulate(cf, x0, u, 0.015, 2.0);
    std::printf("%-12s %-44s climbed %.3f m (expected %.3f)\n", "crazyflie",
                "1% over hover speed, 2 s", xc(2) - x0(2),
                0.5 * (1.01 * 1.01 - 1.0) * cf.p.g * 4.0);
  }
  {
    const models::MikroKopter mk;
    const auto x0 = mk.hover_state({0.0, 0.0, 1.0});
    const auto x = simulate(mk, x0, mk.hover_input(), 0.015, 10.0);
    std::printf("%-12s %-44s drift %.1e m, rotors at %.4f\n", "mikrokopter",
                "hover torque 0.0756 N m, 10 s @ 15 ms", (x - x0).head<3>().norm(), x(12));
    auto xs = x0;
    xs.tail<4>().setZero();
    const auto xr = simulate(mk, xs, mk.hover_input(), 0.001, 0.2);
    std::printf("%-12s %-44s rotor speed %.4f after 0.2 s (hover %.4f)\n", "mikrokopter",
                "spin-up from rest at hover torque", xr(12), mk.hover_speed());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  const std::string_view cmd = argv[1];
  if (cmd == "-h" || cmd == "--help" || cmd == "help") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (cmd == "--version") {
    std::printf("%s\n", version());
    return 0;
  }
  if (cmd == "demo") {
    if (argc > 2) {
      std::fprintf(stderr, "mixpilot demo: unexpected argument '%s'\n", argv[2]);
      return 2;
    }
    return run_demo();
  }
  std::fprintf(stderr, "mixpilot: unknown command '%s' (see 'mixpilot --help')\n", argv[1]);
  return 2;
}
