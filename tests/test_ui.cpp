// The UI through real rendering (EGL, Mesa's software rasterizer): each mode's screen renders,
// and pixels that can fail are checked against the telemetry they draw.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/cli.hpp"
#include "app/offscreen.hpp"
#include "app/screenshot.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"
#include "ui/panels.hpp"
#include "ui/requests.hpp"
#include "ui/score_card.hpp"
#include "ui/theme.hpp"

#include "ui_layout.hpp"

namespace mixpilot {
namespace {

constexpr int kW = 1280, kH = 720;

struct Rgb {
  std::uint8_t r, g, b;
};
Rgb rgb_of(ImU32 c) { return {std::uint8_t(c & 0xFF), std::uint8_t((c >> 8) & 0xFF), std::uint8_t((c >> 16) & 0xFF)}; }

bool near(const std::uint8_t* p, Rgb c, int tol = 6) {
  return std::abs(p[0] - c.r) <= tol && std::abs(p[1] - c.g) <= tol && std::abs(p[2] - c.b) <= tol;
}

// A flight of `scenario` for `seconds`, its telemetry kept.
struct Flown {
  std::unique_ptr<Mode> mode;
  ui::History history;
};

Flown fly(const char* scenario, double seconds, const char* pilot = nullptr) {
  ModeRequest request;
  request.duration = seconds;
  if (pilot) request.pilot_name = pilot;
  std::string error;
  Flown f;
  f.mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + scenario, std::move(request),
                     error);
  EXPECT_TRUE(f.mode) << error;
  if (!f.mode) return f;
  struct Keep : TelemetrySink {
    ui::History* h;
    void on_sample(const Telemetry& s) override { h->push(s); }
  } keep;
  keep.h = &f.history;
  Session session(*f.mode);
  session.add_sink(&keep);
  session.run();
  return f;
}

// One frame of the screen; what it asks for is dropped (these tests look at what it draws).
void draw(const ui::Scene& scene, const ui::History& h, const ui::RunInfo& run, ui::UiState& st) {
  ui::Requests ignored;
  ui::draw_screen(scene, h, run, st, ignored);
}

class Ui : public testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    if (!screen_.open(kW, kH, error)) GTEST_SKIP() << "no EGL device: " << error;
  }
  std::vector<std::uint8_t> render(const ui::Scene& scene, const ui::History& h, ui::UiState& st) {
    ui::RunInfo run;
    run.state = ui::RunState::flying;
    for (int f = 0; f < 2; ++f) screen_.frame([&] { draw(scene, h, run, st); });
    return screen_.pixels();
  }
  cli::Offscreen screen_;
};

// The authority bar: the pilot's colour fills the fraction λ of the bar, the planner's the rest.
TEST_F(Ui, AuthorityBarFillMatchesLambda) {
  Flown f = fly("mi_helix.toml", 3.0, "novice");
  ASSERT_TRUE(f.mode);
  const ui::Scene scene = ui::scene_of(*f.mode, "novice");
  ui::UiState st;
  const double lambda = f.history.newest().lambda;
  const auto px = render(scene, f.history, st);
  // The bar's row: the first row from the view's top with both colours, counted left to right.
  ImVec2 vmin, vmax;
  ui::RunInfo run;
  run.state = ui::RunState::flying;
  ui::view_rect(ImVec2(kW, kH), run, vmin, vmax);
  int best_row = -1, pilot = 0, planner = 0;
  for (int y = int(vmin.y); y < int(vmin.y) + 120 && best_row < 0; ++y) {
    int a = 0, b = 0;
    for (int x = 0; x < kW; ++x) {
      const std::uint8_t* p = &px[(std::size_t(y) * kW + std::size_t(x)) * 4];
      a += near(p, rgb_of(ui::colour::kPilot)) ? 1 : 0;
      b += near(p, rgb_of(ui::colour::kPlannerFill)) ? 1 : 0;
    }
    if (a > 100 && b > 0 && a + b > 300) {
      best_row = y;
      pilot = a;
      planner = b;
    }
  }
  ASSERT_GE(best_row, 0) << "no authority bar found";
  // The needle and the 0.5 tick hide a few pixels: within 2 % of the bar's width.
  EXPECT_NEAR(double(pilot) / double(pilot + planner), lambda, 0.02) << "row " << best_row;
}

