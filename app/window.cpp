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
#include <optional>

#include "app/cli.hpp"
#include "ui/keys.hpp"
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

// GLFW's key code as the UI names the key (ui/keys.hpp); nullopt for a key the UI has no name
// for (ImGui 1.86 reads none but those: text arrives as characters).
std::optional<ui::Key> ui_key(int key) {
  using ui::Key;
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return Key(int(Key::a) + (key - GLFW_KEY_A));
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return Key(int(Key::digit0) + (key - GLFW_KEY_0));
  if (key >= GLFW_KEY_F1 && key <= GLFW_KEY_F12) return Key(int(Key::f1) + (key - GLFW_KEY_F1));
  switch (key) {
    case GLFW_KEY_SPACE: return Key::space;
    case GLFW_KEY_ENTER: return Key::enter;
    case GLFW_KEY_KP_ENTER: return Key::keypad_enter;
    case GLFW_KEY_ESCAPE: return Key::escape;
    case GLFW_KEY_TAB: return Key::tab;
    case GLFW_KEY_BACKSPACE: return Key::backspace;
    case GLFW_KEY_INSERT: return Key::insert;
    case GLFW_KEY_DELETE: return Key::del;
    case GLFW_KEY_LEFT: return Key::left;
    case GLFW_KEY_RIGHT: return Key::right;
    case GLFW_KEY_UP: return Key::up;
    case GLFW_KEY_DOWN: return Key::down;
    case GLFW_KEY_PAGE_UP: return Key::page_up;
    case GLFW_KEY_PAGE_DOWN: return Key::page_down;
    case GLFW_KEY_HOME: return Key::home;
    case GLFW_KEY_END: return Key::end;
    case GLFW_KEY_LEFT_BRACKET: return Key::left_bracket;
    case GLFW_KEY_RIGHT_BRACKET: return Key::right_bracket;
    case GLFW_KEY_MINUS: return Key::minus;
    case GLFW_KEY_EQUAL: return Key::equal;
    case GLFW_KEY_KP_SUBTRACT: return Key::keypad_subtract;
    case GLFW_KEY_KP_ADD: return Key::keypad_add;
    case GLFW_KEY_KP_0: return Key::keypad_0;
    case GLFW_KEY_LEFT_SHIFT: return Key::left_shift;
    case GLFW_KEY_RIGHT_SHIFT: return Key::right_shift;
    case GLFW_KEY_LEFT_CONTROL: return Key::left_ctrl;
    case GLFW_KEY_RIGHT_CONTROL: return Key::right_ctrl;
    case GLFW_KEY_LEFT_ALT: return Key::left_alt;
    case GLFW_KEY_RIGHT_ALT: return Key::right_alt;
    case GLFW_KEY_LEFT_SUPER: return Key::left_super;
    case GLFW_KEY_RIGHT_SUPER: return Key::right_super;
    default: return std::nullopt;
  }
}

// In place of ImGui's GLFW key callback, which writes GLFW's key codes into io.KeysDown: the
// same, by the UI's key names (ImGui's other GLFW callbacks stay).
void key_callback(GLFWwindow*, int key, int, int action, int) {
  ImGuiIO& io = ImGui::GetIO();
  if (const std::optional<ui::Key> k = ui_key(key); k && action != GLFW_REPEAT)
    ui::set_key(io, *k, action == GLFW_PRESS);
  // As ImGui's callback: the modifiers from the keys held (GLFW's mods are not reliable
  // across systems).
  using ui::Key;
  const auto held = [&](Key l, Key r) { return io.KeysDown[int(l)] || io.KeysDown[int(r)]; };
  io.KeyCtrl = held(Key::left_ctrl, Key::right_ctrl);
  io.KeyShift = held(Key::left_shift, Key::right_shift);
  io.KeyAlt = held(Key::left_alt, Key::right_alt);
  io.KeySuper = held(Key::left_super, Key::right_super);
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
  WindowContent c;
  c.build_frame = [&app](double dt) { app.build_frame(dt); };
  c.shown_time = [&app] { return app.shown_time(); };
  c.start = [&app] { app.start(); };
  c.over = [&app] { return app.over(); };
  c.text_scale = [&app] { return app.text_scale(); };
  return run_window(c, o, written, error);
}

bool run_window(const WindowContent& app, const WindowOptions& o,
                std::vector<std::string>& written, std::string& error) {
  if (!glfwInit()) {
    error = "cannot open a window (" + glfw_error() + "); use --headless";
    return false;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
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
  // The UI's scale: the display's (or --scale) times the user's text size, followed as either
  // changes (the window moved to another display, the text size set).
  const auto wanted_scale = [&] {
    return (o.scale > 0 ? o.scale : ui_scale(window)) * (app.text_scale ? app.text_scale() : 1.0f);
  };
  float scale = wanted_scale();
  ui::apply_style(scale);
  ui::load_fonts(scale);
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  glfwSetKeyCallback(window, key_callback);  // ImGui's backend kept no callback of ours to chain
  ui::use_key_names(ImGui::GetIO());
  ImGui_ImplOpenGL3_Init("#version 330 core");

  std::vector<bool> shot(o.screenshots.size(), false);
  bool ok = true;
  if (o.exit_at_end && app.start) app.start();
  auto last = std::chrono::steady_clock::now();
  std::string title;
  while (!glfwWindowShouldClose(window) && !interrupted()) {  // ^C ends the flight as headless
    glfwPollEvents();
    if (const float want = wanted_scale(); std::abs(want - scale) > 1e-3f) {
      // Fonts are rebuilt between frames, never within one.
      scale = want;
      ui::apply_style(scale);
      ui::load_fonts(scale);
      ImGui_ImplOpenGL3_DestroyFontsTexture();
      ImGui_ImplOpenGL3_CreateFontsTexture();
    }
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
    const double shown = app.shown_time ? app.shown_time() : -1.0;
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
    if (o.exit_at_end && app.over && app.over()) break;
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return ok;
}

}  // namespace mixpilot::cli
