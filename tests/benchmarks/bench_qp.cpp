// BM_QpSolve/<problem>: one OCP-QP solve by the Riccati IPM behind partial condensing of stage
// pairs, twice (QpRiccatiIpmPairs' default: blocks of 4 stages; SPEC §4), on the QPs of
// tests/qp_problems.hpp, at the default tolerances (complementarity 1e-8, stationarity 1e-6).
// The condensing and the expansion of the solution are part of every timed solve.
//   mi         MikroKopter mixed-initiative (SPEC §5.4): nx 16, nu 4, N 50, 4 τ bounds per stage,
//              4 Ω bounds on stages 1..N
//   crazyflie  nx 13, nu 4, N 50, 4 input bounds (SPEC §5.2)
//   pendubot   nx 4, nu 1, N 10, input bound and two ℓ2²-soft velocity bounds (SPEC §5.1)
// <problem> is cold-started; <problem>_warm solves the next sampling instant's QP (x0 = predicted
// x_1 plus a 2 % disturbance) warm-started (primal-dual) from the shifted solution, as in RTI.
// <problem>_dense: the same with QpCondensedDense (condensing + dense IPM, short horizons); its
// Hessian condensing is part of every timed solve (in RTI it runs in prepare()).
// <problem>_stagewise: the same with QpRiccatiIpm (the Riccati recursion over all N stages).
// Counter "iterations": IPM iterations per solve.
//
// MIXPILOT_DUMP_QP=<file> appends each QP solved here (once per benchmark) to <file> as one JSON
// line, with the solver settings; format in docs/qp-dump-format.md.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <string>

#include "core/qp/ocp_qp_io.hpp"
#include "core/qp/qp_condensed_dense.hpp"
#include "core/qp/qp_riccati_ipm.hpp"
#include "core/qp/qp_riccati_ipm_pairs.hpp"
#include "tests/qp_problems.hpp"

namespace mixpilot {
namespace {

QpRiccatiIpmSettings bench_settings() {
  QpRiccatiIpmSettings s;
  s.tol_comp = 1e-8;
  s.tol_stat = 1e-6;
  return s;
}

void dump_once(const std::string& name, const OcpQp& qp, const QpRiccatiIpmSettings& settings) {
  static std::set<std::string> done;
  const char* path = std::getenv("MIXPILOT_DUMP_QP");
  if (path == nullptr || *path == '\0' || !done.insert(name).second) return;
  std::ofstream out(path, std::ios::app);
  write_ocp_qp_json(out, qp, settings, name);
}

// RTI shift: stage i takes stage i+1's values where the sizes agree (the last stage keeps its own).
void shift(OcpQpSolution& s) {
  auto sh = [](std::vector<Eigen::VectorXd>& v) {
    for (std::size_t i = 0; i + 1 < v.size(); ++i)
      if (v[i].size() == v[i + 1].size()) v[i] = v[i + 1];
  };
  sh(s.x), sh(s.u), sh(s.pi), sh(s.lam_l), sh(s.lam_u), sh(s.sl), sh(s.su), sh(s.lam_sl),
      sh(s.lam_su);
}

template <class Solver = QpRiccatiIpm>
void run(benchmark::State& state, const std::string& name, const OcpQp& base, bool warm) {
  const QpRiccatiIpmSettings settings = bench_settings();
  Solver solver(base.dims, settings);
  OcpQpSolution sol(base.dims), start(base.dims);
  OcpQp qp = base;
  if (warm) {
    // The next sampling instant: x0 is the predicted x_1 plus a disturbance; warm start from
    // the shifted previous solution.
    if (solver.solve(base, start) != QpStatus::success) state.SkipWithError("first solve failed");
    qp.x0 = start.x[1] + 0.02 * start.x[1].cwiseAbs().cwiseMax(1e-3);
    shift(start);
  }
  dump_once(name, qp, settings);
  QpStatus status = QpStatus::success;
  for (auto _ : state) {
    if (warm) sol = start;  // same sizes: a copy without allocation
    status = solver.solve(qp, sol, warm ? QpWarmStart::primal_dual : QpWarmStart::cold);
    benchmark::DoNotOptimize(sol.x.data());
    benchmark::ClobberMemory();
  }
  if (status != QpStatus::success) state.SkipWithError(to_string(status));
  state.counters["iterations"] = sol.iterations;
}

const OcpQp& mi() {
  static const OcpQp qp = testing_qp::mixed_initiative_qp();
  return qp;
}
const OcpQp& crazyflie() {
  static const OcpQp qp = testing_qp::crazyflie_qp();
  return qp;
}
const OcpQp& pendubot() {
  static const OcpQp qp = testing_qp::pendubot_qp();
  return qp;
}

template <class Solver>
void add(const std::string& name, const OcpQp& (*problem)(), bool warm) {
  benchmark::RegisterBenchmark(name.c_str(), [name, problem, warm](benchmark::State& state) {
    run<Solver>(state, name, problem(), warm);
  })->Unit(benchmark::kMicrosecond);
}

// Per problem: QpRiccatiIpmPairs (default levels), then the stage-wise Riccati IPM; full
// condensing where the horizon suits it.
const bool registered = [] {
  struct Problem {
    const char* name;
    const OcpQp& (*qp)();
  };
  for (const Problem p : {Problem{"mi", mi}, Problem{"crazyflie", crazyflie},
                          Problem{"pendubot", pendubot}}) {
    const std::string base = std::string("BM_QpSolve/") + p.name;
    for (const bool warm : {false, true}) {
      const std::string suffix = warm ? "_warm" : "";
      add<QpRiccatiIpmPairs>(base + suffix, p.qp, warm);
      add<QpRiccatiIpm>(base + "_stagewise" + suffix, p.qp, warm);
    }
  }
  add<QpCondensedDense>("BM_QpSolve/pendubot_dense", pendubot, false);
  add<QpCondensedDense>("BM_QpSolve/pendubot_dense_warm", pendubot, true);
  add<QpCondensedDense>("BM_QpSolve/crazyflie_dense", crazyflie, false);
  return true;
}();

}  // namespace
}  // namespace mixpilot
