// BM_Rti/mi: one control step of the mixed-initiative NMPC (SPEC §5.4, N = 50) on mi_helix,
// flown by the emulated novice (whose λ moves the most). Only MiController::step is timed
// (manual timing); the pilot's own NMPC and the plant run untimed between steps. The flight is
// restarted every 400 steps, after 100 untimed warm-up steps, so it never leaves the helix.
// The QP is solved by the RTI default (QpRiccatiIpmPairs, pairs condensed in prepare());
// BM_Rti/mi_stagewise: the same with QpRiccatiIpm.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <memory>

#include "core/control/mi_controller.hpp"
#include "core/control/pilot_emulated.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot {
namespace {

void BM_RtiMi(benchmark::State& state, QpSolverKind qp_solver) {
  std::string error;
  const auto sc = load_scenario(MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml", error);
  if (!sc) {
    state.SkipWithError(error.c_str());
    return;
  }
  const models::MikroKopter model;
  const IntegratorErk4<models::MikroKopter> plant(model);
  const double dt = sc->controller.dt;
  auto controller = std::make_unique<MiController>();
  auto pilot = std::make_unique<EmulatedPilot>();
  models::MikroKopter::State x, xn;
  std::int64_t k = 0;
  PilotCommand cmd;

  const auto plant_step = [&](const Eigen::VectorXd& u) {
    const models::MikroKopter::Input us = u;
    for (int s = 0; s < 15; ++s) {
      plant.step(x, us, dt / 15, xn);
      x = xn;
    }
  };
  const auto restart = [&] {
    controller = std::make_unique<MiController>();
    pilot = std::make_unique<EmulatedPilot>();
    RtiSettings rti;
    rti.qp_solver = qp_solver;
    if (!controller->setup(model, sc->controller, sc->arena, sc->reference, rti) ||
        !pilot->setup(model, sc->pilots.at("novice"), sc->reference, dt))
      std::abort();  // the shipped scenario's settings form valid OCPs
    x = model.hover_state(sc->reference.position(0.0));
    controller->reset(x);
    for (k = 0; k < 100; ++k) {
      pilot->command(k, k * dt, x, cmd);
      controller->step(k * dt, x, cmd);
      plant_step(controller->control());
    }
  };
  restart();

  double integration = 0, linearization = 0, qp = 0, iterations = 0;
  for (auto _ : state) {
    pilot->command(k, k * dt, x, cmd);
    const auto t0 = std::chrono::steady_clock::now();
    controller->step(k * dt, x, cmd);
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    const RtiStats& st = controller->rti().stats();
    integration += st.integration_us;
    linearization += st.linearization_us;
    qp += st.qp_us;
    iterations += st.qp_iterations;
    plant_step(controller->control());
    if (++k == 500) restart();
  }
  const double n = double(state.iterations());
  state.counters["integration_us"] = integration / n;
  state.counters["linearization_us"] = linearization / n;
  state.counters["qp_us"] = qp / n;
  state.counters["qp_iterations"] = iterations / n;
}
BENCHMARK_CAPTURE(BM_RtiMi, default, rti_defaults::kQpSolver)
    ->Name("BM_Rti/mi")
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RtiMi, stagewise, QpSolverKind::riccati_ipm)
    ->Name("BM_Rti/mi_stagewise")
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mixpilot
