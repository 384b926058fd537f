// A video of a replay (`mixpilot replay REC --video OUT.mp4`): the novice's 30 s of mi_helix at
// 1280x720 and 30 fps, the whole command timed (the recording flown again, 900 frames rendered
// offscreen by Mesa, llvmpipe without a GPU, and encoded by ffmpeg in its own process); it must
// take less than the clip's own 30 s. BM_VideoFrame times what this process does per frame
// (the two UI passes, the rendering, the readback), the encoder aside.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "app/child_process.hpp"
#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

const fs::path& bench_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("mixpilot-bench-video-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// The novice's 30 s of mi_helix, recorded once; "" with `error` when it cannot be.
std::string recording(std::string& error) {
  static std::string path, why;
  if (!path.empty() || !why.empty()) {
    error = why;
    return path;
  }
  cli::FlyOptions o;
  o.scenario_path = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";
  o.pilot = "novice";
  o.history = "off";
  int status = 0;
  auto rig = cli::FlightRig::assemble(o, why, status);
  const std::string p = (bench_dir() / "novice30.mcap").string();
  if (rig && rig->record(p, "", {}, true, why)) {
    rig->start();
    while (rig->step()) {
    }
    if (rig->close(false).recorded == p) path = p;
  }
  if (path.empty() && why.empty()) why = "the recording was not written";
  error = why;
  return path;
}

void BM_VideoReplay(benchmark::State& state) {
  std::string error;
  const std::string rec = recording(error);
  if (rec.empty()) {
    state.SkipWithError(error.c_str());
    return;
  }
  const std::string out = (bench_dir() / "novice30.mp4").string();
  for (auto _ : state) {
    cli::ChildProcess mixpilot;
    if (!mixpilot.start(MIXPILOT_BINARY,
                        {"replay", rec, "--video", out, "--force", "--size", "1280x720", "--fps", "30"},
                        cli::ChildProcess::Input::none, error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    std::string said;
    while (mixpilot.read_error(said)) {
    }
    const cli::ChildExit e = mixpilot.wait();
    if (!e.ok()) {
      error = "mixpilot replay --video: " + cli::to_string(e) + ": " + said;
      state.SkipWithError(error.c_str());
      return;
    }
  }
  state.counters["frames"] = 900;
}
BENCHMARK(BM_VideoReplay)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_VideoFrame(benchmark::State& state) {
  std::string error;
  const std::string rec = recording(error);
  if (rec.empty()) {
    state.SkipWithError(error.c_str());
    return;
  }
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = rec;
  o.history = "off";
  cli::Trainer app(o);
  cli::Offscreen screen;
  if (!app.open_replay(rec, error) || !screen.open(1280, 720, error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  app.load_replay();
  std::vector<std::uint8_t> rgba;
  double t = 0.0;
  for (auto _ : state) {
    app.seek(t);
    screen.layout([&] { app.build_frame(0.0); });
    screen.frame([&] { app.build_frame(0.0); });
    screen.read_bottom_up(rgba);
    benchmark::DoNotOptimize(rgba.data());
    t = t + 1.0 / 30.0 < 29.9 ? t + 1.0 / 30.0 : 0.0;
  }
}
BENCHMARK(BM_VideoFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mixpilot
