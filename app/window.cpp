#include "app/window.hpp"

#include <epoxy/gl.h>  // before GLFW: GL entry points through libepoxy
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "app/cli.hpp"
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

// The UI's scale on this window's display. ImGui lays out in window coordinates: where the
// desktop scales the framebuffer itself (Wayland, macOS: a 2x framebuffer behind a 1280x720
// window) that part of the content scale is already done; where it does not (X11: Xft.dpi),
// the fonts and sizes carry all of it.
float ui_scale(GLFWwindow* window) {
  float sx = 1.0f, sy = 1.0f;
  glfwGetWindowContentScale(window, &sx, &sy);
  int ww = 0, wh = 0, fw = 0, fh = 0;
  glfwGetWindowSize(window, &ww, &wh);
  glfwGetFramebufferSize(window, &fw, &fh);
  const float framebuffer = ww > 0 && fw > 0 ? float(fw) / float(ww) : 1.0f;
  const float s = sx / std::max(framebuffer, 1.0f);
  return std::isfinite(s) && s > 0.0f ? std::clamp(s, 0.5f, 4.0f) : 1.0f;
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

bool run_window(Trainer& app, const WindowOptions& o, std::vector<std::string>& written,
                std::string& error) {
  if (!glfwInit()) {
    error = "cannot open a window (" + glfw_error() + "); use --headless";
    return false;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, "mixpilot", nullptr, nullptr);
  if (!window) {
    error = "cannot open an OpenGL 3.3 window (" + glfw_error() + "); use --headless";
    glfwTerminate();
    return false;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  const float scale = o.scale > 0 ? o.scale : ui_scale(window);
  ui::apply_style(scale);
  ui::load_fonts(scale);
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  std::vector<bool> shot(o.screenshots.size(), false);
  bool ok = true;
  if (o.exit_at_end) app.start();
  auto last = std::chrono::steady_clock::now();
  std::string title;
  while (!glfwWindowShouldClose(window) && !interrupted()) {  // ^C ends the flight as headless
    glfwPollEvents();
    const auto now = std::chrono::steady_clock::now();
    const double wall_dt = std::chrono::duration<double>(now - last).count();
    last = now;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    app.build_frame(wall_dt);
    ImGui::Render();
    int w = 0, h = 0;
    glfwGetFramebufferSize(window, &w, &h);
    glViewport(0, 0, w, h);
    {
      const ImVec4 c = ImGui::ColorConvertU32ToFloat4(ui::colour::kPane);
      glClearColor(c.x, c.y, c.z, 1.0f);
    }
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    const double shown = app.shown_time();
    for (std::size_t i = 0; i < shot.size(); ++i) {
      if (shot[i] || shown < o.screenshots[i].t) continue;
      shot[i] = true;
      std::string e;
      if (write_file(o.screenshots[i].path, frame_png(w, h), o.overwrite, e)) {
        written.push_back(o.screenshots[i].path);
      } else if (ok) {
        ok = false;
        error = e;
      }
    }
    glfwSwapBuffers(window);
    if (o.exit_at_end && app.over()) break;
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return ok;
}

}  // namespace mixpilot::cli
