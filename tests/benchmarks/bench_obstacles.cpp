// BM_Rti/obstacles: one control step (prepare + feedback + shift) of the SPEC §5.3 obstacle-
// avoidance NMPC (N = 50, LCL form) mid-avoidance in scenarios/obstacles_thrown_balls.toml: the
// closed loop is flown to 0.75 s (ball 1 in flight, its clearance active over the horizon) and
// the measured window spans the 20 steps up to the closest approach at ~0.9 s, rewinding after.
// Plant, reference and obstacle updates are untimed (manual timing). Counters: the split of a
// step (integration, linearization, QP) and QP iterations.
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "core/nlp/rti.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/scenario/obstacle_scenario.hpp"

namespace mixpilot {
namespace {

void BM_RtiObstacles(benchmark::State& state) {
  std::string error;
  const auto sc = load_obstacle_scenario(
      MIXPILOT_SOURCE_DIR "/scenarios/obstacles_thrown_balls.toml", error);
  if (!sc) {
    state.SkipWithError(error.c_str());
    return;
  }
  ObstacleAvoidanceOcp problem(sc->world.size(), sc->controller);
  RtiSolver rti;
  if (const SetupResult r = rti.setup(problem.ocp()); !r) {
    state.SkipWithError(r.reason().c_str());
    return;
  }
  const auto& erk4 = problem.integrator();
  const OcpTrajectory& ref = sc->reference.trajectory;
  const double dt = sc->controller.dt;

  constexpr int kStart = 50, kSpan = 20;
  const auto plant = [&](models::Crazyflie::State& x, const models::Crazyflie::Input& u) {
    models::Crazyflie::State xn;
    for (int s = 0; s < 15; ++s) {  // 1 kHz RK4, as the mode's plant
      erk4.step(x, u, dt / 15, xn);
      x = xn;
    }
  };
  const auto set_stage_data = [&](int k) {
    problem.set_reference(rti.data(), ref, k);
    problem.set_obstacles(rti.data(), sc->world, k * dt);
  };

  OcpTrajectory start_traj;
  models::Crazyflie::State start_x;
  {  // Warm up the closed loop to the start of the measured window.
    for (int i = 0; i <= problem.ocp().N; ++i) rti.trajectory().x[i] = ref.x[i];
    for (int i = 0; i < problem.ocp().N; ++i) rti.trajectory().u[i] = ref.u[i];
    models::Crazyflie::State x = ref.x[0];
    for (int k = 0; k < kStart; ++k) {
      set_stage_data(k);
      rti.prepare();
      rti.feedback(x);
      plant(x, rti.control());
      rti.shift();
    }
    start_traj = rti.trajectory();
    start_x = x;
  }

  models::Crazyflie::State x = start_x;
  models::Crazyflie::Input u;
  int k = kStart;
  set_stage_data(k);
  double integration = 0, linearization = 0, qp = 0, iterations = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    rti.prepare();
    rti.feedback(x);
    u = rti.control();
    rti.shift();
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    integration += rti.stats().integration_us;
    linearization += rti.stats().linearization_us;
    qp += rti.stats().qp_us;
    iterations += rti.stats().qp_iterations;
    plant(x, u);  // untimed
    if (++k == kStart + kSpan) {
      k = kStart;
      x = start_x;
      rti.trajectory() = start_traj;
    }
    set_stage_data(k);
  }
  const double n = double(state.iterations());
  state.counters["integration_us"] = integration / n;
  state.counters["linearization_us"] = linearization / n;
  state.counters["qp_us"] = qp / n;
  state.counters["qp_iterations"] = iterations / n;
}
BENCHMARK(BM_RtiObstacles)->Name("BM_Rti/obstacles")->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mixpilot
