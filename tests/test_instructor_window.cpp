// The instructor's window (SPEC §10, `mixpilot instruct`): its screen from a view made here
// (tiles, the list past four stations, what the instructor keeps in force on a tile, the layout
// at 100 % and 150 %); a trainee's window READY under a ceiling, as it shows it and announces
// it; and the whole window — app/instructor_app.hpp through the headless renderer — with two
// station processes (headless, real time, loopback, this test's own domain): both listed with
// their tiles, a ceiling sent to one from the command pane and shown accepted and in force on
// its tile, a gust shown on the tile while it acts, commands to a station that obeys no
// instructor and a bad marker shown refused with the station's reason.
//
// Processes are waited for on conditions with generous timeouts, never timed.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <functional>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/instructor_app.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "input/net/instructor_client.hpp"
#include "net_test.hpp"
#include "spawned.hpp"
#include "temp_files.hpp"
#include "ui/instructor.hpp"
#include "ui/keys.hpp"
#include "ui_layout.hpp"

// LeakSanitizer (the sanitize preset): Mesa and fontconfig keep allocations until exit, in
// modules it cannot name for a suppression; test_app turns it off the same way.
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }

namespace mixpilot::net {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::Spawned;

bool shown(const char* window) {
  ImGuiWindow* w = ImGui::FindWindowByName(window);
  return w && w->Active && !w->Hidden;
}

// Drives a frame function as a user would: keys by the UI's names, the mouse moved until ImGui
// hovers an item, clicks.
struct Driver {
  cli::Offscreen& screen;
  std::function<void()> build;