// Sustained overload: while the safe controller flies, the HUD says so in the critical colour
// (and not before); a headless screenshot's HUD counts the fallbacks and deadline misses of the
// steps before it, as the window does (it showed 0 whatever the flight did).
TEST_F(Ui, TheHudSaysWhenTheMachineCannotKeepUpAndCountsWhatHappened) {
  ModeRequest request;
  request.duration = 3.0;
  request.pilot_name = "novice";
  std::string error;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml",
                        std::move(request), error);
  ASSERT_TRUE(mode) << error;
  std::vector<std::int64_t> overruns;
  for (std::int64_t k = 100; k < 150; ++k) overruns.push_back(k);
  mode->replay_timing(overruns, {100, 101});
  const ui::Scene scene = ui::scene_of(*mode, "novice");
  cli::ScreenshotSink shots(scene, {}, true);
  ui::History h;
  int critical_before = -1, critical_during = -1;
  const auto critical = [&] {
    ui::UiState st;
    const auto px = render(scene, h, st);
    // Inside the HUD's window only (the plots have critical-coloured lines of their own).
    const ImGuiWindow* hud = ImGui::FindWindowByName("##hud");
    if (!hud) return -1;
    int n = 0;
    for (int y = int(hud->Pos.y); y < int(hud->Pos.y + hud->Size.y) && y < kH; ++y)
      for (int x = int(hud->Pos.x); x < int(hud->Pos.x + hud->Size.x) && x < kW; ++x)
        n += near(&px[(std::size_t(y) * kW + std::size_t(x)) * 4], rgb_of(ui::colour::kCritical), 40);
    if (const char* dir = std::getenv("MIXPILOT_SHOT_DIR"))
      (void)cli::write_file(std::string(dir) + "/safe_hold_" + std::to_string(h.newest().step) +
                                ".png", screen_.png(), true, error);
    return n;
  };
  while (mode->step()) {
    h.push(mode->telemetry());
    shots.on_sample(mode->telemetry());
    if (mode->telemetry().step == 90) critical_before = critical();
    if (mode->telemetry().step == 120) critical_during = critical();
  }
  EXPECT_GT(critical_during, critical_before + 300) << critical_before;  // the line's text
  EXPECT_EQ(shots.counts().fallbacks, 50);
  EXPECT_EQ(shots.counts().deadline_misses, 50);  // each overrun, the two recorded among them
}

// A frame depends only on what it draws: rendered twice, the same pixels.
TEST_F(Ui, SameSnapshotSamePixels) {
  Flown f = fly("mi_helix.toml", 1.0, "novice");
  ASSERT_TRUE(f.mode);
  const ui::Scene scene = ui::scene_of(*f.mode, "novice");
  ui::UiState st;
  EXPECT_EQ(render(scene, f.history, st), render(scene, f.history, st));
}

// Keys reach the UI: '3' switches to the top camera, and the arena looks different.
TEST_F(Ui, KeyThreeSwitchesToTopCamera) {
  Flown f = fly("mi_helix.toml", 1.0, "novice");
  ASSERT_TRUE(f.mode);
  const ui::Scene scene = ui::scene_of(*f.mode, "novice");
  ui::UiState st;
  const auto chase = render(scene, f.history, st);
  ASSERT_EQ(st.camera, ui::Camera::chase);
  ui::set_key(ImGui::GetIO(), ui::Key::digit3, true);
  ui::RunInfo run;
  screen_.frame([&] { draw(scene, f.history, run, st); });
  ui::set_key(ImGui::GetIO(), ui::Key::digit3, false);
  EXPECT_EQ(st.camera, ui::Camera::top);
  EXPECT_NE(render(scene, f.history, st), chase);
}

// The request of type T among `requests`, or nullptr.
template <class T>
const T* find_request(const ui::Requests& requests) {
  const T* found = nullptr;
  for (const ui::Request& r : requests)
    std::visit([&](const auto& group) {
      std::visit([&](const auto& one) {
        if constexpr (std::is_same_v<std::decay_t<decltype(one)>, T>) found = &one;
      }, group);
    }, r);
  return found;
}

