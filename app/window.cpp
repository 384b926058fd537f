#include "app/window.hpp"

#include <epoxy/gl.h>  // before GLFW: GL entry points through libepoxy
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>

#include "app/cli.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "ui/screen.hpp"
#include "ui/theme.hpp"

namespace mixpilot::cli {
namespace {

std::string glfw_error() {
  const char* what = nullptr;
  glfwGetError(&what);
  return what ? what : "unknown GLFW error";
}

// The window's current frame as PNG bytes (read before the swap).
std::string frame_png(int w, int h) {
  std::vector<unsigned char> px(std::size_t(w) * std::size_t(h) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
  stbi_flip_vertically_on_write(1);
  std::string out;
  stbi_write_png_to_func(
      [](void* c, void* d, int n) { static_cast<std::string*>(c)->append(static_cast<char*>(d), std::size_t(n)); },
      &out, w, h, 4, px.data(), w * 4);
  stbi_flip_vertically_on_write(0);
  return out;
}

}  // namespace

bool window_available(std::string& error) {
  if (!glfwInit()) {
    error = "cannot open a window (" + glfw_error() + "); use --headless";
    return false;
  }
  glfwTerminate();
  return true;
}

bool fly_window(Session& session, const ui::Scene& scene, const WindowOptions& o,
                WindowResult& result, std::string& error) {
  if (!glfwInit()) {
    error = "cannot open a window (" + glfw_error() + "); use --headless";
    return false;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, ("mixpilot — " + scene.title).c_str(),
                                        nullptr, nullptr);
  if (!window) {
    error = "cannot open an OpenGL 3.3 window (" + glfw_error() + "); use --headless";
    glfwTerminate();
    return false;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  float sx = 1.0f, sy = 1.0f;
  glfwGetWindowContentScale(window, &sx, &sy);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ui::apply_style(sx);
  ui::load_fonts(sx);
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  RealtimeRunner runner(session, 8192);
  ui::History history;
  ui::UiState ui_state;
  std::vector<bool> shot(o.screenshots.size(), false);
  bool started = false, ok = true;
  if (o.exit_at_end) {
    runner.start();
    started = true;
  }
  Telemetry sample = session.mode().telemetry();  // sized once; the ring copies into it
  Metrics metrics;
  while (!glfwWindowShouldClose(window) && !interrupted()) {  // ^C ends the flight as headless
    glfwPollEvents();
    while (runner.telemetry().pop(sample)) history.push(sample);
    const RealtimeStats st = runner.stats();
    ui::RunInfo run;
    run.speed = runner.speed();
    run.deadline_misses = st.deadline_misses;
    run.state = !started ? ui::RunState::ready
                : session.mode().lost() ? ui::RunState::lost
                : !runner.running() ? ui::RunState::finished
                : runner.paused() ? ui::RunState::paused
                                  : ui::RunState::flying;
    // The score card once the run is over (the runner's thread has ended: the mode is ours).
    if (started && !runner.running() && metrics.empty()) metrics = session.mode().metrics();
    run.metrics = metrics;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const ui::UiRequest req = ui::draw_screen(scene, history, run, ui_state);
    ImGui::Render();
    if (req.start && !started) {
      runner.start();
      started = true;
    }
    if (req.toggle_pause && started) runner.set_paused(!runner.paused());
    if (req.speed > 0) runner.set_speed(req.speed);
    int w = 0, h = 0;
    glfwGetFramebufferSize(window, &w, &h);
    glViewport(0, 0, w, h);
    glClearColor(0.086f, 0.098f, 0.118f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    for (std::size_t i = 0; i < shot.size(); ++i) {
      if (shot[i] || history.empty() || history.newest().t < o.screenshots[i].t) continue;
      shot[i] = true;
      std::string e;
      if (write_file(o.screenshots[i].path, frame_png(w, h), o.overwrite, e)) {
        result.screenshots.push_back(o.screenshots[i].path);
      } else if (ok) {
        ok = false;
        error = e;
      }
    }
    glfwSwapBuffers(window);
    if (o.exit_at_end && started && !runner.running() && history.size() > 0 &&
        history.newest().step + 1 >= session.mode().steps_done())
      break;
  }
  runner.stop();
  const RealtimeStats st = runner.stats();
  result.finished = session.mode().finished();
  result.deadline_misses = st.deadline_misses;
  result.worst_lateness_us = st.worst_lateness_us;
  result.worst_step_us = st.worst_step_us;
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return ok;
}

}  // namespace mixpilot::cli
