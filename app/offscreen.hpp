#pragma once
// Rendering without a window (SPEC §8 "Headless"): an OpenGL 3.3 core context on EGL's Mesa
// surfaceless platform, a framebuffer object of the requested size, and Dear ImGui with its
// OpenGL3 renderer, so the UI code draws exactly what the window would show.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mixpilot::cli {

class Offscreen {
 public:
  Offscreen() = default;
  Offscreen(const Offscreen&) = delete;
  Offscreen& operator=(const Offscreen&) = delete;
  ~Offscreen();

  // Creates the context, the framebuffer and ImGui (style and fonts of ui/theme.hpp) at the
  // display scale `scale` (1: 100 %, 1.5: 150 %): what the window shows on such a display.
  // False with the reason (no EGL device, no OpenGL 3.3) and what to install.
  [[nodiscard]] bool open(int width, int height, std::string& error, float scale = 1.0f);

  // The UI at another display scale from the next frame on: style and fonts made again.
  void rescale(float scale);

  // Renders one ImGui frame: `build` runs between ImGui::NewFrame() and ImGui::Render().
  // `dt` is the frame's time step for ImGui [s].
  void frame(const std::function<void()>& build, float dt = 1.0f / 60.0f);

  // One frame's layout and input only, nothing rendered: cheap, for tests that look for what
  // lies under the mouse.
  void layout(const std::function<void()>& build, float dt = 1.0f / 60.0f);

  // The last frame, RGBA, top row first: width × height × 4 bytes.
  std::vector<std::uint8_t> pixels() const;
  // The last frame, RGBA, bottom row first (as OpenGL reads it), into `rgba` (resized; its
  // capacity kept from frame to frame): no copy beyond the read, for a video.
  void read_bottom_up(std::vector<std::uint8_t>& rgba) const;
  // The last frame as a PNG file's bytes.
  std::string png() const;

  int width() const { return width_; }
  int height() const { return height_; }
  float scale() const { return scale_; }
  const std::string& font() const { return font_; }

 private:
  void close();

  int width_ = 0, height_ = 0;
  float scale_ = 1.0f;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  unsigned fbo_ = 0, colour_ = 0;
  bool imgui_ = false;
  std::string font_;  // the font file loaded, "" for ImGui's built-in
};

}  // namespace mixpilot::cli
