#pragma once
// The window (SPEC §8): GLFW 3.3, OpenGL 3.3 core, ImGui's GLFW and OpenGL3 backends, drawing
// the app (app/trainer.hpp) at the display's rate. The live flight runs on the real-time
// runner's thread; this thread only draws and acts on the user's requests.
#include <functional>
#include <string>
#include <vector>

#include "app/screenshot.hpp"
#include "app/trainer.hpp"

namespace mixpilot::cli {

struct WindowOptions {
  int width = 1280, height = 720;
  bool exit_at_end = false;  // start at once and close the window when the run is over
  std::vector<ScreenshotRequest> screenshots;  // the window's frame when the shown time reaches T
  bool overwrite = false;
  float scale = 0.0f;  // the UI's display scale (0: the window's content scale)
  std::string title = "mixpilot";
};

// What a window shows, frame by frame: the app's trainer, or the instructor's window.
struct WindowContent {
  std::function<void(double wall_dt)> build_frame;  // between NewFrame() and Render()
  std::function<double()> shown_time;  // [s] what the screenshots' times are measured against
  std::function<void()> start;         // exit_at_end: at once
  std::function<bool()> over;          // exit_at_end: close once true
  // The user's text size, a factor on the display's scale (nullptr: 1).
  std::function<float()> text_scale;
};

// Whether a window can be opened here (a display and GLFW); false with the reason.
[[nodiscard]] bool window_available(std::string& error);

// Shows `app` in a window until it is closed (or, with exit_at_end, the run is over). False with
// the reason when no window can be opened or a screenshot fails; `screenshots` lists those
// written.
[[nodiscard]] bool run_window(Trainer& app, const WindowOptions& o,
                              std::vector<std::string>& screenshots, std::string& error);
[[nodiscard]] bool run_window(const WindowContent& content, const WindowOptions& o,
                              std::vector<std::string>& screenshots, std::string& error);

}  // namespace mixpilot::cli
