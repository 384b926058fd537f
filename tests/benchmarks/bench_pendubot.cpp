// BM_Rti/pendubot: one control step (prepare + feedback + shift) of the SPEC §5.1 swing-up NMPC
// at N = 10, Δt = 2 ms, tracking the committed Ipopt reference. The closed loop (exact state,
// RK4 plant at 0.25 ms substeps) runs inside the benchmark with manual timing; the window starts
// mid-swing (t = 0.5 s: q̇1 near the reference's 7 rad/s peak) and rewinds every 20 steps. QP by
// condensing + warm-started active set (the mode's default) and, for comparison, condensing +
// dense IPM and the Riccati IPM.
// Thesis figure: 98.6 µs (ACADO + qpOASES, i7-4770).
#include <benchmark/benchmark.h>

#include <chrono>

#include "core/control/pendubot.hpp"
#include "core/nlp/rti.hpp"
#include "core/nlp/trajectory_io.hpp"

namespace mixpilot {
namespace {

void BM_RtiPendubot(benchmark::State& state, QpSolverKind qp_solver) {
  std::string error;
  const auto ref = read_trajectory_csv(
      MIXPILOT_SOURCE_DIR "/scenarios/references/pendubot_swingup.csv", error);
  if (!ref) {
    state.SkipWithError(error.c_str());
    return;
  }
  const OcpTrajectory& r = ref->trajectory;
  const PendubotSwingup problem;
  RtiSolver rti;
  RtiSettings settings;
  settings.qp_solver = qp_solver;
  if (const SetupResult r = rti.setup(problem.ocp(), settings); !r) {
    state.SkipWithError(r.reason().c_str());
    return;
  }
  const auto& erk4 = problem.integrator();
  constexpr double dt = 0.002;
  constexpr int kSubsteps = 8;

  models::Pendubot::State x = models::Pendubot::down_down(), xn;
  auto plant = [&](double u) {
    for (int j = 0; j < kSubsteps; ++j) {
      erk4.step<double>(x, models::Pendubot::Input(u), dt / kSubsteps, xn);
      x = xn;
    }
  };

  constexpr int kStart = 250, kSpan = 20;
  for (int i = 0; i <= 10; ++i) rti.trajectory().x[i] = r.x[i];
  for (int i = 0; i < 10; ++i) rti.trajectory().u[i] = r.u[i];
  Eigen::VectorXd x0(4);
  for (int k = 0; k < kStart; ++k) {  // warm up the closed loop to the window
    problem.set_reference(rti.data(), r, k);
    rti.prepare();
    x0 = x;
    rti.feedback(x0);
    const double u = rti.control()(0);
    rti.shift();
    plant(u);
  }
  const OcpTrajectory start_traj = rti.trajectory();
  const models::Pendubot::State start_x = x;

  int k = kStart;
  double integration = 0, linearization = 0, qp = 0, iterations = 0;
  problem.set_reference(rti.data(), r, k);
  for (auto _ : state) {
    x0 = x;
    const auto t0 = std::chrono::steady_clock::now();
    rti.prepare();
    rti.feedback(x0);
    const double u = rti.control()(0);
    rti.shift();
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    integration += rti.stats().integration_us;
    linearization += rti.stats().linearization_us;
    qp += rti.stats().qp_us;
    iterations += rti.stats().qp_iterations;
    plant(u);  // untimed
    if (++k == kStart + kSpan) {
      k = kStart;
      x = start_x;
      rti.trajectory() = start_traj;
    }
    problem.set_reference(rti.data(), r, k);
  }
  const double n = double(state.iterations());
  state.counters["integration_us"] = integration / n;
  state.counters["linearization_us"] = linearization / n;
  state.counters["qp_us"] = qp / n;
  state.counters["qp_iterations"] = iterations / n;
}
// Condensing + active set (the short-horizon QP variant, SPEC §4), + dense IPM, the Riccati IPM.
BENCHMARK_CAPTURE(BM_RtiPendubot, active_set, QpSolverKind::condensed_active_set)
    ->Name("BM_Rti/pendubot")->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RtiPendubot, dense_ipm, QpSolverKind::condensed_dense)
    ->Name("BM_Rti/pendubot_dense_ipm")->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RtiPendubot, riccati, QpSolverKind::riccati_ipm)
    ->Name("BM_Rti/pendubot_riccati")->UseManualTime()->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mixpilot