  void frame() { screen.frame(build, 1.0f / 30.0f); }
  void key(ui::Key k, bool ctrl = false) {
    ImGuiIO& io = ImGui::GetIO();
    io.KeyCtrl = ctrl;
    ui::set_key(io, k, true);
    frame();
    ui::set_key(io, k, false);
    io.KeyCtrl = false;
    frame();
  }
  std::optional<ImVec2> locate(const char* window, const char* label) {
    frame();
    ImGuiWindow* w = ImGui::FindWindowByName(window);
    if (!w) return std::nullopt;
    const ImGuiID id = w->GetID(label);
    const ImRect r = w->Rect();
    for (float y = r.Min.y + 2; y < r.Max.y; y += 5) {
      for (float x = r.Min.x + 2; x < r.Max.x; x += 10) {
        ImGui::GetIO().MousePos = ImVec2(x, y);
        screen.layout(build, 1e-4f);
        if (GImGui->HoveredId == id) return ImVec2(x, y);
      }
    }
    return std::nullopt;
  }
  void click(ImVec2 at) {
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = at;
    frame();
    io.MouseDown[0] = true;
    frame();
    io.MouseDown[0] = false;
    frame();
    io.MousePos = ImVec2(-1, -1);
  }
};

// Saves the last frame as NAME.png in $MIXPILOT_SHOT_DIR when it is set (to look at it).
void save(const cli::Offscreen& screen, const std::string& name) {
  if (const char* dir = std::getenv("MIXPILOT_SHOT_DIR"))
    std::ofstream(fs::path(dir) / (name + ".png"), std::ios::binary) << screen.png();
}

// A view of `n` stations, as the network thread makes one (no scene: the default volume).
ui::InstructorView fake_view(int n) {
  ui::InstructorView v;
  v.domain = 7;
  v.issuer = "teacher@host";
  v.security = "no DDS Security";
  for (int i = 0; i < n; ++i) {
    ui::StationTile t;
    t.name = std::string("sim") + char('1' + i);
    t.trainee = "trainee " + std::to_string(i + 1);
    t.scenario = "mi_helix";
    t.mode = "mixed_initiative";
    t.state = i == 1 ? "paused" : "flying";
    t.accepts_instructor = i != 2;
    t.security = "unauthenticated, loopback";
    t.t = 12.5;
    t.duration = 30;
    t.lambda = 0.2 + 0.15 * i;
    t.deviation = 0.04;
    t.time_in_ball = 0.9;
    t.mean_lambda = 0.7;
    t.telemetry = true;
    auto h = std::make_shared<ui::History>(200);
    for (int k = 0; k < 200; ++k) {
      Telemetry s;
      s.step = k;
      s.t = 2.5 + 0.05 * k;
      s.x = Eigen::VectorXd::Zero(13);
      s.x << std::cos(0.02 * k), std::sin(0.02 * k), 1.0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0;
      s.lambda = 0.5 + 0.45 * std::sin(0.05 * k + i);
      s.set_channel(0, "lambda", "", s.lambda);
      s.set_channel(1, "deviation", "m", 0.04);
      h->push(s);
    }
    t.history = h;
    t.commands.push_back({InstructorCommandKind::bounds, "bounds: λ floor 0, ceiling 0.3",
                          ui::CommandOutcome::accepted, "", 3.0});
    t.commands.push_back({InstructorCommandKind::pause, "pause", ui::CommandOutcome::refused,
                          "instructor not allowed: this station obeys no instructor", 1.0});
    v.stations.push_back(std::move(t));
  }
  return v;
}

// The screen alone: four tiles side by side, the list past four (S; a tick shows a fifth
// station, dropping the first), a large tile with its plots and the others small; nothing overlaps, is
// cut or leaves the display at 100 % and 150 %.
class InstructorWindow : public Net {};

TEST_F(InstructorWindow, TilesTheListAndTheLargeViewFitAt100And150Percent) {
  for (const float scale : {1.0f, 1.5f}) {
    cli::Offscreen screen;
    std::string error;
    if (!screen.open(1280, 720, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
    const ui::InstructorView v = fake_view(6);
    ui::InstructorUi ui;
    std::vector<ui::InstructorRequest> out;
    Driver d{screen, [&] { ui::draw_instructor(v, ui, out); }};
    d.frame();
    d.frame();
    const std::string tag = scale == 1.0f ? "100" : "150";
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << tag << " %: " << p;
    EXPECT_TRUE(shown("##tile sim1") && shown("##tile sim4")) << tag;
    EXPECT_FALSE(shown("##tile sim5")) << tag;
    save(screen, "overview_" + tag);
    // The top bar offers the list; S opens it.
    d.key(ui::Key::s);
    EXPECT_TRUE(shown("Stations (S)")) << tag;
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << tag << " % list: " << p;
    save(screen, "list_" + tag);
    EXPECT_EQ(ui.selected, "sim1");
    // Show sim5 from the list: the first of the shown gives way.
    const std::optional<ImVec2> tick = d.locate("Stations (S)", "##show sim5");
    ASSERT_TRUE(tick) << tag;
    d.click(*tick);
    d.frame();
    d.key(ui::Key::escape);
    EXPECT_FALSE(shown("Stations (S)")) << tag;
    EXPECT_TRUE(shown("##tile sim5")) << tag;
    EXPECT_FALSE(shown("##tile sim1")) << tag;
    // Key 2: the second tile's station, large, the others small.
    d.key(ui::Key::digit2);
    const std::vector<const ui::StationTile*> tiles = ui::shown_tiles(v, ui);
    ASSERT_EQ(tiles.size(), 4u);
    EXPECT_EQ(ui.selected, tiles[1]->name);
    EXPECT_TRUE(ui.large);
    d.frame();
    EXPECT_TRUE(shown(("##tile " + ui.selected).c_str()));
    EXPECT_TRUE(shown(("##mini " + tiles[0]->name).c_str()));
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << tag << " % large: " << p;
    save(screen, "large_" + tag);
    // Esc: side by side again, the selection kept; Ctrl+B asks for the bounds of the sliders.
    d.key(ui::Key::escape);
    EXPECT_FALSE(ui.large);
    ui.draft.ceiling = 0.4f;
    out.clear();
    d.key(ui::Key::b, true);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].station, tiles[1]->name);
    EXPECT_EQ(out[0].command.kind, InstructorCommandKind::bounds);
    EXPECT_EQ(out[0].command.bounds, (AuthorityBounds{0.0, 0.4f}));
  }
}

// What the instructor's commands keep in force at a station shows on its tile while it acts,
// as the trainee's HUD says it: over the top of the arena (a window of its own) side by side,
// on a line under the header of a small tile while another is large; the λ strip draws the
// bounds. A station with nothing in force shows nothing. Nothing overlaps or is cut at 100 %
// and 150 %.
TEST_F(InstructorWindow, TilesShowWhatIsInForceAtTheStation) {
  ui::InstructorView v = fake_view(3);
  ui::StationTile& gusted = v.stations[0];
  gusted.in_force.bounds = {0.0, 0.3};
  gusted.in_force.gust = {2.0, 0.0, 0.0};
  gusted.in_force.gust_left = 0.35;
  gusted.in_force.extra_delay = 0.1;
  gusted.in_force.input_loss_left = 0.8;
  auto h = std::make_shared<ui::History>(gusted.history->size());
  for (std::size_t i = 0; i < gusted.history->size(); ++i) {
    Telemetry s = (*gusted.history)[i];
    s.instructor.bounds = {0.0, 0.3};
    h->push(s);
  }
  gusted.history = h;
  ASSERT_EQ(v.stations[1].state, "paused");  // sim2: paused by the instructor, nothing else
  EXPECT_EQ(ui::tile_in_force(gusted),
            (std::vector<std::string>{"instructor: ceiling 0.30", "· gust 2.0 N, 0.3 s left",
                                      "· delay +0.100 s", "· input lost, 0.8 s left"}));
  EXPECT_EQ(ui::tile_in_force(v.stations[1]), std::vector<std::string>{"instructor: paused"});
  EXPECT_TRUE(ui::tile_in_force(v.stations[2]).empty());
  for (const float scale : {1.0f, 1.5f}) {
    const std::string tag = scale == 1.0f ? "100" : "150";
    cli::Offscreen screen;
    std::string error;
    if (!screen.open(1280, 720, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
    ui::InstructorUi ui;
    std::vector<ui::InstructorRequest> out;
    Driver d{screen, [&] { ui::draw_instructor(v, ui, out); }};
    d.frame();
    d.frame();
    EXPECT_TRUE(shown("##in force sim1")) << tag;
    EXPECT_TRUE(shown("##in force sim2")) << tag;
    EXPECT_FALSE(shown("##in force sim3")) << tag;
    // Over its own tile's arena, under the header, inside the tile.
    const ImGuiWindow* over = ImGui::FindWindowByName("##in force sim1");
    const ImGuiWindow* tile = ImGui::FindWindowByName("##tile sim1");
    ASSERT_TRUE(over && tile);
    EXPECT_GE(over->Pos.x, tile->Pos.x) << tag;
    EXPECT_LE(over->Pos.x + over->Size.x, tile->Pos.x + tile->Size.x) << tag;
    EXPECT_GT(over->Pos.y, tile->Pos.y + 2.0f * ImGui::GetTextLineHeight()) << tag;
    // Above the λ strip and the figures (two lines each) at the tile's bottom.
    EXPECT_LE(over->Pos.y + over->Size.y,
              tile->Pos.y + tile->Size.y - 4.0f * ImGui::GetTextLineHeight())
        << tag;
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << tag << " %: " << p;
    save(screen, "in_force_" + tag);
    // sim2 large: sim1 small, its line under the header; sim2's pause over its arena.
    d.key(ui::Key::digit2);
    d.frame();
    EXPECT_TRUE(shown("##mini sim1")) << tag;
    EXPECT_FALSE(shown("##in force sim1")) << tag;
    EXPECT_TRUE(shown("##in force sim2")) << tag;
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << tag << " % large: " << p;
    save(screen, "in_force_large_" + tag);
  }
}

// READY shows what the flight starts with. A trainee's window flown with an instructor's
// ceiling of 0.3 (fly --ceiling 0.3) and published as a station: before its first step its
// telemetry — what the authority bar, the λ plot and the reason line draw — holds λ 0.3 (the
// initial 0.5 under the ceiling) with the ceiling in force and as the reason, and the station
// is announced READY at λ 0.3 under that ceiling, so the instructor's tile says the same.
// Nothing overlaps or is cut at 100 % and 150 %.
TEST_F(InstructorWindow, ReadyShowsTheCeilingToTheTraineeAndTheInstructor) {
  const fs::path dir = test::fresh_path("instructor_window", "ready");
  fs::create_directories(dir);
  setenv("XDG_CONFIG_HOME", (dir / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (dir / "data").c_str(), 1);
  std::string error;
  net::InstructorClient teacher;
  ASSERT_TRUE(teacher.open({domain_, "teacher", nullptr, false}, error)) << error;
  for (const float scale : {1.0f, 1.5f}) {
    const std::string tag = scale == 1.0f ? "100" : "150";
    cli::Offscreen screen;
    if (!screen.open(1280, 720, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
    cli::FlyOptions o;
    o.scenario_path = kSrc + "/scenarios/mi_helix.toml";
    o.pilot = "novice";
    o.duration = 2.0;
    o.bounds = {0.0, 0.3};
    o.publish = true;
    o.domain = domain_;
    o.station = "ready" + tag;
    o.trainee = "Ada";
    o.history = "off";
    o.ghost = "off";
    cli::Trainer app(o);
    int status = 0;
    ASSERT_TRUE(app.open_live(error, status)) << error;
    for (int i = 0; i < 3; ++i) screen.frame([&] { app.build_frame(0.0); }, 1e-4f);
    ASSERT_EQ(app.run_info().state, ui::RunState::ready) << tag;
    const Telemetry& ready = app.live()->mode().telemetry();
    EXPECT_FALSE(ready.solved) << tag;
    EXPECT_EQ(ready.lambda, 0.3) << tag;
    EXPECT_EQ(ready.instructor.bounds, (AuthorityBounds{0.0, 0.3})) << tag;
    EXPECT_EQ(ready.reason.cap, LambdaCap::instructor_ceiling) << tag;
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << tag << " %: " << p;
    save(screen, "ready_ceiling_" + tag);
    ASSERT_TRUE(eventually([&] {
      teacher.poll(0.01);
      const std::optional<StationView> v = teacher.station(o.station);
      return v && v->in_force.bounds == AuthorityBounds{0.0, 0.3};
    }, 30)) << tag;
    const StationView v = *teacher.station(o.station);
    EXPECT_EQ(v.state, StationState::ready) << tag;
    EXPECT_EQ(v.lambda, 0.3) << tag;
    EXPECT_EQ(v.trainee, "Ada") << tag;
  }
}

// --- With station processes ------------------------------------------------------------------------

std::vector<std::pair<std::string, std::string>> user_dirs(const fs::path& dir) {
  return {{"XDG_CONFIG_HOME", (dir / "config").string()}, {"XDG_DATA_HOME", (dir / "data").string()}};
}

// A station: the novice flies mi_helix's five-minute variant headless in real time, announced and
// publishing (it is interrupted at the end).
std::vector<std::string> station(const std::string& name, std::uint32_t domain,
                                 std::vector<std::string> more) {
  std::vector<std::string> a = {kMixpilot, "fly", "--scenario", kSrc + "/scenarios/mi_helix_endurance.toml",
                                "--pilot", "novice", "--headless", "--realtime", "--publish", "--domain", std::to_string(domain),
                                "--station", name, "--history", "off"};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

const ui::StationTile* tile_of(const ui::InstructorView& v, const std::string& name) {
  for (const ui::StationTile& t : v.stations)
    if (t.name == name) return &t;
  return nullptr;
}

// The window with two stations: A obeys unauthenticated commands on loopback, B obeys no
// instructor. Both are listed with their tiles (the scene of their shipped scenario, telemetry);
// the command pane's Apply bounds sends a ceiling of 0.3 to A, accepted; B refuses a pause
// (instructor not allowed) and A an empty marker (bad value), each shown with the reason.
TEST_F(InstructorWindow, TwoStationsACeilingAcceptedAndRefusalsShown) {
  const fs::path dir = test::fresh_path("instructor_window", "two_stations");
  fs::create_directories(dir);
  auto screen = std::make_unique<cli::Offscreen>();
  std::string error;
  if (!screen->open(1280, 720, error)) GTEST_SKIP() << "no EGL device: " << error;
  const std::uint32_t dom = domain_;
  Spawned a(station("A", dom, {"--instructor", "--allow-unauthenticated-commands"}), dir / "a.txt",
            user_dirs(dir));
  Spawned b(station("B", dom, {}), dir / "b.txt", user_dirs(dir));

  cli::InstructorAppOptions o;
  o.domain = dom;
  o.issuer = "window-test";
  o.answer_s = 60;  // a loaded or sanitized machine: the answer is waited for, never timed
  cli::InstructorApp app(o);
  ASSERT_TRUE(app.open(error)) << error;
  Driver d{*screen, [&] { app.build_frame(1.0 / 30.0); }};
  const auto frames_until = [&](auto done, double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done()) {
      if (std::chrono::steady_clock::now() > until) return false;
      d.frame();
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
    }
    return true;
  };
  // Both heard, with their telemetry and their scenario's scene.
  ASSERT_TRUE(frames_until([&] {
    const auto v = app.view();
    const ui::StationTile *ta = tile_of(*v, "A"), *tb = tile_of(*v, "B");
    return ta && tb && ta->telemetry && tb->telemetry && ta->state == "flying" &&
           tb->state == "flying" && ta->history && ta->history->size() > 5 && tb->history &&
           tb->history->size() > 5;
  }, 90)) << read_file(dir / "a.txt") << read_file(dir / "b.txt");
  d.frame();
  d.frame();
  EXPECT_TRUE(shown("##tile A"));
  EXPECT_TRUE(shown("##tile B"));
  {
    const auto v = app.view();
    const ui::StationTile& ta = *tile_of(*v, "A");
    EXPECT_EQ(ta.scenario, "mi_helix_endurance");
    EXPECT_EQ(ta.state, "flying");
    EXPECT_TRUE(ta.accepts_instructor);
    EXPECT_FALSE(tile_of(*v, "B")->accepts_instructor);
    ASSERT_TRUE(ta.scene) << ta.scene_note;  // the shipped scenario's arena, obstacles, reference
    EXPECT_GT(ta.scene->reference.cols(), 1);
    EXPECT_GT(ta.scene->ball_radius, 0.0);
    // The vehicle where the station flies it: inside the arena, near its reference.
    const Telemetry& s = ta.history->newest();
    EXPECT_TRUE((s.x.head<3>().array() >= ta.scene->arena_min.array() - 0.5).all() &&
                (s.x.head<3>().array() <= ta.scene->arena_max.array() + 0.5).all())
        << s.x.head<3>().transpose();
    ASSERT_EQ(s.reference.size(), 3);
    EXPECT_LT((s.x.head<3>() - s.reference).norm(), 1.0);
    EXPECT_GT(s.lambda, 0.0);
    EXPECT_LE(s.lambda, 1.0);
  }
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << p;
  save(*screen, "two");

  // Key 1: A, large; the ceiling's slider at 0.3, then its button clicked.
  d.key(ui::Key::digit1);
  EXPECT_EQ(app.ui_state().selected, "A");
  EXPECT_TRUE(app.ui_state().large);
  app.ui_state().draft.ceiling = 0.3f;
  const std::optional<ImVec2> apply = d.locate("##commands", "Apply bounds (Ctrl+B)");
  ASSERT_TRUE(apply);
  d.click(*apply);
  const auto newest = [&](const char* station) -> std::optional<ui::CommandRow> {
    const auto v = app.view();
    const ui::StationTile* t = tile_of(*v, station);
    if (!t || t->commands.empty()) return std::nullopt;
    return t->commands.back();
  };
  const auto answered = [&](const char* station) {
    return [&, station] {
      const auto c = newest(station);
      return c && c->outcome != ui::CommandOutcome::waiting_for_station &&
             c->outcome != ui::CommandOutcome::sent;
    };
  };
  ASSERT_TRUE(frames_until(answered("A"), 60));
  const ui::CommandRow ceiling = *newest("A");
  EXPECT_EQ(ceiling.what, "bounds: λ floor 0, ceiling 0.3");
  EXPECT_EQ(ceiling.outcome, ui::CommandOutcome::accepted) << ceiling.why;
  d.frame();  // a pane that grew shows its scrollbar from the next frame
  d.frame();
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << p;
  save(*screen, "accepted");
  // What the ceiling keeps in force shows on A's tile, once A flies with it (the slider's
  // float, as sent).
  ASSERT_TRUE(frames_until([&] {
    const ui::StationTile* t = tile_of(*app.view(), "A");
    return t && t->in_force.bounds == AuthorityBounds{0.0, double(0.3f)};
  }, 60));
  // Ctrl+G: a gust of 2 N (for its longest, so a loaded machine still sees it act), on A's tile
  // while it acts, with its force and time left.
  app.ui_state().draft.gust_s = float(kMaxCommandDuration);
  d.key(ui::Key::g, true);
  ASSERT_TRUE(frames_until([&] {
    const auto c = newest("A");
    return c && c->kind == InstructorCommandKind::gust && answered("A")();
  }, 60));
  EXPECT_EQ(newest("A")->outcome, ui::CommandOutcome::accepted) << newest("A")->why;
  ASSERT_TRUE(frames_until([&] {
    const ui::StationTile* t = tile_of(*app.view(), "A");
    return t && t->in_force.gust_left > 0.0;
  }, 60));
  {
    const ui::StationTile& ta = *tile_of(*app.view(), "A");
    EXPECT_EQ(ta.in_force.gust, Eigen::Vector3d(2.0, 0.0, 0.0));
    EXPECT_LE(ta.in_force.gust_left, kMaxCommandDuration);
    const std::vector<std::string> said = ui::tile_in_force(ta);
    ASSERT_EQ(said.size(), 2u);
    EXPECT_EQ(said[0], "instructor: ceiling 0.30");
    EXPECT_EQ(said[1].rfind("· gust 2.0 N, ", 0), 0u) << said[1];
  }
  d.frame();
  EXPECT_TRUE(shown("##in force A"));
  EXPECT_FALSE(shown("##in force B"));
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << p;
  save(*screen, "gust");

  // Ctrl+M with no text: A refuses it as a bad value, and the window says so.
  d.key(ui::Key::m, true);
  ASSERT_TRUE(frames_until([&] {
    const auto c = newest("A");
    return c && c->kind == InstructorCommandKind::marker && answered("A")();
  }, 60));
  const ui::CommandRow marker = *newest("A");
  EXPECT_EQ(marker.outcome, ui::CommandOutcome::refused);
  EXPECT_NE(marker.why.find("bad value"), std::string::npos) << marker.why;

  // Key 2: B; its Pause button: refused, B obeys no instructor.
  d.key(ui::Key::digit2);
  EXPECT_EQ(app.ui_state().selected, "B");
  const std::optional<ImVec2> pause = d.locate("##commands", "Pause (Ctrl+P)");
  ASSERT_TRUE(pause);
  d.click(*pause);
  ASSERT_TRUE(frames_until(answered("B"), 60));
  const ui::CommandRow refused = *newest("B");
  EXPECT_EQ(refused.what, "pause");
  EXPECT_EQ(refused.outcome, ui::CommandOutcome::refused);
  EXPECT_NE(refused.why.find("instructor not allowed"), std::string::npos) << refused.why;
  d.frame();
  d.frame();
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << p;
  save(*screen, "refused");
  EXPECT_EQ(app.asked(), 4u);

  // The same window at 150 %: nothing overlaps or is cut.
  screen.reset();
  cli::Offscreen big;
  ASSERT_TRUE(big.open(1280, 720, error, 1.5f)) << error;
  Driver d150{big, [&] { app.build_frame(1.0 / 30.0); }};
  d150.frame();
  d150.frame();
  d150.frame();
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << "150 %: " << p;
  save(big, "refused_150");

  a.interrupt();
  b.interrupt();
  ASSERT_GE(a.wait(60), 0);
  ASSERT_GE(b.wait(60), 0);
  const std::string sa = read_file(dir / "a.txt"), sb = read_file(dir / "b.txt");
  EXPECT_NE(sa.find("2 accepted, 1 refused (1 bad value)"), std::string::npos) << sa;
  EXPECT_NE(sb.find("0 accepted, 1 refused (1 instructor not allowed)"), std::string::npos) << sb;
}

}  // namespace
}  // namespace mixpilot::net
