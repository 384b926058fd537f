#pragma once
// A fixture that drives the app's window code headless, as a user would: frames rendered
// offscreen (EGL), keys by the UI's names as the window passes them, the mouse moved until ImGui
// hovers an item, clicks, and frames until a live flight is over.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "ui/keys.hpp"

namespace mixpilot::test {

class AppWindowTest : public testing::Test {
 protected:
  // One frame; its build time [s] (what the UI thread spent on it). ImGui needs a positive frame
  // time; the app's playhead moves by `dt` alone.
  double frame(cli::Trainer& app, double dt = 1.0 / 60.0) {
    const auto t0 = std::chrono::steady_clock::now();
    screen_.frame([&] { app.build_frame(dt); }, std::max(float(dt), 1e-4f));
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  // A key held for one frame, then released.
  void key(cli::Trainer& app, ui::Key k, bool ctrl = false) {
    ImGuiIO& io = ImGui::GetIO();
    io.KeyCtrl = ctrl;
    ui::set_key(io, k, true);
    frame(app, 0.0);
    ui::set_key(io, k, false);
    io.KeyCtrl = false;
    frame(app, 0.0);
  }
  // Where the item `label` of `window` lies: the mouse moves over the window until ImGui says
  // it hovers that item (layout-only frames, nothing rendered).
  std::optional<ImVec2> locate(cli::Trainer& app, const char* window, const char* label) {
    frame(app, 0.0);
    ImGuiWindow* w = ImGui::FindWindowByName(window);
    if (!w) return std::nullopt;
    const ImGuiID id = w->GetID(label);
    const ImRect r = w->Rect();
    for (float y = r.Min.y + 2; y < r.Max.y; y += 5) {
      for (float x = r.Min.x + 2; x < r.Max.x; x += 10) {
        ImGui::GetIO().MousePos = ImVec2(x, y);
        screen_.layout([&] { app.build_frame(0.0); }, 1e-4f);
        if (GImGui->HoveredId == id) return ImVec2(x, y);
      }
    }
    return std::nullopt;
  }
  void click(cli::Trainer& app, ImVec2 at) {
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = at;
    frame(app, 0.0);
    io.MouseDown[0] = true;
    frame(app, 0.0);
    io.MouseDown[0] = false;
    frame(app, 0.0);
    io.MousePos = ImVec2(-1, -1);
  }
  // Frames until `done` (what the app loads or flies off the UI thread), at most `limit`;
  // whether it came.
  template <class Done>
  bool frames_until(cli::Trainer& app, Done done,
                    std::chrono::seconds limit = std::chrono::seconds(20)) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (!done() && std::chrono::steady_clock::now() < deadline) {
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return done();
  }
  // Frames until the live flight's run is over (real time), at most `limit`.
  void until_over(cli::Trainer& app, std::chrono::seconds limit = std::chrono::seconds(60)) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (!app.over() && std::chrono::steady_clock::now() < deadline) {
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  cli::Offscreen screen_;
};

}  // namespace mixpilot::test
