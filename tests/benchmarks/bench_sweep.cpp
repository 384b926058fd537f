// A sweep of 40 runs (`mixpilot sweep`, docs/sweeps.md) on one job and on two: the whole
// command timed (start, every run checked, 40 flights, the merge), into a fresh folder each
// time. The runs are the tracking smooth step (8 s, SPEC §5.2) at 20 round-trip times with the
// predictor and horizons of 30 and 50: alike in length, none lost. Two independent flights on
// two cores should take little more than half the time of one after the other:
//   mixpilot-bench --benchmark_filter=BM_Sweep40 --benchmark_repetitions=3
// and compare the medians (jobs:2 against jobs:1).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/child_process.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

const fs::path& bench_dir() {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / ("mixpilot-bench-sweep-" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::string rtts;
    for (int i = 0; i < 20; ++i) rtts += (i ? ", " : "") + std::to_string(0.003 * i);
    std::ofstream(d / "sweep40.toml")
        << "scenario = \"" << MIXPILOT_SOURCE_DIR << "/scenarios/tracking_smooth_step.toml\"\n"
        << "[grid]\n\"plant.rtt\" = [" << rtts << "]\n\"controller.N\" = [30, 50]\n";
    return d;
  }();
  return dir;
}

void BM_Sweep40(benchmark::State& state) {
  const fs::path dir = bench_dir();
  const std::string jobs = std::to_string(state.range(0));
  const fs::path out = dir / ("jobs" + jobs);
  for (auto _ : state) {
    state.PauseTiming();
    std::error_code ec;
    fs::remove_all(out, ec);
    state.ResumeTiming();
    cli::ChildProcess mixpilot;
    std::string error;
    if (!mixpilot.start(MIXPILOT_BINARY,
                        {"sweep", (dir / "sweep40.toml").string(), "--out", out.string(), "--jobs",
                         jobs},
                        cli::ChildProcess::Input::none, error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    std::string said;
    while (mixpilot.read_error(said)) {
    }
    const cli::ChildExit e = mixpilot.wait();
    if (!e.ok()) {
      error = "mixpilot sweep: " + cli::to_string(e) + ": " + said.substr(0, 400);
      state.SkipWithError(error.c_str());
      return;
    }
  }
  state.counters["runs"] = 40;
}
BENCHMARK(BM_Sweep40)->ArgName("jobs")->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace mixpilot
