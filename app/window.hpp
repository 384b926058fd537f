#pragma once
// `mixpilot fly` in a window (SPEC §8): GLFW 3.3, OpenGL 3.3 core, ImGui's GLFW and OpenGL3
// backends. The session runs on the real-time runner's thread (core/runtime/); this thread
// drains its telemetry into the UI's history and draws the newest state at the display's rate.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/screenshot.hpp"
#include "core/modes/session.hpp"
#include "ui/scene.hpp"

namespace mixpilot::cli {

struct WindowOptions {
  int width = 1280, height = 720;
  bool exit_at_end = false;  // start at once and close the window when the run is over
  std::vector<ScreenshotRequest> screenshots;  // the window's frame when t first reaches T
  bool overwrite = false;
};

struct WindowResult {
  bool finished = false;  // the run reached its end (not closed early)
  std::int64_t deadline_misses = 0;
  double worst_lateness_us = 0.0, worst_step_us = 0.0;
  std::vector<std::string> screenshots;  // written
};

// Whether a window can be opened here (a display and GLFW); false with the reason.
[[nodiscard]] bool window_available(std::string& error);

// Flies `session` in a window until the run ends (with exit_at_end) or the window is closed.
// False with the reason when no window can be opened (no display) or a screenshot fails.
[[nodiscard]] bool fly_window(Session& session, const ui::Scene& scene, const WindowOptions& o,
                              WindowResult& result, std::string& error);

}  // namespace mixpilot::cli
