// The app (app/trainer.hpp) through the headless renderer, used as a person would: clicks and
// keys reach it; the live flight starts, pauses and restarts; a recording of every mode replays
// with a timeline to scrub, speeds and jumps to its events; and the arena draws the vehicle and
// its λ-coloured trail where the telemetry says.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <imgui.h>
#include <imgui_internal.h>

#include "app/flight.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "ui/panels.hpp"
#include "ui/theme.hpp"

#include "temp_files.hpp"

namespace mixpilot {
namespace {

constexpr int kW = 1280, kH = 720;

std::string scenario(const char* name) {
  return std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + name;
}

cli::FlyOptions live_options(const char* name, double seconds, const char* pilot = "novice") {
  cli::FlyOptions o;
  o.scenario_path = scenario(name);
  o.pilot = pilot;
  o.duration = seconds;
  return o;
}

// A recording of `name` flown headless for `seconds`.
std::string record(const char* name, double seconds, const char* pilot, const std::string& file) {
  cli::FlyOptions o = live_options(name, seconds, pilot);
  std::string error;
  int status = 0;
  auto f = cli::prepare_flight(o, error, status);
  EXPECT_TRUE(f) << error;
  const std::string path = test::fresh_path("app", file).string();
  RecordingSink rec;
  EXPECT_TRUE(rec.open(path, *f->mode, cli::session_info(*f), error)) << error;
  Session session(*f->mode);
  session.add_sink(&rec);
  session.run();
  EXPECT_TRUE(rec.close(error)) << error;
  return path;
}

struct Rgb {
  int r, g, b;
};
Rgb rgb_of(ImU32 c) { return {int(c & 0xFF), int((c >> 8) & 0xFF), int((c >> 16) & 0xFF)}; }

class App : public testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    if (!screen_.open(kW, kH, error)) GTEST_SKIP() << "no EGL device: " << error;
  }

  void frame(cli::Trainer& app, double dt = 1.0 / 60.0) {
    // ImGui needs a positive frame time; the app's playhead moves by `dt` alone.
    screen_.frame([&] { app.build_frame(dt); }, std::max(float(dt), 1e-4f));
  }
  // A key held for one frame, then released (ImGui's key indices are GLFW's key codes).
  void key(cli::Trainer& app, int k, bool ctrl = false) {
    ImGuiIO& io = ImGui::GetIO();
    io.KeyCtrl = ctrl;
    io.KeysDown[k] = true;
    frame(app, 0.0);
    io.KeysDown[k] = false;
    io.KeyCtrl = false;
    frame(app, 0.0);
  }
  void key(cli::Trainer& app, ImGuiKey_ k) { key(app, ImGui::GetIO().KeyMap[k]); }
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
  const std::uint8_t* px(const std::vector<std::uint8_t>& p, int x, int y) {
    return &p[(std::size_t(y) * kW + std::size_t(x)) * 4];
  }
  // Whether a pixel within `radius` of `at` has colour `c` (to `tol` per channel).
  bool colour_near(const std::vector<std::uint8_t>& p, ImVec2 at, Rgb c, int radius, int tol) {
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const int x = int(at.x) + dx, y = int(at.y) + dy;
        if (x < 0 || y < 0 || x >= kW || y >= kH) continue;
        const std::uint8_t* q = px(p, x, y);
        if (std::abs(q[0] - c.r) <= tol && std::abs(q[1] - c.g) <= tol && std::abs(q[2] - c.b) <= tol)
          return true;
      }
    return false;
  }
  // Frames until the live flight's run is over (real time: a few seconds at most).
  void until_over(cli::Trainer& app) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!app.over() && std::chrono::steady_clock::now() < deadline) {
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  cli::Offscreen screen_;
};

// Saves the last frame as NAME.png in $MIXPILOT_SHOT_DIR when it is set (to look at the app's
// states that no command line reaches).
void save_shot(const cli::Offscreen& screen, const std::string& name) {
  const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
  if (!dir || !*dir) return;
  std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen.png();
}

