// The QPs the controllers really solve (tests/benchmarks/qp_sets.hpp): ~200 QPs per flight of
// a shipped scenario, each solved from the warm start the loop used, by the solver the loop
// used (RtiSettings of the mode: the RTI default, stage pairs condensed once).
//
// BM_QpSolve/closed_<set>: one QP per benchmark iteration, going round the set. Timed: the
// QP solver's preparation (the x̄_0-free work: in RTI part of the preparation phase) plus its
// solve (the feedback phase), from QP data to solution; copying the set's QP and warm start
// into the solver's input is not. Counters, over the set's QPs, each QP's fastest time over the
// rounds (repeatable under load): median_us, p90_us, worst_us of preparation + solve,
// feedback_median_us / feedback_p90_us / feedback_worst_us of the solve alone; iterations
// (mean) and max_iterations.
//
// BM_RtiStep/closed_<set>: the flight itself, one mode step per benchmark iteration (the
// flight restarts at its end); timed is the RTI of the step as its statistics measure it:
// preparation + feedback. Counters over the steps of the run: step_median_us, step_p90_us,
// step_worst_us, and feedback_median_us, feedback_p90_us, feedback_worst_us: the feedback phase
// alone (measurement → control), what a real-time loop waits for.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/modes/make_mode.hpp"
#include "tests/benchmarks/qp_sets.hpp"

namespace mixpilot::bench {
namespace {

constexpr int kSetSize = 200;

// The counters <prefix>median_us, <prefix>p90_us and <prefix>worst_us.
void report(benchmark::State& state, const std::string& prefix, const Percentiles& p) {
  state.counters[prefix + "median_us"] = p.median;
  state.counters[prefix + "p90_us"] = p.p90;
  state.counters[prefix + "worst_us"] = p.worst;
}

void BM_QpSolveClosed(benchmark::State& state, const QpSetSpec& spec) {
  const QpSet& set = cached_closed_loop_set(spec, kSetSize);
  if (set.qps.empty()) {
    state.SkipWithError("no QP set (see stderr)");
    return;
  }
  const OcpQpDims& dims = set.qps.front().qp.dims;
  std::unique_ptr<QpSolver> solver = make_qp_solver(set.rti, dims);
  OcpQp qp(dims);
  OcpQpSolution sol(dims);
  const std::size_t n = set.qps.size();
  std::vector<double> best(n, std::numeric_limits<double>::infinity()), best_fb = best;
  std::vector<int> iterations(n, 0);
  std::size_t k = 0;
  bool failed = false;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    const ClosedLoopQp& c = set.qps[k];
    qp = c.qp;  // same sizes: copies without allocating
    sol = c.start;
    const auto t0 = Clock::now();
    solver->prepare(qp, sol, c.warm);  // as the RTI's preparation phase
    const auto t1 = Clock::now();
    const QpStatus st = solver->solve(qp, sol, c.warm);
    const auto t2 = Clock::now();
    benchmark::DoNotOptimize(sol.u.data());
    const double total = std::chrono::duration<double, std::micro>(t2 - t0).count();
    const double fb = std::chrono::duration<double, std::micro>(t2 - t1).count();
    state.SetIterationTime(total * 1e-6);
    best[k] = std::min(best[k], total);
    best_fb[k] = std::min(best_fb[k], fb);
    iterations[k] = sol.iterations;
    failed = failed || st != QpStatus::success;
    k = k + 1 == n ? 0 : k + 1;
  }
  if (failed) state.SkipWithError("a QP of the set failed");
  std::vector<double> t, f;
  double it_sum = 0;
  int it_max = 0, measured = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(best[i])) continue;  // not reached in this run
    t.push_back(best[i]);
    f.push_back(best_fb[i]);
    it_sum += iterations[i];
    it_max = std::max(it_max, iterations[i]);
    ++measured;
  }
  const Percentiles pt = percentiles(t), pf = percentiles(f);
  report(state, "", pt);
  report(state, "feedback_", pf);
  state.counters["iterations"] = measured ? it_sum / measured : 0.0;
  state.counters["max_iterations"] = it_max;
  state.counters["qps"] = measured;
}

void BM_RtiStepClosed(benchmark::State& state, const QpSetSpec& spec) {
  std::string error;
  const auto make = [&] {
    ModeRequest request;
    if (spec.pilot) request.pilot_name = spec.pilot;
    return load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + spec.scenario,
                     std::move(request), error);
  };
  std::unique_ptr<Mode> mode = make();
  if (!mode) {
    state.SkipWithError(error.c_str());
    return;
  }
  std::vector<double> step, feedback;
  double iterations = 0;
  for (auto _ : state) {
    if (!mode->step()) {
      state.PauseTiming();
      mode = make();
      state.ResumeTiming();
      if (!mode || !mode->step()) {
        state.SkipWithError("the flight cannot be restarted");
        break;
      }
    }
    const Telemetry& t = mode->telemetry();
    if (!t.solved) {  // the safe controller flew: no RTI step to time
      state.SetIterationTime(0.0);
      continue;
    }
    state.SetIterationTime(t.stats.total_us * 1e-6);
    step.push_back(t.stats.total_us);
    feedback.push_back(t.stats.qp_us);
    iterations += t.stats.qp_iterations;
  }
  const double n = double(step.size());
  const Percentiles ps = percentiles(step), pf = percentiles(feedback);
  report(state, "step_", ps);
  report(state, "feedback_", pf);
  state.counters["qp_iterations"] = n > 0 ? iterations / n : 0.0;
}

const bool registered = [] {
  for (const QpSetSpec& spec : qp_set_specs()) {
    benchmark::RegisterBenchmark((std::string("BM_QpSolve/") + spec.name).c_str(),
                                 [&spec](benchmark::State& s) { BM_QpSolveClosed(s, spec); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((std::string("BM_RtiStep/") + spec.name).c_str(),
                                 [&spec](benchmark::State& s) { BM_RtiStepClosed(s, spec); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
  }
  return true;
}();

}  // namespace
}  // namespace mixpilot::bench
