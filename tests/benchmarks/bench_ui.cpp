// One full UI frame (SPEC §8): ImGui's draw data built from a flight's scene and history and
// rendered offscreen at 1280x720 by Mesa (llvmpipe when there is no GPU), glFinish included.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "app/offscreen.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"

namespace mixpilot {
namespace {

void BM_UiFrame(benchmark::State& state, const char* scenario, ui::Camera camera) {
  ModeRequest request;
  request.duration = 5.0;
  std::string error;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + scenario,
                        std::move(request), error);
  if (!mode) {
    state.SkipWithError(error.c_str());
    return;
  }
  ui::History history;
  struct Keep : TelemetrySink {
    ui::History* h;
    void on_sample(const Telemetry& s) override { h->push(s); }
  } keep;
  keep.h = &history;
  Session session(*mode);
  session.add_sink(&keep);
  session.run();
  cli::Offscreen screen;
  if (!screen.open(1280, 720, error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  const ui::Scene scene = ui::scene_of(*mode, "bench");
  ui::UiState st;
  st.camera = camera;
  ui::RunInfo run;
  run.state = ui::RunState::flying;
  ui::Requests requests;
  for (auto _ : state) {
    requests.clear();
    screen.frame([&] { ui::draw_screen(scene, history, run, st, requests); });
  }
}

BENCHMARK_CAPTURE(BM_UiFrame, mi_chase, "mi_helix.toml", ui::Camera::chase)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, mi_orbit, "mi_helix.toml", ui::Camera::orbit)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, pendubot, "pendubot_swingup.toml", ui::Camera::chase)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, obstacles, "obstacles_thrown_balls.toml", ui::Camera::chase)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mixpilot