// A newcomer's first flight: one click on the session panel's Start, then Space pauses and
// resumes it.
TEST_F(App, ClickStartThenSpacePausesAndResumes) {
  cli::Trainer app(live_options("mi_helix.toml", 3.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  frame(app);
  EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  save_shot(screen_, "ready");
  const auto start = locate(app, "Session", "Start flight (Space)");
  ASSERT_TRUE(start) << "no Start button in the session panel";
  click(app, *start);
  ASSERT_TRUE(app.live()->started);
  frame(app);
  EXPECT_EQ(app.run_info().state, ui::RunState::flying);
  key(app, ImGuiKey_Space);
  EXPECT_TRUE(app.live()->runner->paused());
  EXPECT_EQ(app.run_info().state, ui::RunState::paused);
  key(app, ImGuiKey_Space);
  EXPECT_FALSE(app.live()->runner->paused());
  until_over(app);
  EXPECT_EQ(app.run_info().state, ui::RunState::finished);
  EXPECT_FALSE(app.run_info().metrics.empty()) << "no score card at the end";
  frame(app);
  save_shot(screen_, "finished");
}

// R flies the same scenario again from its start: a new flight, the old one's telemetry gone.
TEST_F(App, RestartFliesANewFlight) {
  cli::Trainer app(live_options("mi_helix.toml", 2.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  frame(app);
  const cli::LiveFlight* first = app.live();
  ASSERT_GT(app.shown_time(), 0.2);
  key(app, 'R');
  EXPECT_NE(app.live(), first);
  EXPECT_TRUE(app.live()->started);
  EXPECT_LT(app.shown_time(), 0.2);
}

// Choosing another scenario in the panel makes the next flight of it (not started).
TEST_F(App, TheSessionPanelPicksTheScenario) {
  cli::Trainer app(live_options("mi_helix.toml", 2.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  const ui::SessionChoices& c = *app.run_info().session;
  const auto it = std::find(c.scenarios.begin(), c.scenarios.end(), "pendubot_swingup");
  ASSERT_NE(it, c.scenarios.end());
  ASSERT_NE(std::find(c.pilots.begin(), c.pilots.end(), "experienced"), c.pilots.end());
  EXPECT_EQ(c.pilots[std::size_t(c.pilot)], "novice");
  // The request a pick in the combo makes, acted on by the app.
  ui::UiRequest pick;
  pick.scenario = int(it - c.scenarios.begin());
  app.act(pick);
  frame(app);
  EXPECT_EQ(app.live()->flight.mode->kind(), ModeKind::pendubot_swingup);
  EXPECT_FALSE(app.live()->started);
  EXPECT_TRUE(app.run_info().session->pilots.empty()) << "the Pendubot mode has no pilot";
}

// A replay: ] jumps to the next event, Home / End, a click on the timeline seeks there, ↑ speeds
// up, and playing advances the playhead by the wall time times the speed.
TEST_F(App, ReplayTimelineSeeksJumpsAndPlays) {
  const std::string rec = record("mi_helix.toml", 8.0, "reckless", "reckless.mcap");
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = rec;
  cli::Trainer app(o);
  std::string error;
  ASSERT_TRUE(app.open_replay(rec, error)) << error;
  app.load_replay();
  frame(app);
  EXPECT_EQ(app.run_info().state, ui::RunState::replay);
  ASSERT_TRUE(app.run_info().replay);
  const ui::ReplayInfo& r = *app.run_info().replay;
  ASSERT_FALSE(r.events.empty()) << "the reckless pilot's takeover is no event";
  EXPECT_EQ(app.replay()->mismatch(), "");
  key(app, ']');
  EXPECT_DOUBLE_EQ(r.t, r.events.front().t);
  key(app, ImGuiKey_End);
  EXPECT_NEAR(r.t, r.duration - app.replay()->dt(), 1e-9);
  key(app, '[');
  EXPECT_DOUBLE_EQ(r.t, r.events.back().t);
  key(app, ImGuiKey_Home);
  EXPECT_EQ(r.t, 0.0);
  // The timeline spans the transport bar's width: its middle is the recording's middle.
  ImGuiWindow* bar = ImGui::FindWindowByName("##transport");
  ASSERT_TRUE(bar);
  const ImVec2 mid(0.5f * (bar->InnerRect.Min.x + bar->InnerRect.Max.x), bar->InnerRect.Min.y + 12);
  click(app, mid);
  EXPECT_NEAR(r.t, 0.5 * r.duration, 0.02 * r.duration);
  key(app, ImGuiKey_UpArrow);
  EXPECT_EQ(app.run_info().speed, 2.0);
  key(app, ImGuiKey_Space);
  ASSERT_TRUE(r.playing);
  const double before = r.t;
  frame(app, 0.5);
  EXPECT_NEAR(r.t - before, 1.0, 1e-9) << "0.5 s of wall time at 2x";
  // The frame shows the step under the playhead.
  EXPECT_NEAR(app.shown_time(), r.t, 1e-9);
}

// A recording of every mode replays in the app, bit for bit, and draws.
TEST_F(App, EveryModeReplays) {
  for (const char* name : {"mi_helix.toml", "pendubot_swingup.toml", "tracking_helix.toml",
                           "obstacles_thrown_balls.toml"}) {
    const bool mi = std::string(name).starts_with("mi_");
    const std::string rec = record(name, 1.5, mi ? "novice" : "", std::string(name) + ".mcap");
    cli::FlyOptions o;
    o.replay = true;
    o.pilot = rec;
    cli::Trainer app(o);
    std::string error;
    ASSERT_TRUE(app.open_replay(rec, error)) << name << ": " << error;
    app.load_replay();
    EXPECT_EQ(app.replay()->mismatch(), "") << name;
    app.seek(1.0);
    frame(app);
    frame(app);
    EXPECT_NEAR(app.shown_time(), 1.0, app.replay()->dt()) << name;
    EXPECT_EQ(app.run_info().state, ui::RunState::replay) << name;
  }
}

// Where the telemetry puts the vehicle, the arena draws it: its centre dot and its nose, seen
// from the top camera.
TEST_F(App, TheVehicleIsDrawnWhereItsPositionProjects) {
  cli::Trainer app(live_options("mi_helix.toml", 3.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.start();
  until_over(app);
  app.ui_state().camera = ui::Camera::top;
  app.ui_state().score_card_closed = true;
  app.ui_state().show_sticks = false;
  frame(app);
  frame(app);
  const auto pixels = screen_.pixels();
  const Telemetry& s = app.live()->history.newest();
  ImVec2 vmin, vmax;
  ui::view_rect(ImVec2(kW, kH), app.run_info(), vmin, vmax);
  const auto project = [&](const Eigen::Vector3d& p) {
    ImVec2 at;
    EXPECT_TRUE(ui::project_in_arena(app.live()->scene, s, app.ui_state(), vmin, vmax, p, at));
    return at;
  };
  const Eigen::Vector3d p = s.x.head<3>();
  const ImVec2 centre = project(p);
  EXPECT_TRUE(colour_near(pixels, centre, rgb_of(ui::colour::kText), 2, 12))
      << "no vehicle at (" << centre.x << ", " << centre.y << ")";
  // The nose: along the body x axis, in the critical colour; nothing of it half a metre away.
  // The MikroKopter's attitude: ZYX Euler angles γ = (φ, θ, ψ) (SPEC §2).
  ASSERT_EQ(s.x.size(), 16);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(s.x(5), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(s.x(4), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(s.x(3), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const ImVec2 nose = project(p + R * Eigen::Vector3d(0.3, 0, 0));
  EXPECT_TRUE(colour_near(pixels, nose, rgb_of(ui::colour::kCritical), 2, 12));
  const ImVec2 away = project(p + R * Eigen::Vector3d(-0.6, 0, 0));
  EXPECT_FALSE(colour_near(pixels, away, rgb_of(ui::colour::kCritical), 2, 12));
}

// The trail is coloured by the authority of each step: where λ says pilot, the pilot's colour;
// where it says planner, the planner's.
TEST_F(App, TheTrailShowsWhoHadAuthority) {
  cli::Trainer app(live_options("mi_helix.toml", 5.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.start();
  until_over(app);
  app.ui_state().camera = ui::Camera::top;
  app.ui_state().score_card_closed = true;
  app.ui_state().show_sticks = false;
  frame(app);
  frame(app);
  const auto pixels = screen_.pixels();
  const ui::History& h = app.live()->history;
  ImVec2 vmin, vmax;
  ui::view_rect(ImVec2(kW, kH), app.run_info(), vmin, vmax);
  int samples = 0, right = 0, wrong = 0;
  for (std::size_t i = h.first_at_or_after(h.newest().t - 5.5) + 1; i + 30 < h.size(); i += 3) {
    const double lambda = h[i].lambda;
    if (std::abs(lambda - 0.5) < 0.25) continue;  // colours too close to tell apart
    ImVec2 at;
    const Eigen::Vector3d mid = 0.5 * (h[i - 1].x.head<3>() + h[i].x.head<3>());
    if (!ui::project_in_arena(app.live()->scene, h.newest(), app.ui_state(), vmin, vmax, mid, at))
      continue;
    if (at.x < vmin.x + 5 || at.y < vmin.y + 120 || at.x > vmax.x - 5 || at.y > vmax.y - 5) continue;
    ++samples;
    right += colour_near(pixels, at, rgb_of(ui::authority_colour(lambda)), 1, 16) ? 1 : 0;
    wrong += colour_near(pixels, at, rgb_of(ui::authority_colour(1.0 - lambda)), 1, 16) ? 1 : 0;
  }
  ASSERT_GE(samples, 20);
  EXPECT_GE(right, int(0.8 * samples)) << right << " of " << samples;
  EXPECT_LE(wrong, int(0.1 * samples)) << wrong << " of " << samples;
}

// F1 opens the shortcut sheet; Ctrl+O the file browser.
TEST_F(App, HelpAndOpenDialogFromTheKeyboard) {
  cli::Trainer app(live_options("mi_helix.toml", 1.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  key(app, ui::kKeyF1);
  EXPECT_TRUE(app.ui_state().show_help);
  frame(app);
  save_shot(screen_, "help");
  const ImGuiWindow* sheet = ImGui::FindWindowByName("Keyboard and mouse (F1)");
  EXPECT_TRUE(sheet && sheet->Active);
  key(app, ImGuiKey_Escape);
  EXPECT_FALSE(app.ui_state().show_help);
  key(app, 'O', true);
  EXPECT_TRUE(app.ui_state().open_dialog.open);
  EXPECT_FALSE(app.ui_state().open_dialog.entries.empty());
  frame(app);  // a popup shows from its second frame
  const ImGuiWindow* browser = ImGui::FindWindowByName("Open a scenario or a recording");
  EXPECT_TRUE(browser && browser->Active);
  save_shot(screen_, "open_dialog");
}

}  // namespace
}  // namespace mixpilot
