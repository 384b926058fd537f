#include "app/offscreen.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdio>

#include <epoxy/egl.h>  // EGL and GL entry points, both through libepoxy
#include <epoxy/gl.h>

#include <imgui.h>
#include <backends/imgui_impl_opengl3.h>

#include <stb/stb_image_write.h>  // implemented in Debian's libstb, which ImGui links

#include "ui/keys.hpp"
#include "ui/theme.hpp"

namespace mixpilot::cli {
namespace {

const char* const kInstall =
    " (headless rendering needs Mesa's EGL: apt-get install libegl1 libegl-mesa0 "
    "libgl1-mesa-dri)";

std::string egl_error(const char* what) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s failed (EGL error 0x%04x)", what, eglGetError());
  return buf;
}

}  // namespace

Offscreen::~Offscreen() { close(); }

bool Offscreen::open(int width, int height, std::string& error, float scale) {
  width_ = width;
  height_ = height;
  scale_ = scale;
  // libepoxy loads libEGL itself and aborts the process when it cannot: ask first.
  if (void* egl = dlopen("libEGL.so.1", RTLD_LAZY | RTLD_LOCAL)) {
    dlclose(egl);
  } else {
    error = std::string("cannot load libEGL.so.1 (") + dlerror() + ")" + kInstall;
    return false;
  }
  auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_display) {
    error = std::string("EGL has no eglGetPlatformDisplayEXT") + kInstall;
    return false;
  }
  EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor)) {
    error = egl_error("opening Mesa's surfaceless EGL display") + kInstall;
    return false;
  }
  display_ = dpy;
  if (!eglBindAPI(EGL_OPENGL_API)) {
    error = egl_error("eglBindAPI(OpenGL)") + kInstall;
    return false;
  }
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (ctx == EGL_NO_CONTEXT) {
    error = egl_error("creating an OpenGL 3.3 core context") + kInstall;
    return false;
  }
  context_ = ctx;
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
    error = egl_error("eglMakeCurrent") + kInstall;
    return false;
  }
  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glGenRenderbuffers(1, &colour_);
  glBindRenderbuffer(GL_RENDERBUFFER, colour_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    error = "the offscreen framebuffer of " + std::to_string(width) + "x" +
            std::to_string(height) + " is incomplete";
    return false;
  }
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  imgui_ = true;
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // nothing written behind the user's back
  // Keys by the UI's names (ui/keys.hpp), as the window maps them: keys injected into a
  // headless frame mean what they mean in the window.
  mixpilot::ui::use_key_names(io);
  io.DisplaySize = ImVec2(float(width), float(height));
  mixpilot::ui::apply_style(scale);
  font_ = mixpilot::ui::load_fonts(scale);
  if (!ImGui_ImplOpenGL3_Init("#version 330 core")) {
    error = "ImGui's OpenGL3 renderer did not start";
    return false;
  }
  return true;
}

void Offscreen::rescale(float scale) {
  scale_ = scale;
  mixpilot::ui::apply_style(scale);
  font_ = mixpilot::ui::load_fonts(scale);
  ImGui_ImplOpenGL3_DestroyFontsTexture();
  ImGui_ImplOpenGL3_CreateFontsTexture();
}

void Offscreen::frame(const std::function<void()>& build, float dt) {
  ImGuiIO& io = ImGui::GetIO();
  io.DeltaTime = dt;
  io.DisplaySize = ImVec2(float(width_), float(height_));
  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();
  build();
  ImGui::Render();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, width_, height_);
  {
    const ImVec4 c = ImGui::ColorConvertU32ToFloat4(ui::colour::kPane);
    glClearColor(c.x, c.y, c.z, 1.0f);
  }
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  glFinish();
}

void Offscreen::layout(const std::function<void()>& build, float dt) {
  ImGuiIO& io = ImGui::GetIO();
  io.DeltaTime = dt;
  io.DisplaySize = ImVec2(float(width_), float(height_));
  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();
  build();
  ImGui::EndFrame();
}

std::vector<std::uint8_t> Offscreen::pixels() const {
  const std::size_t row = std::size_t(width_) * 4;
  std::vector<std::uint8_t> bottom_up(row * std::size_t(height_)), out(bottom_up.size());
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  for (int y = 0; y < height_; ++y)
    std::copy_n(bottom_up.data() + row * std::size_t(height_ - 1 - y), row, out.data() + row * std::size_t(y));
  return out;
}

void Offscreen::read_bottom_up(std::vector<std::uint8_t>& rgba) const {
  rgba.resize(std::size_t(width_) * std::size_t(height_) * 4);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
}

std::string Offscreen::png() const {
  const auto px = pixels();
  std::string out;
  stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
      },
      &out, width_, height_, 4, px.data(), width_ * 4);
  return out;
}

void Offscreen::close() {
  if (imgui_) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui::DestroyContext();
    imgui_ = false;
  }
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (colour_) glDeleteRenderbuffers(1, &colour_);
  fbo_ = colour_ = 0;
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
  display_ = context_ = nullptr;
}

}  // namespace mixpilot::cli