// The shortcut sheet's keys, by the UI's key names, ask for what they name (UI.md §10): each
// press gives its typed request, in the state where it means something.
TEST_F(Ui, KeysAskForWhatTheyName) {
  Flown f = fly("mi_helix.toml", 0.5, "novice");
  ASSERT_TRUE(f.mode);
  const ui::Scene scene = ui::scene_of(*f.mode, "novice");
  ui::UiState st;
  ui::RunInfo run;
  ui::SessionChoices session;
  run.session = &session;
  ui::Requests out;
  // One frame with `k` going down (Ctrl, Shift held as asked), then one with it released.
  const auto press = [&](ui::Key k, bool ctrl = false, bool shift = false) {
    ImGuiIO& io = ImGui::GetIO();
    io.KeyCtrl = ctrl;
    io.KeyShift = shift;
    ui::set_key(io, k, true);
    out.clear();
    screen_.frame([&] { ui::draw_screen(scene, f.history, run, st, out); });
    ui::set_key(io, k, false);
    io.KeyCtrl = io.KeyShift = false;
    screen_.frame([&] { draw(scene, f.history, run, st); });
  };
  screen_.frame([&] { draw(scene, f.history, run, st); });

  // Ready: Space starts, Ctrl+R records the next flight, R flies again.
  run.state = ui::RunState::ready;
  press(ui::Key::space);
  EXPECT_TRUE(find_request<ui::StartFlight>(out));
  press(ui::Key::r, true);
  ASSERT_TRUE(find_request<ui::SetRecord>(out));
  EXPECT_TRUE(find_request<ui::SetRecord>(out)->on);
  run.can_restart = true;
  press(ui::Key::r);
  EXPECT_TRUE(find_request<ui::RestartFlight>(out));
  // Flying: Space pauses. Waiting for the remote vehicle: Esc cancels, Space does nothing.
  run.state = ui::RunState::flying;
  press(ui::Key::space);
  EXPECT_TRUE(find_request<ui::TogglePause>(out));
  run.state = ui::RunState::waiting;
  press(ui::Key::escape);
  EXPECT_TRUE(find_request<ui::CancelVehicleWait>(out));
  press(ui::Key::space);
  EXPECT_TRUE(out.empty());

  // The keyboard pilot: the held flight keys, every frame, as input::Key bits.
  ui::InputInfo keyboard;
  keyboard.pilot = "keyboard";
  run.input = &keyboard;
  run.state = ui::RunState::flying;
  press(ui::Key::w);
  ASSERT_TRUE(find_request<ui::HeldFlightKeys>(out));
  EXPECT_EQ(find_request<ui::HeldFlightKeys>(out)->keys, 1u << int(input::Key::thrust_up));
  run.input = nullptr;

  // A replay: Space plays, the arrows step and change the speed, brackets jump, Esc leaves.
  ui::ReplayInfo replay;
  replay.t = 1.0;
  replay.duration = 4.0;
  run.replay = &replay;
  run.session = nullptr;
  run.state = ui::RunState::replay;
  run.speed = 1.0;
  press(ui::Key::space);
  EXPECT_TRUE(find_request<ui::TogglePlay>(out));
  EXPECT_FALSE(find_request<ui::TogglePause>(out)) << "a replay's Space is no live request";
  press(ui::Key::right);
  ASSERT_TRUE(find_request<ui::Seek>(out));
  EXPECT_DOUBLE_EQ(find_request<ui::Seek>(out)->t, 1.1);
  press(ui::Key::left, false, true);
  ASSERT_TRUE(find_request<ui::Seek>(out));
  EXPECT_DOUBLE_EQ(find_request<ui::Seek>(out)->t, 0.99);
  press(ui::Key::down);
  ASSERT_TRUE(find_request<ui::SetPlaySpeed>(out));
  EXPECT_EQ(find_request<ui::SetPlaySpeed>(out)->speed, 0.5);
  press(ui::Key::left_bracket);
  ASSERT_TRUE(find_request<ui::JumpToEvent>(out));
  EXPECT_EQ(find_request<ui::JumpToEvent>(out)->direction, -1);
  press(ui::Key::escape);
  EXPECT_TRUE(find_request<ui::LeaveReplay>(out));
  press(ui::Key::r);
  EXPECT_FALSE(find_request<ui::RestartFlight>(out)) << "R restarts live flights only";
}

