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
#include <SDL2/SDL.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/offscreen.hpp"
#include "core/recording/replay.hpp"
#include "app/trainer.hpp"
#include "core/history/history.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "input/keyboard.hpp"
#include "input/virtual_gamepad.hpp"
#include "input/mapping.hpp"
#include "models/mikrokopter.hpp"
#include "ui/panels.hpp"
#include "ui/theme.hpp"

#include "app_window_test.hpp"
#include "record_flight.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

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
  const std::string path = test::fresh_path("app", file).string();
  EXPECT_TRUE(test::record_flight(live_options(name, seconds, pilot), path));
  return path;
}

struct Rgb {
  int r, g, b;
};
Rgb rgb_of(ImU32 c) { return {int(c & 0xFF), int((c >> 8) & 0xFF), int((c >> 16) & 0xFF)}; }

class App : public test::AppWindowTest {
 protected:
  void SetUp() override {
    // The flights' history and recordings go to this process's folder, never the user's.
    setenv("XDG_DATA_HOME", (test::process_temp_dir() / "app_data").c_str(), 1);
    std::string error;
    if (!screen_.open(kW, kH, error)) GTEST_SKIP() << "no EGL device: " << error;
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
  ASSERT_TRUE(app.live()->started());
  frame(app);
  EXPECT_EQ(app.run_info().state, ui::RunState::flying);
  key(app, ui::Key::space);
  EXPECT_TRUE(app.live()->runner().paused());
  EXPECT_EQ(app.run_info().state, ui::RunState::paused);
  key(app, ui::Key::space);
  EXPECT_FALSE(app.live()->runner().paused());
  until_over(app);
  EXPECT_EQ(app.run_info().state, ui::RunState::finished);
  EXPECT_FALSE(app.run_info().metrics.empty()) << "no score card at the end";
  frame(app);
  save_shot(screen_, "finished");
}

// The window closed before Start: no flight was flown, so the summary says so instead of a
// 0.0 s flight with a skill of 0; a --report asked for is said not written (there is nothing
// to score), and none appears.
TEST_F(App, ClosingBeforeAnyFlightSaysNothingWasFlown) {
  cli::FlyOptions o = live_options("mi_helix.toml", 3.0);
  o.report = test::fresh_path("app", "never.json").string();
  cli::Trainer app(o);
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  frame(app);
  testing::internal::CaptureStdout();
  EXPECT_EQ(app.finish(), 0);
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("mixpilot fly: mi_helix: not flown (the window was closed before Start); "
                     "no report written"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("skill"), std::string::npos) << out;
  EXPECT_EQ(out.find("0.0 s"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(o.report));
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
  key(app, ui::Key::r);
  EXPECT_NE(app.live(), first);
  EXPECT_TRUE(app.live()->started());
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
  app.act(ui::PickScenario{int(it - c.scenarios.begin())});
  frame(app);
  EXPECT_EQ(app.live()->mode().kind(), ModeKind::pendubot_swingup);
  EXPECT_FALSE(app.live()->started());
  EXPECT_TRUE(app.run_info().session->pilots.empty()) << "the Pendubot mode has no pilot";
  // Ctrl+R: the next flight is recorded, and the panel says where.
  ASSERT_FALSE(app.run_info().session->record);
  key(app, ui::Key::r, true);
  EXPECT_TRUE(app.run_info().session->record);
  EXPECT_FALSE(app.run_info().session->record_to.empty());
}

// The session panel's assistance switch (a probe flight, SPEC §10): the request makes the
// unstarted flight again without assistance, and the HUD's scene knows it; on again makes it
// assisted. A scenario without a pilot offers no switch, and the choice waits for the next
// scenario that has one.
TEST_F(App, ProbeSwitchInTheSessionPanelRebuildsTheNextFlight) {
  cli::Trainer app(live_options("mi_helix.toml", 2.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  EXPECT_TRUE(app.run_info().session->assist_choosable);
  EXPECT_TRUE(app.run_info().session->assist);
  EXPECT_FALSE(app.live()->mode().identity().probe);
  app.act(ui::SetAssist{false});
  frame(app);
  EXPECT_TRUE(app.live()->mode().identity().probe);
  EXPECT_TRUE(app.live()->scene.probe);
  EXPECT_FALSE(app.live()->started());
  EXPECT_FALSE(app.run_info().session->assist);
  app.act(ui::SetAssist{true});
  frame(app);
  EXPECT_FALSE(app.live()->mode().identity().probe);
  EXPECT_TRUE(app.run_info().session->assist);

  app.act(ui::SetAssist{false});
  const ui::SessionChoices& c = *app.run_info().session;
  const auto pendubot = std::find(c.scenarios.begin(), c.scenarios.end(), "pendubot_swingup");
  const auto helix = std::find(c.scenarios.begin(), c.scenarios.end(), "mi_helix");
  ASSERT_NE(pendubot, c.scenarios.end());
  ASSERT_NE(helix, c.scenarios.end());
  const int helix_index = int(helix - c.scenarios.begin());
  app.act(ui::PickScenario{int(pendubot - c.scenarios.begin())});
  frame(app);
  EXPECT_EQ(app.live()->mode().kind(), ModeKind::pendubot_swingup);
  EXPECT_FALSE(app.run_info().session->assist_choosable);
  app.act(ui::PickScenario{helix_index});
  frame(app);
  EXPECT_EQ(app.live()->mode().kind(), ModeKind::mixed_initiative);
  EXPECT_TRUE(app.live()->mode().identity().probe);
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
  key(app, ui::Key::right_bracket);
  EXPECT_DOUBLE_EQ(r.t, r.events.front().t);
  key(app, ui::Key::end);
  EXPECT_NEAR(r.t, r.duration - app.replay()->dt(), 1e-9);
  key(app, ui::Key::left_bracket);
  EXPECT_DOUBLE_EQ(r.t, r.events.back().t);
  key(app, ui::Key::home);
  EXPECT_EQ(r.t, 0.0);
  // The timeline spans the transport bar's width: its middle is the recording's middle.
  ImGuiWindow* bar = ImGui::FindWindowByName("##transport");
  ASSERT_TRUE(bar);
  const ImVec2 mid(0.5f * (bar->InnerRect.Min.x + bar->InnerRect.Max.x), bar->InnerRect.Min.y + 12);
  click(app, mid);
  EXPECT_NEAR(r.t, 0.5 * r.duration, 0.02 * r.duration);
  key(app, ui::Key::up);
  EXPECT_EQ(app.run_info().speed, 2.0);
  key(app, ui::Key::space);
  ASSERT_TRUE(r.playing);
  const double before = r.t;
  frame(app, 0.5);
  EXPECT_NEAR(r.t - before, 1.0, 1e-9) << "0.5 s of wall time at 2x";
  // The frame shows the step under the playhead.
  EXPECT_NEAR(app.shown_time(), r.t, 1e-9);
  // ↓ slows it down again; → steps 100 ms; Esc leaves the replay for a live flight of the
  // recording's pilot.
  key(app, ui::Key::space);
  ASSERT_FALSE(r.playing);
  key(app, ui::Key::down);
  EXPECT_EQ(app.run_info().speed, 1.0);
  const double at = r.t;
  key(app, ui::Key::right);
  EXPECT_NEAR(r.t, at + 0.1, 1e-9);
  key(app, ui::Key::escape);
  EXPECT_FALSE(app.replaying());
  ASSERT_TRUE(app.live());
  EXPECT_FALSE(app.live()->started());
  EXPECT_EQ(app.run_info().state, ui::RunState::ready);
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
  key(app, ui::Key::f1);
  EXPECT_TRUE(app.ui_state().show_help);
  frame(app);
  save_shot(screen_, "help");
  const ImGuiWindow* sheet = ImGui::FindWindowByName("Keyboard and mouse (F1)");
  EXPECT_TRUE(sheet && sheet->Active);
  key(app, ui::Key::escape);
  EXPECT_FALSE(app.ui_state().show_help);
  key(app, ui::Key::o, true);
  EXPECT_TRUE(app.ui_state().open_dialog.open);
  EXPECT_FALSE(app.ui_state().open_dialog.entries.empty());
  frame(app);  // a popup shows from its second frame
  const ImGuiWindow* browser = ImGui::FindWindowByName("Open a scenario or a recording");
  EXPECT_TRUE(browser && browser->Active);
  save_shot(screen_, "open_dialog");
}

// The score `mixpilot score` gives a recording (app/score.cpp's path).
Metrics score_of(const std::string& path) {
  std::string error;
  const auto rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  if (!rec) return {};
  const std::string* text = embedded_scenario(*rec, path, error);
  EXPECT_TRUE(text) << error;
  auto mode = replay_mode(*rec, path, *text, embedded_scenario_source(*rec, path), {},
                               error);
  EXPECT_TRUE(mode) << error;
  if (!mode) return {};
  Session session(*mode);
  session.run();
  return replay_metrics(*mode, *rec);
}

double metric(const Metrics& m, const std::string& name) {
  for (const auto& [k, v] : m)
    if (k == name) return v;
  ADD_FAILURE() << "no metric " << name;
  return NAN;
}

// The user's folders in a fresh place, so no settings of the machine's user leak in.
void fresh_user_dirs(const char* name) {
  const auto home = test::fresh_path("app", name);
  std::filesystem::create_directories(home);
  setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
}

// The keyboard pilot from injected key events: the novice's commands on mi_helix followed with
// key taps, flown in real time through the window's code. No collision, always in B, the
// raw sticks are recorded, and `score` of the recording is the live score.
TEST_F(App, TheKeyboardFliesFromInjectedKeys) {
  fresh_user_dirs("keyboard");
  constexpr double kSeconds = 12.0, kDt = 0.015;
  const std::string novice = record("mi_helix.toml", kSeconds, "novice", "kb_novice.mcap");
  std::string error;
  const auto nov = read_recording(novice, error);
  ASSERT_TRUE(nov) << error;
  const input::InputSettings settings;
  const double hover = models::MikroKopter().hover_speed();
  std::vector<input::Controls> wanted;
  for (const PilotCommandMsg& m : nov->pilot) {
    PilotCommand c;
    c.roll = m.roll;
    c.pitch = m.pitch;
    for (int i = 0; i < 4; ++i) c.rotor_speed(i) = m.rotor_speed[std::size_t(i)];
    wanted.push_back(input::controls_for(c, settings, hover));
  }

  cli::FlyOptions o = live_options("mi_helix.toml", kSeconds, "keyboard");
  o.record = test::fresh_path("app", "keyboard.mcap").string();
  cli::Trainer app(o);
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.ui_state().score_card_closed = true;
  app.start();
  // A person follows the novice's stick with taps: while the stick (as the ramp moves it, which
  // the person sees on the sticks panel) is short of the target, the key toward the target is
  // held; near it, none is (the stick drifts back to centre).
  ImGuiIO& io = ImGui::GetIO();
  const double rate = 1.0 / settings.keyboard_ramp_s;
  struct Axis {
    input::Key plus, minus;
    double stick = 0;
    int held = 0;  // +1, -1, 0
  };
  Axis axes[4] = {{input::Key::roll_right, input::Key::roll_left},
                  {input::Key::pitch_forward, input::Key::pitch_back},
                  {input::Key::thrust_up, input::Key::thrust_down},
                  {input::Key::yaw_right, input::Key::yaw_left}};
  int presses = 0;
  double last_t = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!app.over() && std::chrono::steady_clock::now() < deadline) {
    const double t = std::max(0.0, app.shown_time());
    const input::Controls& c = wanted[std::min(std::size_t(t / kDt), wanted.size() - 1)];
    const double target[4] = {c.roll, c.pitch, c.thrust, c.yaw};
    for (int i = 0; i < 4; ++i) {
      Axis& a = axes[i];
      const double move = rate * (t - last_t);
      a.stick = a.held ? std::clamp(a.stick + a.held * move, -1.0, 1.0)
                       : (a.stick > 0 ? std::max(0.0, a.stick - move) : std::min(0.0, a.stick + move));
      const int want = target[i] > a.stick + 0.02 && target[i] > 0.02    ? 1
                       : target[i] < a.stick - 0.02 && target[i] < -0.02 ? -1
                                                                          : 0;
      presses += want != 0 && want != a.held;
      a.held = want;
      ui::set_key(io, ui::kFlightKeys[int(a.plus)], want > 0);
      ui::set_key(io, ui::kFlightKeys[int(a.minus)], want < 0);
    }
    last_t = t;
    frame(app);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  for (const ui::Key k : ui::kFlightKeys) ui::set_key(io, k, false);
  ASSERT_TRUE(app.over());
  EXPECT_GT(presses, 3) << "the novice's commands gave hardly any key presses";
  const Metrics live = app.live()->metrics;
  EXPECT_EQ(app.finish(), 0);

  // How closely the taps followed the novice depends on how the frames fell on this machine;
  // what holds whatever the timing: nothing is hit (the MPC's safety constraints), the keys
  // move the sticks in ramps, and the recording replays to the live score (below).
  EXPECT_EQ(metric(live, "collisions"), 0.0);
  const auto r = read_recording(o.record, error);
  ASSERT_TRUE(r) << error;
  ASSERT_EQ(r->joy.size(), r->states.size());
  EXPECT_EQ(r->pilot.front().source, "keyboard");
  // The keys moved the sticks, in ramps: no step between two control steps is larger than the
  // ramp allows (full deflection in keyboard_ramp_s).
  double most = 0, biggest_step = 0;
  for (std::size_t j = 0; j < r->joy.size(); ++j) {
    most = std::max(most, double(std::abs(r->joy[j].axes[2])));
    if (j > 0)
      biggest_step = std::max(biggest_step,
                              double(std::abs(r->joy[j].axes[2] - r->joy[j - 1].axes[2])));
  }
  std::printf("%d key presses; the roll stick reached %.2f\n", presses, most);
  EXPECT_GT(most, 0.05);
  EXPECT_LE(biggest_step, kDt / settings.keyboard_ramp_s + 1e-6);
  const Metrics scored = score_of(o.record);
  for (const char* k : {"skill", "progress", "time_in_ball", "max_deviation_m", "rms_deviation_m",
                        "mean_lambda", "min_lambda", "collisions", "override_rms"})
    EXPECT_EQ(metric(scored, k), metric(live, k)) << k;
}

// I opens the input settings: each axis's curve, the stick mode, the haptic cue.
TEST_F(App, TheInputSettingsPanel) {
  fresh_user_dirs("settings");
  cli::Trainer app(live_options("mi_helix.toml", 2.0, "keyboard"));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  key(app, ui::Key::i);
  EXPECT_TRUE(app.ui_state().show_settings);
  frame(app);
  frame(app);
  const ImGuiWindow* panel = ImGui::FindWindowByName("Input settings (I)");
  ASSERT_TRUE(panel && panel->Active);
  save_shot(screen_, "input_settings");
  // Defaults changes the draft, Apply hands it to the next flight.
  app.ui_state().draft.mode = 1;
  const auto apply = locate(app, "Input settings (I)", "Apply");
  ASSERT_TRUE(apply);
  click(app, *apply);
  ASSERT_TRUE(app.run_info().input && app.run_info().input->settings);
  EXPECT_EQ(app.run_info().input->settings->mode, 1);
  key(app, ui::Key::i);
  EXPECT_FALSE(app.ui_state().show_settings);
}

// A trainee's history in the user's data folder: 14 flights of mi_helix (every fifth a probe),
// the skill rising and D falling, as a learning pilot's would, the last ones recorded (files
// that stand for their recordings); and a second trainee.
void fill_history() {
  std::string error;
  auto store = history::open_history("", error);
  ASSERT_TRUE(store) << error;
  const std::filesystem::path recordings =
      std::filesystem::path(std::getenv("XDG_DATA_HOME")) / "mixpilot" / "recordings";
  std::filesystem::create_directories(recordings);
  for (int i = 0; i < 14; ++i) {
    history::FlightRecord f;
    f.trainee = "Ada Lovelace";
    f.station = "station-1";
    f.scenario = "mi_helix";
    f.scenario_hash = "0";
    f.mode = "mixed_initiative";
    f.pilot = "gamepad";
    f.started_unix_ms = 1'714'000'000'000 + std::int64_t(i) * 86'400'000 / 3;
    f.duration_s = 30.0;
    f.probe = i % 5 == 4;
    f.app_version = "mixpilot test";
    f.front_end = "window";
    const double skill = 35.0 + 3.2 * i + (i % 3 == 1 ? 4.0 : -2.0) - (f.probe ? 18.0 : 0.0);
    f.metrics = {{"skill", skill}};
    if (!f.probe) f.metrics.emplace_back("assistance_dependence", 0.62 - 0.035 * i);
    if (i >= 9) {
      f.recording_path = (recordings / ("mi_helix-" + std::to_string(i) + ".mcap")).string();
      f.recording_hash = std::to_string(i);
      std::ofstream(f.recording_path) << "";
    }
    ASSERT_TRUE(store->add(f, error)) << error;
  }
  history::FlightRecord other;
  other.trainee = "Grace";
  other.scenario = "mi_helix";
  other.mode = "mixed_initiative";
  other.front_end = "window";
  ASSERT_TRUE(store->add(other, error)) << error;
}

// The Progress panel (H): the trainee picked, their flights of the scenario loaded off the UI
// thread, drawn with the best run, the trend, and a table of the flights.
TEST_F(App, TheProgressPanel) {
  fresh_user_dirs("progress");
  fill_history();
  cli::Trainer app(live_options("mi_helix.toml", 2.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.act(ui::LiveRequest{ui::SetTrainee{"Ada Lovelace"}});
  const auto loaded = [&] {
    const ui::HistoryView* h = app.run_info().history;
    return h && h->loaded && h->progress.trainee == "Ada Lovelace" && !h->progress.flights.empty();
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!loaded() && std::chrono::steady_clock::now() < deadline) frame(app);
  ASSERT_TRUE(loaded());
  const ui::HistoryView& h = *app.run_info().history;
  EXPECT_EQ(h.trainees, (std::vector<std::string>{"Ada Lovelace", "Grace"}));
  EXPECT_EQ(h.progress.flights.size(), 14u);
  EXPECT_EQ(h.progress.probes, 2);
  EXPECT_GT(h.progress.assisted_trend.slope, 0.0);
  key(app, ui::Key::h);
  EXPECT_TRUE(app.ui_state().show_progress);
  frame(app);
  frame(app);
  const ImGuiWindow* panel = ImGui::FindWindowByName("Progress (H)");
  ASSERT_TRUE(panel && panel->Active);
  save_shot(screen_, "progress");
  key(app, ui::Key::escape);
  EXPECT_FALSE(app.ui_state().show_progress);
}

// A broken settings file: the app starts with the defaults and says what is wrong, where.
TEST_F(App, ABrokenSettingsFileGivesTheDefaultsAndSaysWhy) {
  fresh_user_dirs("broken_settings");
  const std::string dir = std::string(std::getenv("XDG_CONFIG_HOME")) + "/mixpilot";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/input.toml") << "mode = 7\n[axes.roll]\nexpo = 2\n";
  cli::Trainer app(live_options("mi_helix.toml", 2.0, "keyboard"));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app, 0.0);
  EXPECT_TRUE(app.run_info().message_is_error);
  EXPECT_NE(app.run_info().message.find("the default input settings are used (I shows them)"),
            std::string::npos)
      << app.run_info().message;
  save_shot(screen_, "input_settings_broken_start");
  key(app, ui::Key::i);
  frame(app, 0.0);
  const ui::InputInfo& in = *app.run_info().input;
  EXPECT_EQ(in.settings->mode, 2);
  EXPECT_EQ(in.settings->roll.expo, input::InputSettings{}.roll.expo);
  EXPECT_NE(in.note.find("input.toml:1:8: mode: value outside [1, 4], got 7"), std::string::npos)
      << in.note;
  EXPECT_NE(in.note.find("input.toml:3:8: axes.roll.expo: value outside [0, 1], got 2"),
            std::string::npos)
      << in.note;
  EXPECT_NE(in.note.find("the default input settings are used"), std::string::npos) << in.note;
  save_shot(screen_, "input_settings_broken");
}

// The gamepad unplugged mid-flight: the banner says so, over the arena, in the critical colour.
TEST_F(App, InputLossIsShownOverTheArena) {
  fresh_user_dirs("loss");
  const auto csv = test::fresh_path("app", "loss.csv");
  std::ofstream(csv) << "t,left_x,left_y,right_x,right_y\n0,0,0,0.3,0\n0.5,unplug\n";
  cli::FlyOptions o = live_options("mi_helix.toml", 3.0, "gamepad");
  o.gamepad_script = csv.string();
  cli::Trainer app(o);
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.ui_state().score_card_closed = true;
  app.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (app.shown_time() < 1.0 && std::chrono::steady_clock::now() < deadline) {
    frame(app);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  app.live()->runner().set_paused(true);
  frame(app);
  frame(app);
  ASSERT_GE(app.shown_time(), 1.0);
  save_shot(screen_, "input_lost");
  const std::vector<std::uint8_t> p = screen_.pixels();
  // The banner's frame: the critical colour along a row near the arena's middle height.
  const Rgb red = rgb_of(ui::colour::kCritical);
  int hits = 0;
  for (int y = int(kH * 0.3); y < int(kH * 0.7); ++y)
    for (int x = kW / 4; x < 3 * kW / 4; ++x) hits += colour_near(p, ImVec2(float(x), float(y)), red, 0, 8);
  EXPECT_GT(hits, 400) << "no input-loss banner in the critical colour";
  app.live()->runner().set_paused(false);
}

// A joystick SDL does not know, mapped from the settings panel: Map it... opens the wizard,
// the user moves each stick as asked and skips the buttons, Save writes the SDL line into the
// user's mappings and the pad is usable at once.
TEST_F(App, TheMappingWizardMakesAnUnknownJoystickAGamepad) {
  fresh_user_dirs("wizard");
  ASSERT_EQ(SDL_InitSubSystem(SDL_INIT_JOYSTICK), 0) << SDL_GetError();
  SDL_VirtualJoystickDesc desc{};
  desc.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
  desc.type = SDL_JOYSTICK_TYPE_UNKNOWN;
  desc.naxes = 4;
  desc.nbuttons = 6;
  desc.vendor_id = 0x1209;  // USB ids, as a real joystick has
  desc.product_id = 0x0002;
  desc.name = "mixpilot unknown stick";
  const int index = SDL_JoystickAttachVirtualEx(&desc);
  ASSERT_GE(index, 0) << SDL_GetError();
  SDL_Joystick* js = SDL_JoystickOpen(index);
  ASSERT_TRUE(js);
  const auto set = [&](int axis, double v) {
    SDL_JoystickSetVirtualAxis(js, axis, Sint16(std::lround(v * 32767)));
  };
  for (int a = 0; a < 4; ++a) set(a, 0.0);

  cli::Trainer app(live_options("mi_helix.toml", 2.0, "keyboard"));
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  key(app, ui::Key::i);
  const auto listed = [&] {
    for (int i = 0; i < 100; ++i) {
      frame(app, 0.0);
      for (const auto& d : app.run_info().input->devices)
        if (d.name == "mixpilot unknown stick") return !d.mapped;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  };
  ASSERT_TRUE(listed()) << "the panel does not list the unknown joystick as unmapped";
  frame(app, 0.0);
  save_shot(screen_, "input_settings_unknown_pad");
  const auto map = locate(app, "Input settings (I)", "Map it...##mixpilot unknown stick");
  ASSERT_TRUE(map);
  click(app, *map);
  frame(app, 0.0);
  ASSERT_TRUE(app.run_info().input->wizard);
  // The user follows the prompts: each stick as asked, then lets go.
  const auto wizard = [&] { return *app.run_info().input->wizard; };
  const auto until = [&](auto done) {
    for (int i = 0; i < 200 && !done(); ++i) {
      frame(app, 0.0);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return done();
  };
  for (int i = 0; i < 10; ++i) frame(app, 0.0);  // the rest position
  const std::pair<int, double> moves[] = {{1, -1.0}, {0, 1.0}, {3, -1.0}, {2, 1.0}};
  for (const auto& [axis, v] : moves) {
    const std::size_t step = wizard().step;
    set(axis, v);
    ASSERT_TRUE(until([&] { return !wizard().hint.empty(); })) << wizard().prompt;
    if (axis == 3) save_shot(screen_, "mapping_wizard");
    set(axis, 0.0);
    ASSERT_TRUE(until([&] { return wizard().step == step + 1; })) << wizard().prompt;
  }
  EXPECT_TRUE(wizard().optional) << "the buttons can be skipped";
  while (!wizard().done) {
    const auto skip = locate(app, "Map a gamepad", "Skip");
    ASSERT_TRUE(skip);
    click(app, *skip);
  }
  EXPECT_NE(wizard().mapping.find("lefty:a1,leftx:a0,righty:a3,rightx:a2,platform:Linux,"),
            std::string::npos)
      << wizard().mapping;
  const auto save = locate(app, "Map a gamepad", "Save");
  ASSERT_TRUE(save);
  click(app, *save);
  frame(app, 0.0);
  EXPECT_FALSE(app.run_info().input->wizard);
  std::ifstream in(std::string(std::getenv("XDG_CONFIG_HOME")) + "/mixpilot/gamecontrollerdb.txt");
  std::string line;
  ASSERT_TRUE(std::getline(in, line)) << "nothing in the user's mappings";
  EXPECT_NE(line.find(",mixpilot unknown stick,"), std::string::npos) << line;
  EXPECT_TRUE(until([&] {
    for (const auto& d : app.run_info().input->devices)
      if (d.name == "mixpilot unknown stick") return d.mapped;
    return false;
  })) << "SDL does not know the pad after Save";
  frame(app, 0.0);
  save_shot(screen_, "input_settings_mapped");
  // Another pad arrives: Select picks it for the gamepad flights.
  input::VirtualGamepad pad;
  ASSERT_TRUE(pad.plug(error)) << error;
  ASSERT_TRUE(until([&] {
    for (const auto& d : app.run_info().input->devices)
      if (d.name == "mixpilot virtual gamepad") return true;
    return false;
  }));
  frame(app, 0.0);
  const auto select = locate(app, "Input settings (I)", "Select##mixpilot virtual gamepad");
  ASSERT_TRUE(select);
  click(app, *select);
  const auto selected = [&] {
    for (const auto& d : app.run_info().input->devices)
      if (d.instance == app.run_info().input->active) return d.name;
    return std::string("none");
  };
  EXPECT_TRUE(until([&] { return selected() == "mixpilot virtual gamepad"; })) << selected();
  pad.unplug();
  SDL_JoystickClose(js);
  SDL_JoystickDetachVirtual(index);
  SDL_QuitSubSystem(SDL_INIT_JOYSTICK);
}

// The window at 100 %, 150 % and 200 % of 1280x720 and in a small window (800x450 at 100 %):
// in every state a newcomer meets (ready with the session panel, a long message, flying, the
// score card, the shortcut sheet, the file browser, the input settings, a replay) no pane
// overlaps another, no window cuts what it holds and no text is cut (ui_layout.hpp). With
// MIXPILOT_SHOT_DIR set, each state is saved as layout_<state>_<W>x<H>_<percent>.png.
TEST(AppLayout, NothingOverlapsOrIsCutAtAnyDisplayScale) {
  fresh_user_dirs("layout");
  fill_history();  // the session panel's picker and the Progress panel with a trainee's flights
  const std::string rec = record("mi_helix.toml", 3.0, "reckless", "layout.mcap");
  struct Display {
    int w, h;
    float scale;
  };
  for (const Display d : {Display{1280, 720, 1.0f}, Display{1280, 720, 1.5f},
                          Display{1280, 720, 2.0f}, Display{800, 450, 1.0f}}) {
    cli::Offscreen screen;
    std::string error;
    if (!screen.open(d.w, d.h, error, d.scale)) GTEST_SKIP() << "no EGL device: " << error;
    const std::string at = std::to_string(d.w) + "x" + std::to_string(d.h) + "_" +
                           std::to_string(int(std::lround(100 * d.scale)));
    const auto frames = [&](cli::Trainer& app, int n = 3) {
      for (int i = 0; i < n; ++i) screen.frame([&] { app.build_frame(0.0); }, 1e-4f);
    };
    const auto check = [&](const char* state) {
      SCOPED_TRACE(std::string(state) + " at " + at);
      for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << problem;
      save_shot(screen, std::string("layout_") + state + "_" + at);
    };
    const auto press = [&](cli::Trainer& app, ui::Key k, bool ctrl = false) {
      ImGui::GetIO().KeyCtrl = ctrl;
      ui::set_key(ImGui::GetIO(), k, true);
      frames(app, 1);
      ui::set_key(ImGui::GetIO(), k, false);
      ImGui::GetIO().KeyCtrl = false;
      frames(app);
    };
    {
      cli::Trainer app(live_options("mi_helix.toml", 0.6));
      int status = 0;
      ASSERT_TRUE(app.open_live(error, status)) << error;
      app.act(ui::LiveRequest{ui::SetTrainee{"Ada Lovelace"}});
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!(app.run_info().history && !app.run_info().history->progress.flights.empty()) &&
             std::chrono::steady_clock::now() < deadline)
        frames(app, 1);
      frames(app);
      check("ready");
      press(app, ui::Key::f1);
      check("help");
      press(app, ui::Key::escape);
      press(app, ui::Key::h);
      check("progress");
      press(app, ui::Key::escape);
      press(app, ui::Key::o, true);
      check("open");
      app.ui_state().open_dialog.open = false;
      frames(app);
      press(app, ui::Key::i);
      check("settings");
      press(app, ui::Key::i);
      app.start();
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      frames(app);
      check("flying");
      const auto over_by = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (!app.over() && std::chrono::steady_clock::now() < over_by) {
        frames(app, 1);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      frames(app);
      check("score_card");
    }
    {
      // A message too long for the top bar (a broken settings file names its path).
      const std::string dir = std::string(std::getenv("XDG_CONFIG_HOME")) + "/mixpilot";
      std::filesystem::create_directories(dir);
      std::ofstream(dir + "/input.toml") << "mode = 7\n";
      cli::Trainer app(live_options("mi_helix.toml", 1.0, "keyboard"));
      int status = 0;
      ASSERT_TRUE(app.open_live(error, status)) << error;
      frames(app);
      ASSERT_FALSE(app.run_info().message.empty());
      check("message");
      std::filesystem::remove(dir + "/input.toml");
    }
    {
      cli::FlyOptions o;
      o.replay = true;
      o.pilot = rec;
      cli::Trainer app(o);
      ASSERT_TRUE(app.open_replay(rec, error)) << error;
      app.load_replay();
      app.seek(2.0);
      frames(app);
      check("replay");
    }
  }
}

}  // namespace
}  // namespace mixpilot
