// mixpilot command-line entry point: headless flights, batch scoring, model checks.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/numerics/version.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"

namespace mixpilot::cli {

namespace {

constexpr const char* kUsage =
    "usage: mixpilot <command> [options]\n"
    "\n"
    "commands:\n"
    "  fly     fly a session in the window (real time), or headless as fast as possible\n"
    "  replay  show a recording (any mode) in the window, or headless screenshots or a\n"
    "          video of it\n"
    "  score   replay and score recorded sessions (or a folder of them, sharded)\n"
    "  recover rebuild a recording cut short by a crash or kill -9\n"
    "  gamepad-script  a recording's pilot commands as a virtual gamepad's script\n"
    "  joy-publish     a recording's sticks as sensor_msgs/msg/Joy over DDS\n"
    "  vehicle         a scenario's vehicle in its own process, for fly --vehicle dds\n"
    "  instruct        the instructor: list the stations (fly --publish), command one\n"
    "  history the flights remembered (table, CSV, JSON); import recordings into it\n"
    "  lesson  fly a trainee's current step of a lesson, judged and remembered\n"
    "  sweep   fly a sweep file's grid of runs on every core (or one shard) into a table\n"
    "  figures the thesis's figures from flights of the shipped scenarios (PNG, CSV, index)\n"
    "  demo    fly scenarios/mi_helix.toml with the emulated novice pilot and print its score\n"
    "  models  open-loop check of each dynamic model\n"
    "\n"
    "Run 'mixpilot <command> --help' for a command's options.\n"
    "\n"
    "environment:\n"
    "  MIXPILOT_DATA_DIR  the folder with the shipped scenarios/ and assets/ (default:\n"
    "                     <folder of the executable>/../share/mixpilot, /usr/share/mixpilot\n"
    "                     when installed)\n"
    "  CYCLONEDDS_URI     Cyclone DDS configuration (default: loopback only, docs/network.md)\n"
    "  XDG_CONFIG_HOME, XDG_DATA_HOME  where input settings, gamepad mappings, the window's\n"
    "                     recordings and the history go (~/.config/mixpilot,\n"
    "                     ~/.local/share/mixpilot)\n"
    "  -h, --help      show this help\n"
    "  --version       print the version\n"
    "\n"
    "exit status: 0 done, 1 bad input or failure, 2 usage, 3 a replay differs from its\n"
    "recording, 4 (lesson) a step was flown and did not pass, 130 interrupted\n";

constexpr const char* kDemoUsage =
    "usage: mixpilot demo\n"
    "\n"
    "Flies the shipped scenarios/mi_helix.toml headless with the emulated novice pilot, as fast\n"
    "as possible, and prints its summary and score: what `mixpilot fly --scenario\n"
    "<data>/scenarios/mi_helix.toml --pilot novice --headless` does. Nothing is written.\n"
    "\n"
    "  -h, --help  show this help\n"
    "\n"
    "environment: MIXPILOT_DATA_DIR, the folder holding scenarios/ (see 'mixpilot --help')\n"
    "\n"
    "exit status: 0 done, 1 no data folder or a failure, 2 usage, 130 interrupted\n";

constexpr const char* kModelsUsage =
    "usage: mixpilot models\n"
    "\n"
    "Simulates each dynamic model open loop with ERK4 (the Pendubot swinging freely, the\n"
    "Crazyflie and the MikroKopter at hover for 10 s) and prints its energy or position drift:\n"
    "a check of the models and the integrator. Nothing is read or written.\n"
    "\n"
    "  -h, --help  show this help\n"
    "\n"
    "exit status: 0 done, 2 usage\n";

// Open-loop simulation of `seconds` of the model from x0 under constant u with ERK4 at dt.
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

}  // namespace

int models_command() {
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
  }
  {
    const models::MikroKopter mk;
    const auto x0 = mk.hover_state({0.0, 0.0, 1.0});
    const auto x = simulate(mk, x0, mk.hover_input(), 0.015, 10.0);
    std::printf("%-12s %-44s drift %.1e m, rotors at %.4f\n", "mikrokopter",
                "hover torque 0.0756 N m, 10 s @ 15 ms", (x - x0).head<3>().norm(), x(12));
  }
  return 0;
}

}  // namespace mixpilot::cli

namespace {

int dispatch(int argc, char** argv) {
  using namespace mixpilot::cli;
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
    std::printf("%s\n", mixpilot::version());
    return 0;
  }
  if (cmd == "fly") return fly_command(argc, argv);
  if (cmd == "replay") return replay_command(argc, argv);
  if (cmd == "score") return score_command(argc, argv);
  if (cmd == "recover") return recover_command(argc, argv);
  if (cmd == "gamepad-script") return gamepad_script_command(argc, argv);
  if (cmd == "joy-publish") return joy_publish_command(argc, argv);
  if (cmd == "vehicle") return vehicle_command(argc, argv);
  if (cmd == "history") return history_command(argc, argv);
  if (cmd == "instruct") return instruct_command(argc, argv);
  if (cmd == "lesson") return lesson_command(argc, argv);
  if (cmd == "sweep") return sweep_command(argc, argv);
  if (cmd == "figures") return figures_command(argc, argv);
  if (cmd == "demo" || cmd == "models") {
    if (argc > 2) {
      if (std::strcmp(argv[2], "--help") == 0 || std::strcmp(argv[2], "-h") == 0) {
        std::fputs(cmd == "demo" ? kDemoUsage : kModelsUsage, stdout);
        return 0;
      }
      std::fprintf(stderr, "mixpilot %s: unexpected argument '%s'\n", argv[1], argv[2]);
      return 2;
    }
    return cmd == "models" ? models_command() : demo_command();
  }
  std::fprintf(stderr, "mixpilot: unknown command '%s' (see 'mixpilot --help')\n", argv[1]);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return dispatch(argc, argv);
  } catch (const mixpilot::cli::UsageError& e) {
    mixpilot::cli::print_usage_error(e);
    return mixpilot::cli::kExitUsage;
  }
}