// At the end of a flight the score card opens with every score field; not before.
TEST_F(Ui, ScoreCardAtTheEnd) {
  Flown f = fly("mi_helix.toml", 0.5, "novice");
  ASSERT_TRUE(f.mode);
  const ui::Scene scene = ui::scene_of(*f.mode, "novice");
  ui::UiState st;
  ui::RunInfo run;
  run.state = ui::RunState::flying;
  screen_.frame([&] { draw(scene, f.history, run, st); });
  const ImGuiWindow* card = ImGui::FindWindowByName("Score card");
  EXPECT_TRUE(card == nullptr || !card->Active);
  run.state = ui::RunState::finished;
  run.metrics = f.mode->metrics();
  ASSERT_FALSE(run.metrics.empty());
  bool active = false;
  screen_.frame([&] {
    draw(scene, f.history, run, st);
    card = ImGui::FindWindowByName("Score card");
    active = card && card->Active;
  });
  EXPECT_TRUE(active);
  // The card explains every field it shows, in every mode (the report's and the lost ones).
  for (const char* scenario : {"mi_helix.toml", "pendubot_swingup.toml", "tracking_helix.toml",
                               "tracking_smooth_step.toml", "obstacles_cluttered.toml"}) {
    Flown g = fly(scenario, 0.3);
    ASSERT_TRUE(g.mode) << scenario;
    for (const auto& [key, value] : g.mode->metrics())
      EXPECT_STRNE(ui::score_field_meaning(key), "") << scenario << ": " << key;
    for (const char* key : {"lost", "lost_at_s"})
      EXPECT_STRNE(ui::score_field_meaning(key), "") << key;
  }
}

// Every mode renders, and its view is not empty: many pixels differ from the background.
TEST_F(Ui, EveryModeRenders) {
  for (const char* scenario : {"mi_helix.toml", "pendubot_swingup.toml", "tracking_helix.toml",
                               "obstacles_thrown_balls.toml"}) {
    Flown f = fly(scenario, 1.0);
    ASSERT_TRUE(f.mode) << scenario;
    const ui::Scene scene = ui::scene_of(*f.mode, "test");
    ui::UiState st;
    const auto px = render(scene, f.history, st);
    const Rgb bg = rgb_of(ui::colour::kBackground);
    int drawn = 0;
    for (int y = 120; y < kH; ++y)
      for (int x = 0; x < kW / 2; ++x)
        drawn += near(&px[(std::size_t(y) * kW + std::size_t(x)) * 4], bg, 2) ? 0 : 1;
    EXPECT_GT(drawn, 2000) << scenario << ": the view is (almost) empty";
  }
}

// At launch the chase camera looks at the vehicle across the column on the arena's axis (a
// sphere between the camera and the vehicle). It is faded: around the vehicle it adds almost no
// obstacle colour to what the scene shows without it, yet its outline is still drawn.
TEST_F(Ui, AnObstacleBetweenTheCameraAndTheVehicleIsFaded) {
  Flown f = fly("mi_helix.toml", 0.1, "novice");
  ASSERT_TRUE(f.mode);
  const ui::Scene scene = ui::scene_of(*f.mode, "novice");
  ui::UiState st;
  ASSERT_EQ(st.camera, ui::Camera::chase);
  const auto with = render(scene, f.history, st);
  ImVec2 vmin, vmax;
  ui::view_rect(ImVec2(kW, kH), ui::RunInfo{}, vmin, vmax);
  const Telemetry& s = f.history.newest();
  ImVec2 vehicle;
  ASSERT_TRUE(ui::project_in_arena(scene, s, st, vmin, vmax, s.x.head<3>(), vehicle));
  // The sphere whose disc on screen holds the vehicle (its radius from its top's projection).
  int blocking = -1;
  float radius = 0.0f;
  for (std::size_t k = 0; k < scene.spheres.size(); ++k) {
    const ui::SceneSphere& o = scene.spheres[k];
    ImVec2 c, top;
    if (!ui::project_in_arena(scene, s, st, vmin, vmax, o.center, c) ||
        !ui::project_in_arena(scene, s, st, vmin, vmax, o.center + o.radius * Eigen::Vector3d::UnitZ(), top))
      continue;
    const float r = std::hypot(top.x - c.x, top.y - c.y);
    if (std::hypot(vehicle.x - c.x, vehicle.y - c.y) < 0.5f * r && r > radius) {
      blocking = int(k);
      radius = r;
    }
  }
  ASSERT_GE(blocking, 0) << "no sphere between the chase camera and the vehicle at launch";
  ui::Scene without = scene;
  without.spheres.erase(without.spheres.begin() + blocking);
  const auto bare = render(without, f.history, st);
  // Strongly obstacle-coloured: reddish purple, well away from the grey scene.
  const auto purple = [](const std::uint8_t* p) { return p[0] - p[1] > 20 && p[2] - p[1] > 10; };
  int region = 0, added = 0, changed = 0;
  const float around = 0.8f * radius;
  for (int y = int(vmin.y); y < int(vmax.y); ++y) {
    for (int x = int(vmin.x); x < int(vmax.x); ++x) {
      const std::size_t i = (std::size_t(y) * kW + std::size_t(x)) * 4;
      changed += with[i] != bare[i] || with[i + 1] != bare[i + 1] || with[i + 2] != bare[i + 2];
      if (std::hypot(float(x) - vehicle.x, float(y) - vehicle.y) > around) continue;
      ++region;
      added += purple(&with[i]) && !purple(&bare[i]) ? 1 : 0;
    }
  }
  ASSERT_GT(region, 1000);
  EXPECT_LT(added, region / 50) << added << " of " << region
                                << " pixels around the vehicle turn obstacle-coloured";
  EXPECT_GT(changed, 300) << "the sphere in front of the vehicle is not drawn at all";
}

