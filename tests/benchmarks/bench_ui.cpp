// One full UI frame (SPEC §8): ImGui's draw data built from a flight's scene and history and
// rendered offscreen at 1280x720 by Mesa (llvmpipe when there is no GPU), glFinish included.
// The `_build` cases time only what the UI thread does before the GPU draws: the panels laid out
// and their vertices built (ImGui::Render's draw data), without rasterizing it. Without a GPU,
// llvmpipe's rasterizing is the CPU doing the GPU's work, and grows with the pixels covered.
#include <benchmark/benchmark.h>
#include <imgui.h>

#include <memory>
#include <string>

#include "app/offscreen.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"

namespace mixpilot {
namespace {

// A trainee's 50 flights of a scenario, as the Progress panel shows them.
ui::HistoryView progress_of_50() {
  ui::HistoryView v;
  v.loaded = true;
  v.trainees = {"Ada", "Bo", "Zoë"};
  ui::ProgressView& p = v.progress;
  p.trainee = "Ada";
  p.scenario = "mi_helix";
  for (int i = 0; i < 50; ++i) {
    ui::ProgressFlight f;
    f.attempt = i + 1;
    f.probe = i % 5 == 4;
    f.skill = 30.0 + i + (i % 3) * 4.0 - (f.probe ? 15.0 : 0.0);
    f.dependence = f.probe ? ui::kNoValue : 0.7 - 0.01 * i;
    f.duration_s = 30.0;
    f.when = "2024-05-01 14:03";
    f.ended = "completed";
    f.recording = "/home/ada/.local/share/mixpilot/recordings/mi_helix-2024.mcap";
    (f.probe ? p.probes : p.assisted)++;
    p.flights.push_back(f);
  }
  p.best = 47;
  p.has_dependence = true;
  p.assisted_trend = {10, 1.1, "rising: +1.1 skill per attempt over the last 10 assisted flights"};
  p.probe_trend = {10, 1.0, "rising: +1.0 skill per attempt over the last 10 probe flights"};
  return v;
}

enum class Draw { rendered, built };

// `progress`: the Progress panel open over the flight (the same frame otherwise).
void BM_UiFrame(benchmark::State& state, const char* scenario, ui::Camera camera, bool progress,
                Draw draw = Draw::rendered) {
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
  const ui::HistoryView view = progress_of_50();
  if (progress) {
    run.history = &view;
    st.show_progress = true;
  }
  ui::Requests requests;
  const auto build = [&] { ui::draw_screen(scene, history, run, st, requests); };
  for (auto _ : state) {
    requests.clear();
    if (draw == Draw::rendered) {
      screen.frame(build);
    } else {
      screen.layout(build);
      ImGui::Render();  // the draw data, as the window hands it to the GPU
      benchmark::DoNotOptimize(ImGui::GetDrawData()->TotalVtxCount);
    }
  }
  state.counters["vertices"] = ImGui::GetDrawData()->TotalVtxCount;
}

BENCHMARK_CAPTURE(BM_UiFrame, mi_chase, "mi_helix.toml", ui::Camera::chase, false)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, mi_orbit, "mi_helix.toml", ui::Camera::orbit, false)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, pendubot, "pendubot_swingup.toml", ui::Camera::chase, false)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, obstacles, "obstacles_thrown_balls.toml", ui::Camera::chase, false)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, mi_chase_progress, "mi_helix.toml", ui::Camera::chase, true)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, mi_chase_build, "mi_helix.toml", ui::Camera::chase, false,
                  Draw::built)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_UiFrame, mi_chase_progress_build, "mi_helix.toml", ui::Camera::chase, true,
                  Draw::built)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mixpilot
