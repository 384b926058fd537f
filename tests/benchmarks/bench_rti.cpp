// BM_Rti/crazyflie_tracking: one control step (prepare + feedback + shift) of the SPEC §5.2
// tracking NMPC at N = 50, flying the Ipopt smooth-step reference. The closed loop runs inside
// the benchmark (plant and reference updates untimed, via manual timing); it starts 10 steps
// into the maneuver, where the inputs and attitude change fastest, and rewinds every 20 steps.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "core/control/crazyflie_tracking.hpp"
#include "core/nlp/rti.hpp"
#include "core/nlp/trajectory_io.hpp"

namespace mixpilot {
namespace {

void BM_RtiCrazyflieTracking(benchmark::State& state) {
  std::string error;
  const auto ref = read_trajectory_csv(
      MIXPILOT_SOURCE_DIR "/scenarios/references/crazyflie_smooth_step.csv", error);
  if (!ref) {
    state.SkipWithError(error.c_str());
    return;
  }
  CrazyflieTracking problem(50, 0.015);
  RtiSolver rti;
  if (const SetupResult r = rti.setup(problem.ocp()); !r) {
    state.SkipWithError(r.reason().c_str());
    return;
  }
  const auto& erk4 = problem.integrator();

  constexpr int kStart = 10, kSpan = 20;
  OcpTrajectory start_traj;
  Eigen::VectorXd start_x;
  {  // Warm up the closed loop to the start of the measured window.
    problem.hover_guess(rti.trajectory(), {0, 0, 0.4});
    Eigen::VectorXd x = problem.model().hover_state({0, 0, 0.4});
    for (int k = 0; k < kStart; ++k) {
      problem.set_reference(rti.data(), ref->trajectory, k);
      rti.prepare();
      rti.feedback(x);
      Eigen::VectorXd xn(13);
      erk4.step(x, rti.control(), 0.015, xn);
      x = xn;
      rti.shift();
    }
    start_traj = rti.trajectory();
    start_x = x;
  }

  Eigen::VectorXd x = start_x, xn(13), u(4);
  int k = kStart;
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
    erk4.step(x, u, 0.015, xn);  // plant (untimed)
    x = xn;
    if (++k == kStart + kSpan) {
      k = kStart;
      x = start_x;
      rti.trajectory() = start_traj;
    }
    problem.set_reference(rti.data(), ref->trajectory, k);
  }
  const double n = double(state.iterations());
  state.counters["integration_us"] = integration / n;
  state.counters["linearization_us"] = linearization / n;
  state.counters["qp_us"] = qp / n;
  state.counters["qp_iterations"] = iterations / n;
}
BENCHMARK(BM_RtiCrazyflieTracking)->Name("BM_Rti/crazyflie_tracking")->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mixpilot