// Every mode's flying screen at 100 %, 150 % and 200 % of 1280x720 and in an 800x450 window:
// no pane overlaps another, nothing is cut (ui_layout.hpp).
TEST(UiLayout, EveryModeFitsAtEveryDisplayScale) {
  std::vector<std::pair<const char*, Flown>> flights;
  for (const char* scenario : {"mi_helix.toml", "pendubot_swingup.toml", "tracking_helix.toml",
                               "obstacles_thrown_balls.toml"})
    flights.emplace_back(scenario, fly(scenario, 1.5));
  struct Display {
    int w, h;
    float scale;
  };
  for (const Display d : {Display{1280, 720, 1.0f}, Display{1280, 720, 1.5f},
                          Display{1280, 720, 2.0f}, Display{800, 450, 1.0f}}) {
    cli::Offscreen screen;
    std::string error;
    if (!screen.open(d.w, d.h, error, d.scale)) GTEST_SKIP() << "no EGL device: " << error;
    for (auto& entry : flights) {
      const char* const scenario = entry.first;
      Flown& f = entry.second;
      ASSERT_TRUE(f.mode) << scenario;
      SCOPED_TRACE(std::string(scenario) + " at " + std::to_string(d.w) + "x" + std::to_string(d.h) +
                   ", scale " + std::to_string(d.scale));
      const ui::Scene scene = ui::scene_of(*f.mode, "test");
      ui::UiState st;
      ui::RunInfo run;
      run.state = ui::RunState::flying;
      for (int i = 0; i < 3; ++i) screen.frame([&] { draw(scene, f.history, run, st); });
      for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << problem;
      // To look at: MIXPILOT_SHOT_DIR/<prefix><scenario>_<W>x<H>_<percent>.png.
      const auto shot = [&](const char* prefix) {
        const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
        if (!dir || !*dir) return;
        const std::string name = std::string(scenario).substr(0, std::string(scenario).find('.'));
        std::ofstream(std::string(dir) + "/" + prefix + name + "_" + std::to_string(d.w) + "x" +
                          std::to_string(d.h) + "_" +
                          std::to_string(int(std::lround(100 * d.scale))) + ".png",
                      std::ios::binary)
            << screen.png();
      };
      shot("mode_");
      // The HUD with all it can show at once: the safe controller flying, a remote vehicle's
      // round trip, the instructor's commands in force, counts of five digits.
      ui::History all = f.history;
      Telemetry s = all.newest();
      s.events |= kEventSafeHold;
      s.set_channel(s.num_channels, "RTT estimate", "s", 0.1234);
      s.set_channel(s.num_channels, "RTT sample", "s", 0.1250);
      s.instructor.bounds = AuthorityBounds{0.1, 0.3};
      s.instructor.gust = Eigen::Vector3d(2.0, 0.0, 0.0);
      s.instructor.gust_left = 0.4;
      s.instructor.extra_delay = 0.05;
      s.instructor.input_loss_left = 1.5;
      all.push(s);
      // Flying (the HUD as wide as the view allows) and finished (beside the session panel, at
      // its least width).
      ui::SessionChoices session;
      session.scenarios = {scenario};
      session.scenario = 0;
      session.pilots = {"novice", "experienced"};
      session.pilot = 0;
      for (const ui::RunState state : {ui::RunState::flying, ui::RunState::finished}) {
        ui::RunInfo busy = run;
        busy.state = state;
        busy.session = &session;
        busy.fallbacks = busy.deadline_misses = 12345;
        busy.instructor_paused = true;
        for (int i = 0; i < 3; ++i) screen.frame([&] { draw(scene, all, busy, st); });
        for (const std::string& problem : test::layout_problems())
          ADD_FAILURE() << "with every HUD item, " << (state == ui::RunState::finished ? "finished" : "flying")
                        << ": " << problem;
      }
      shot("hud_full_");  // finished
    }
  }
}

}  // namespace
}  // namespace mixpilot
