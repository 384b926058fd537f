// A newcomer's first minutes in the window, through the headless renderer as a person uses it:
// the first launch's welcome and tour driven by the keyboard alone to a score card, shown only
// on a fresh machine and never again once done with; every key the window handles listed in
// the shortcut sheet's table; a tooltip on every control of every panel; the chase camera's
// first view clear of obstacles in every shipped scenario; the text size kept and laid out;
// READY showing what the flight starts with; window.toml's mutations.
// `ctest -R '(FirstLaunch|Onboarding)'`.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/stat.h>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "app/window_settings.hpp"
#include "core/history/history.hpp"
#include "ui/chase_camera.hpp"
#include "ui/first_launch.hpp"
#include "ui/shortcuts.hpp"

#include "app_window_test.hpp"
#include "record_flight.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
constexpr int kW = 1280, kH = 720;

std::string scenario(const std::string& name) {
  return std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + name;
}

// What `mixpilot fly` without options opens (app/fly.cpp): mi_helix, the first launch allowed.
cli::FlyOptions first_launch_options(double seconds) {
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  o.duration = seconds;
  o.first_launch = true;
  return o;
}

// The user's folders in a fresh place: no history, no window settings.
void fresh_user_dirs(const char* name) {
  const auto home = test::fresh_path("onboarding", name);
  fs::create_directories(home / "config");
  fs::create_directories(home / "data");
  setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
}

std::string window_toml() {
  return std::string(std::getenv("XDG_CONFIG_HOME")) + "/mixpilot/window.toml";
}

std::string slurp_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Saves the last frame as NAME.png in $MIXPILOT_SHOT_DIR when it is set.
void save_shot(const cli::Offscreen& screen, const std::string& name) {
  const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
  if (!dir || !*dir) return;
  std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen.png();
}

// A recording of `name` flown headless for `seconds` by the novice.
std::string record(const char* name, double seconds, const std::string& file) {
  cli::FlyOptions o;
  o.scenario_path = scenario(name);
  o.pilot = "novice";
  o.duration = seconds;
  const std::string path = test::fresh_path("onboarding", file).string();
  EXPECT_TRUE(test::record_flight(o, path));
  return path;
}

class FirstLaunch : public test::AppWindowTest {
 protected:
  void SetUp() override {
    std::string error;
    if (!screen_.open(kW, kH, error)) GTEST_SKIP() << "no EGL device: " << error;
  }
  // Frames until the welcome is decided (the history is read off the UI thread), at most
  // 10 s: whether it shows.
  bool welcome_shows(cli::Trainer& app) {
    EXPECT_TRUE(frames_until(app, [&] { return !app.welcome_undecided(); }, std::chrono::seconds(10)))
        << "the welcome was not decided within 10 s";
    frame(app);  // what the decision draws
    return app.ui_state().first_launch == ui::FirstLaunch::welcome;
  }
  bool window_shown(const char* name) {
    const ImGuiWindow* w = ImGui::FindWindowByName(name);
    return w && w->Active && !w->Hidden;
  }
};

// The same at 100 % and 150 % (laid out with nothing overlapping or cut, ui_layout.hpp).
class FirstLaunchAtScale : public FirstLaunch, public testing::WithParamInterface<float> {
 protected:
  void SetUp() override {
    std::string error;
    if (!screen_.open(kW, kH, error, GetParam())) GTEST_SKIP() << "no EGL device: " << error;
  }
  std::string at() const { return "_" + std::to_string(int(std::lround(100 * GetParam()))); }
  void check_layout(const char* state) {
    for (const std::string& p : test::layout_problems()) ADD_FAILURE() << state << at() << ": " << p;
  }
  static double skill_of(const cli::Trainer& app) {
    for (const auto& [name, value] : app.run_info().metrics)
      if (name == "skill") return value;
    return std::nan("");
  }
  // The pilot `name` picked in the session panel by keys alone (Tab, the arrows, Space); the
  // keyboard stays in the panels. "" done, else what went wrong.
  std::string pick_pilot_by_keys(cli::Trainer& app, const std::string& name) {
    const ui::SessionChoices& c = *app.run_info().session;
    const auto wanted = std::find(c.pilots.begin(), c.pilots.end(), name);
    if (wanted == c.pilots.end()) return "no pilot " + name;
    key(app, ui::Key::tab);
    frame(app);
    ImGuiContext& g = *GImGui;
    if (!app.ui_state().keyboard_in_panels || !g.NavWindow) return "Tab did not go into the panels";
    const ImGuiID box = g.NavWindow->GetID("pilot");
    for (int i = 0; i < 30 && g.NavId != box; ++i) key(app, ui::Key::down);
    if (g.NavId != box) return std::string("the arrows never reached the pilot box in ") + g.NavWindow->Name;
    // The list opens on the pilot flying now; the arrows move through it in order.
    const int steps = int(wanted - c.pilots.begin()) - app.run_info().session->pilot;
    key(app, ui::Key::space);
    if (!ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId)) return "Space did not open the list";
    for (int i = 0; i < std::abs(steps); ++i) key(app, steps > 0 ? ui::Key::down : ui::Key::up);
    key(app, ui::Key::space);
    frame(app);
    const ui::SessionChoices& now = *app.run_info().session;
    if (now.pilot < 0 || now.pilots[std::size_t(now.pilot)] != name)
      return "picked " + (now.pilot < 0 ? std::string("none") : now.pilots[std::size_t(now.pilot)]);
    return "";
  }
};

// A newcomer with the keyboard alone: the welcome shows, Space takes its first way in (watch the
// novice), Space steps through the tour's callouts, each pointing at what it names, the last
// one starts the flight, and the flight ends on its score card. Then a second flight, the
// experienced pilot picked in the session panel by keys, whose card shows the improvement
// since the first. The welcome was done with: it is kept in window.toml and a second start
// shows none.
TEST_P(FirstLaunchAtScale, TheKeyboardAloneGoesFromTheWelcomeToTwoFlightsAndTheImprovement) {
  fresh_user_dirs(("keyboard_only" + at()).c_str());
  {
    cli::Trainer app(first_launch_options(3.0));
    std::string error;
    int status = 0;
    ASSERT_TRUE(app.open_live(error, status)) << error;
    ASSERT_TRUE(welcome_shows(app));
    frame(app);
    frame(app);
    ASSERT_TRUE(window_shown(ui::kWelcomeWindow));
    EXPECT_TRUE(app.ui_state().keyboard_in_panels) << "the welcome takes the keyboard";
    check_layout("welcome");
    save_shot(screen_, "first_launch_welcome" + at());
    // Space presses the way in the keyboard is on: the first, watch the novice.
    key(app, ui::Key::space);
    frame(app);
    ASSERT_EQ(app.ui_state().first_launch, ui::FirstLaunch::tour);
    ASSERT_TRUE(app.live());
    EXPECT_EQ(app.live()->flight().pilot, "novice");
    EXPECT_EQ(app.run_info().state, ui::RunState::ready);
    const auto steps = ui::tour_steps();
    for (std::size_t i = 0; i < steps.size(); ++i) {
      frame(app);
      frame(app);
      ASSERT_EQ(app.ui_state().tour_step, int(i));
      ASSERT_TRUE(window_shown(ui::kTourWindow));
      // The callout points at something on screen that the last frame drew.
      const ui::TourMarks& m = app.ui_state().marks;
      const bool drawn = steps[i].target == ui::TourTarget::authority_bar ? m.bar_max.x > m.bar_min.x
                         : steps[i].target == ui::TourTarget::ball        ? m.ball_radius > 0
                         : steps[i].target == ui::TourTarget::sticks ? m.sticks_max.x > m.sticks_min.x
                                                                      : m.start_max.x > m.start_min.x;
      // The sticks show at READY where there is room for them beside the session panel (not
      // at 150 % of 1280x720): the callout then stands in the centre and says so.
      if (steps[i].target != ui::TourTarget::sticks || GetParam() == 1.0f) {
        EXPECT_TRUE(drawn) << "step " << i + 1 << " points at nothing: " << steps[i].title;
      }
      check_layout("tour");
      save_shot(screen_, "first_launch_tour_" + std::to_string(i + 1) + at());
      key(app, ui::Key::space);
    }
    EXPECT_EQ(app.ui_state().first_launch, ui::FirstLaunch::none);
    EXPECT_FALSE(app.ui_state().keyboard_in_panels) << "the keyboard is back on the flight";
    EXPECT_NE(slurp_text(window_toml()).find("welcome = \"dismissed\""), std::string::npos)
        << slurp_text(window_toml());
    until_over(app);
    ASSERT_TRUE(app.over());
    frame(app);
    frame(app);
    EXPECT_FALSE(app.run_info().metrics.empty());
    EXPECT_TRUE(window_shown("Score card")) << "no score card at the end of the first flight";
    save_shot(screen_, "first_launch_score_card" + at());
    const double first_skill = skill_of(app);
    ASSERT_TRUE(std::isfinite(first_skill));
    // The second flight, still by keys: Esc closes the card, Tab goes into the session panel,
    // Down to the pilot box, Space opens it, Down to the experienced pilot, Space picks it; Esc
    // back to the flight, Space starts it.
    key(app, ui::Key::escape);
    frame(app);
    EXPECT_FALSE(window_shown("Score card")) << "Esc did not close the card";
    ASSERT_EQ(pick_pilot_by_keys(app, "experienced"), "");
    key(app, ui::Key::escape);
    ASSERT_FALSE(app.ui_state().keyboard_in_panels);
    ASSERT_EQ(app.run_info().state, ui::RunState::ready);
    key(app, ui::Key::space);
    ASSERT_TRUE(app.live()->started());
    until_over(app);
    ASSERT_TRUE(app.over());
    // Its card, once the flight is in the history: the change since the first, a new best.
    ASSERT_TRUE(frames_until(app, [&] {
      const ui::ScoreCard* c = app.run_info().card;
      return c && c->comparison != ui::Comparison::reading;
    }));
    const ui::ScoreCard* card = app.run_info().card;
    ASSERT_EQ(card->comparison, ui::Comparison::compared) << card->note;
    const double second_skill = skill_of(app);
    EXPECT_GT(second_skill, first_skill) << "the experienced pilot's flight is the better one";
    EXPECT_NEAR(card->since_last, second_skill - first_skill, 1e-9);
    EXPECT_TRUE(card->new_best);
    EXPECT_NE(card->last_text.find(" since your last assisted flight ("), std::string::npos)
        << card->last_text;
    frame(app);
    frame(app);
    EXPECT_TRUE(window_shown("Score card"));
    check_layout("second card");
    save_shot(screen_, "first_launch_second_card" + at());
    std::printf("  skills %.1f then %.1f\n", first_skill, second_skill);
    EXPECT_EQ(app.finish(), 0);
  }
  cli::Trainer again(first_launch_options(1.0));
  std::string error;
  int status = 0;
  ASSERT_TRUE(again.open_live(error, status)) << error;
  EXPECT_FALSE(welcome_shows(again)) << "the welcome came back once done with";
}

INSTANTIATE_TEST_SUITE_P(Scales, FirstLaunchAtScale, testing::Values(1.0f, 1.5f));

// Ada's flight of mi_helix (skill 60) in the history of this test's user folders.
bool remember_a_flight() {
  std::string error;
  auto store = history::open_history("", error);
  EXPECT_TRUE(store) << error;
  if (!store) return false;
  history::FlightRecord f;
  f.trainee = "Ada";
  f.scenario = "mi_helix";
  f.mode = "mixed_initiative";
  f.front_end = "window";
  f.metrics = {{"skill", 60.0}};
  const bool added = store->add(f, error).has_value();
  EXPECT_TRUE(added) << error;
  return added;
}

// The welcome is a first launch's: not with a flight in the history, not once dismissed, not
// when the command line chose (first_launch off); a window.toml that cannot be written is said
// and costs nothing else.
TEST_F(FirstLaunch, ShowsOnlyOnAFreshMachine) {
  std::string error;
  int status = 0;
  {
    fresh_user_dirs("with_history");
    ASSERT_TRUE(remember_a_flight());
    cli::Trainer app(first_launch_options(1.0));
    ASSERT_TRUE(app.open_live(error, status)) << error;
    EXPECT_FALSE(welcome_shows(app)) << "a machine with a flight in its history is no first launch";
  }
  {
    fresh_user_dirs("dismissed");
    fs::create_directories(fs::path(window_toml()).parent_path());
    std::ofstream(window_toml()) << "welcome = \"dismissed\"\n";
    cli::Trainer app(first_launch_options(1.0));
    ASSERT_TRUE(app.open_live(error, status)) << error;
    EXPECT_FALSE(welcome_shows(app));
  }
  {
    fresh_user_dirs("chosen");
    cli::FlyOptions o = first_launch_options(1.0);
    o.first_launch = false;  // --scenario given, a script, a replay
    cli::Trainer app(o);
    ASSERT_TRUE(app.open_live(error, status)) << error;
    EXPECT_FALSE(welcome_shows(app));
  }
  {
    fresh_user_dirs("unwritable");
    // The config folder is a file: nothing can be saved there.
    const std::string config = std::getenv("XDG_CONFIG_HOME");
    fs::remove_all(config);
    std::ofstream(config) << "not a folder\n";
    cli::Trainer app(first_launch_options(1.0));
    ASSERT_TRUE(app.open_live(error, status)) << error;
    ASSERT_TRUE(welcome_shows(app));
    key(app, ui::Key::escape);  // not now
    frame(app);
    EXPECT_EQ(app.ui_state().first_launch, ui::FirstLaunch::none);
    EXPECT_TRUE(app.run_info().message_is_error);
    EXPECT_NE(app.run_info().message.find("could not keep that the welcome was seen"),
              std::string::npos)
        << app.run_info().message;
    save_shot(screen_, "first_launch_unwritable");
    // The flight flies all the same.
    app.start();
    until_over(app);
    EXPECT_TRUE(app.over());
    EXPECT_EQ(app.finish(), 0);
  }
}

// window.toml mutated as the scenario files are (tests/mutate_scenarios.py): each key missing,
// of another type, 0, negative, tiny, huge, nan, ±inf, integer limits, an empty or unknown
// string; unknown keys, tables, a key twice, deep nesting, binary bytes, an empty file; not a
// file (a folder, a FIFO, a device). Each read gives valid settings: the file's, or the
// defaults with a note that names the file and, for its content, the line and column. What it
// accepts it writes back as it read it.
TEST(OnboardingWindowSettings, EveryMutationGivesValidSettingsOrTheDefaultsAndWhere) {
  const fs::path dir = test::fresh_path("onboarding", "window_mutations");
  fs::create_directories(dir);
  const std::string path = (dir / "window.toml").string();
  std::string error;
  ASSERT_TRUE(cli::save_window_settings(path, cli::WindowSettings{1.25f, true}, error)) << error;
  const std::string base = slurp_text(path);
  const std::vector<std::string> lines = [&] {
    std::vector<std::string> v;
    std::stringstream in(base);
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
  }();
  ASSERT_EQ(lines.size(), 3u) << base;
  const auto joined = [](const std::vector<std::string>& v) {
    std::string t;
    for (const std::string& l : v) t += l + "\n";
    return t;
  };
  std::string nested;
  for (int i = 0; i < 33; ++i) nested += "a.";
  std::vector<std::pair<std::string, std::string>> variants = {
      {"empty", ""},
      {"unknown key", base + "colour = \"blue\"\n"},
      {"a table", base + "[text_scale]\nx = 1\n"},
      {"key twice", base + "text_scale = 2.0\n"},
      {"nested 33", base + nested + "b = 1\n"},
      {"nested array 50000", base + "x = " + std::string(50000, '[') + "\n"},
      {"binary", base + std::string("\x00\x01\xff\n", 4)},
      {"no newline at the end", base.substr(0, base.size() - 1)},
      {"a long comment", base + "# " + std::string(1 << 20, 'x') + "\n"},
  };
  const std::vector<const char*> numbers = {
      "0", "-1.5", "-1", "1e-300", "1e300", "nan", "inf", "-inf", "2147483647", "-2147483648",
      "9223372036854775807", "1", "0.5", "3", "3.0000001", "\"text\"", "true", "[1.0]", "{ x = 1 }"};
  const std::vector<const char*> strings = {"1", "\"\"", "\"no such thing\"", "\"Dismissed\"",
                                            "\"show\"", "true", "[\"dismissed\"]"};
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::string key = lines[i].substr(0, lines[i].find(' '));
    std::vector<std::string> v = lines;
    v.erase(v.begin() + std::ptrdiff_t(i));
    variants.emplace_back(key + " missing", joined(v));
    for (const char* value : key == "text_scale" ? numbers : strings) {
      v = lines;
      v[i] = key + " = " + value;
      variants.emplace_back(key + " = " + value, joined(v));
    }
  }
  int accepted = 0, refused = 0;
  for (const auto& [label, text] : variants) {
    SCOPED_TRACE(label);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
    std::string note;
    const cli::WindowSettings s = cli::load_window_settings(path, note);
    ASSERT_TRUE(std::isfinite(s.text_scale));
    EXPECT_GE(s.text_scale, cli::kMinTextScale);
    EXPECT_LE(s.text_scale, cli::kMaxTextScale);
    if (note.empty()) {
      ++accepted;
      // Written back and read again: the same settings.
      ASSERT_TRUE(cli::save_window_settings(path, s, error)) << error;
      std::string again_note;
      const cli::WindowSettings again = cli::load_window_settings(path, again_note);
      EXPECT_EQ(again_note, "");
      EXPECT_EQ(again.text_scale, s.text_scale);
      EXPECT_EQ(again.welcome_dismissed, s.welcome_dismissed);
    } else {
      ++refused;
      const cli::WindowSettings defaults;
      EXPECT_EQ(s.text_scale, defaults.text_scale);
      EXPECT_EQ(s.welcome_dismissed, defaults.welcome_dismissed);
      // FILE:LINE:COL: what was expected; the window's defaults are used.
      EXPECT_EQ(note.rfind(path + ":", 0), 0u) << note;
      const std::string rest = note.substr(path.size() + 1);
      const std::size_t colon = rest.find(':');
      ASSERT_NE(colon, std::string::npos) << note;
      EXPECT_GT(std::atoi(rest.c_str()), 0) << note;
      EXPECT_GT(std::atoi(rest.c_str() + colon + 1), 0) << note;
      EXPECT_NE(note.find("; the window's defaults are used"), std::string::npos) << note;
      EXPECT_EQ(note.find('\n'), std::string::npos) << "one line: " << note;
    }
  }
  EXPECT_GT(accepted, 5);
  EXPECT_GT(refused, 20);
  std::printf("  window.toml: %zu variants, %d accepted, %d refused with where\n", variants.size(),
              accepted, refused);
  // Not a file: said without a line, the defaults used.
  const auto not_a_file = [&](const std::string& p, const char* what) {
    SCOPED_TRACE(what);
    std::string note;
    const cli::WindowSettings s = cli::load_window_settings(p, note);
    EXPECT_EQ(s.text_scale, 1.0f);
    EXPECT_FALSE(s.welcome_dismissed);
    EXPECT_NE(note.find(p + ": not a settings file"), std::string::npos) << note;
  };
  fs::create_directories(dir / "folder");
  not_a_file((dir / "folder").string(), "a folder");
  ASSERT_EQ(mkfifo((dir / "fifo").c_str(), 0600), 0);
  not_a_file((dir / "fifo").string(), "a FIFO");
  fs::create_symlink("/dev/zero", dir / "device");
  not_a_file((dir / "device").string(), "a device");
  // Missing, or a dangling link: no file, the defaults without a word.
  fs::create_symlink(dir / "nowhere", dir / "dangling");
  for (const char* name : {"missing", "dangling"}) {
    std::string note;
    const cli::WindowSettings s = cli::load_window_settings((dir / name).string(), note);
    EXPECT_EQ(note, "") << name;
    EXPECT_EQ(s.text_scale, 1.0f) << name;
  }
}

// The three ways in, by their keys: 1 the novice, 2 the person (the keyboard, no gamepad here),
// 3 the beginner course under the name typed; F1's sheet shows the welcome again.
TEST_F(FirstLaunch, EachWayInAndTheWelcomeAgain) {
  std::string error;
  int status = 0;
  const auto welcome = [&](cli::Trainer& app) {
    ui::show_welcome(app.ui_state());
    frame(app);
    frame(app);
  };
  fresh_user_dirs("ways");
  cli::Trainer app(first_launch_options(1.0));
  ASSERT_TRUE(app.open_live(error, status)) << error;
  ASSERT_TRUE(welcome_shows(app));
  key(app, ui::Key::digit2);
  frame(app);
  EXPECT_EQ(app.live()->flight().pilot, "keyboard");
  EXPECT_EQ(app.ui_state().first_launch, ui::FirstLaunch::tour);
  welcome(app);
  key(app, ui::Key::digit1);
  frame(app);
  EXPECT_EQ(app.live()->flight().pilot, "novice");
  welcome(app);
  std::snprintf(app.ui_state().course_trainee, sizeof app.ui_state().course_trainee, "Ada");
  key(app, ui::Key::digit3);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline &&
         !(app.live()->flight().lesson.active())) {
    frame(app);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(app.live()->flight().lesson.active()) << "no lesson step READY";
  EXPECT_EQ(app.live()->flight().lesson.lesson, "beginner");
  EXPECT_EQ(app.run_info().session->trainee, "Ada");
  frame(app);
  save_shot(screen_, "first_launch_course_tour");
  key(app, ui::Key::escape);  // skip the tour
  EXPECT_EQ(app.ui_state().first_launch, ui::FirstLaunch::none);
  // F1, then its button: the welcome again.
  key(app, ui::Key::f1);
  ASSERT_TRUE(app.ui_state().show_help);
  const auto again = locate(app, ui::kHelpWindow, "Show the welcome again");
  ASSERT_TRUE(again);
  click(app, *again);
  EXPECT_EQ(app.ui_state().first_launch, ui::FirstLaunch::welcome);
  EXPECT_FALSE(app.ui_state().show_help);
}

// ---- Onboarding: the keys, the tooltips, the camera, the text size, READY ------------------

class Onboarding : public test::AppWindowTest {
 protected:
  void SetUp() override {
    std::string error;
    if (!screen_.open(kW, kH, error)) GTEST_SKIP() << "no EGL device: " << error;
  }
};

// What the UI's state says that a key can change (besides the requests it makes).
std::string fingerprint(const ui::UiState& u) {
  std::ostringstream s;
  s << int(u.camera) << u.show_sticks << u.show_help << u.show_debrief << u.show_progress
    << u.plots_paused << u.open_dialog.open << u.show_settings << u.score_card_closed
    << u.keyboard_in_panels << int(u.first_launch) << u.tour_step;
  return s.str();
}

bool is_modifier(ui::Key k) { return k >= ui::Key::left_shift && k < ui::Key::count; }

// Every key the window acts on, in every state a person meets it in (a live flight READY with
// the novice and with the keyboard flying, the sheet open, a replay, the welcome), with and
// without Ctrl, is a row of the table the sheet lists (or, while the keyboard is in the panels,
// one of ImGui's navigation keys the Tab row names); and every row acts somewhere. Each row's
// key is named on its sheet line.
TEST_F(Onboarding, EveryKeyTheWindowHandlesIsInTheSheet) {
  fresh_user_dirs("keys");
  const std::string rec = record("mi_helix.toml", 2.0, "keys.mcap");
  std::string error;
  int status = 0;
  cli::FlyOptions novice;
  novice.scenario_path = scenario("mi_helix.toml");
  novice.duration = 2.0;
  cli::Trainer live(novice);
  ASSERT_TRUE(live.open_live(error, status)) << error;
  cli::FlyOptions kb = novice;
  kb.pilot = "keyboard";
  cli::Trainer keyboard(kb);
  ASSERT_TRUE(keyboard.open_live(error, status)) << error;
  cli::FlyOptions ro;
  ro.replay = true;
  ro.pilot = rec;
  cli::Trainer replay(ro);
  ASSERT_TRUE(replay.open_replay(rec, error)) << error;
  replay.load_replay();
  replay.seek(1.0);

  struct State {
    const char* name;
    cli::Trainer* app;
    void (*prepare)(ui::UiState&);
  };
  const State states[] = {
      {"ready, novice", &live, [](ui::UiState&) {}},
      {"ready, keyboard", &keyboard, [](ui::UiState&) {}},
      {"sheet open, top camera", &live,
       [](ui::UiState& u) {
         u.show_help = true;
         u.camera = ui::Camera::top;
       }},
      {"replay", &replay, [](ui::UiState&) {}},
      {"welcome", &live, [](ui::UiState& u) { ui::show_welcome(u); }},
  };
  std::set<std::size_t> rows_acted;
  const auto table = ui::shortcuts();
  for (const State& st : states) {
    SCOPED_TRACE(st.name);
    cli::Trainer& app = *st.app;
    for (int i = 0; i < 3; ++i) frame(app);  // the scene and history up to date
    const ui::Scene& scene = app.replaying() ? app.replay()->scene() : app.live()->scene;
    const ui::History history =
        app.replaying() ? ui::History::view(app.replay()->tape(), app.replay()->tape().size() / 2)
                        : app.live()->history;
    const ui::RunInfo run = app.run_info();
    ui::UiState base = app.ui_state();
    st.prepare(base);
    ui::Requests out;
    const auto draw = [&](ui::UiState& u) {
      screen_.layout([&] { ui::draw_screen(scene, history, run, u, out); }, 1e-4f);
    };
    for (int i = 0; i < 3; ++i) {  // the panels laid out, the keyboard's focus given
      ui::UiState u = base;
      draw(u);
      base.focus_panels = u.focus_panels;
      base.keyboard_in_panels = u.keyboard_in_panels;
    }
    const unsigned now = ui::key_context(run, base);
    for (int k = 0; k < int(ui::Key::count); ++k) {
      const auto key = ui::Key(k);
      if (is_modifier(key)) continue;
      for (const bool ctrl : {false, true}) {
        ImGuiIO& io = ImGui::GetIO();
        ui::UiState u = base;
        out.clear();
        io.KeyCtrl = ctrl;
        ui::set_key(io, key, true);
        draw(u);
        ui::set_key(io, key, false);
        io.KeyCtrl = false;
        bool acted = fingerprint(u) != fingerprint(base);
        for (const ui::Request& r : out) {
          const auto* l = std::get_if<ui::LiveRequest>(&r);
          const auto* held = l ? std::get_if<ui::HeldFlightKeys>(l) : nullptr;
          if (!held || held->keys != 0) acted = true;
        }
        for (int i = 0; i < 2; ++i) {  // released; whatever opened closes again
          ui::UiState settle = base;
          draw(settle);
        }
        if (!acted) continue;
        const std::string what = std::string(ctrl ? "Ctrl+" : "") + ui::key_name(key) + " (key " +
                                 std::to_string(k) + ")";
        bool listed = false;
        for (std::size_t i = 0; i < table.size(); ++i) {
          const ui::Shortcut& s = table[i];
          const bool mod = s.mod == ui::Mod::any || (s.mod == ui::Mod::ctrl) == ctrl;
          constexpr unsigned kFlights = ui::kLive | ui::kReplay | ui::kWelcome;
          const unsigned conditions = s.when & ~kFlights;
          if (s.key == key && mod && (s.when & now & kFlights) && (now & conditions) == conditions) {
            listed = true;
            rows_acted.insert(i);
          }
        }
        if (!listed && base.keyboard_in_panels &&
            std::find(std::begin(ui::kPanelKeys), std::end(ui::kPanelKeys), key) !=
                std::end(ui::kPanelKeys))
          listed = true;
        EXPECT_TRUE(listed) << what << " acts but the sheet does not list it";
      }
    }
  }
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_TRUE(rows_acted.count(i)) << "the row of " << ui::key_name(table[i].key)
                                     << " does nothing in any state";
    // Its sheet line (its own, or the one above that covers it) names its key.
    std::size_t line = i;
    while (line > 0 && !table[line].keys) --line;
    ASSERT_TRUE(table[line].keys);
    const std::string keys = table[line].keys;
    std::string name = ui::key_name(table[i].key);
    EXPECT_NE(keys.find(name), std::string::npos) << "'" << keys << "' does not name " << name;
  }
}

// Every control of every panel has a tooltip: in each state a newcomer meets, the mouse goes
// over every window, and every item ImGui says it hovers (a button, a box, a slider, a list, a
// field; not the windows' own close buttons and scroll bars) brings up a tooltip window.
TEST_F(Onboarding, EveryControlHasATooltip) {
  fresh_user_dirs("tooltips");
  ASSERT_TRUE(remember_a_flight());
  const std::string rec = record("mi_helix.toml", 2.0, "tips.mcap");
  std::vector<std::string> missing;
  int items = 0;
  const auto scan = [&](cli::Trainer& app, const std::string& state) {
    for (int i = 0; i < 3; ++i) frame(app, 0.0);
    save_shot(screen_, "tooltips_" + state);
    ImGuiContext& g = *GImGui;
    struct Area {
      std::string name;
      ImRect rect;
    };
    std::vector<Area> areas;
    std::set<ImGuiID> decorations;
    for (ImGuiWindow* w : g.Windows) {
      if (!w->Active || w->Hidden) continue;
      if (w->Flags & (ImGuiWindowFlags_Tooltip | ImGuiWindowFlags_NoInputs)) continue;
      for (const char* d : {"#CLOSE", "#COLLAPSE"}) decorations.insert(w->GetID(d));
      decorations.insert(ImGui::GetWindowScrollbarID(w, ImGuiAxis_X));
      decorations.insert(ImGui::GetWindowScrollbarID(w, ImGuiAxis_Y));
      for (int n = 0; n < 4; ++n) decorations.insert(ImGui::GetWindowResizeCornerID(w, n));
      for (const ImGuiDir dir : {ImGuiDir_Left, ImGuiDir_Right, ImGuiDir_Up, ImGuiDir_Down})
        decorations.insert(ImGui::GetWindowResizeBorderID(w, dir));
      if (!(w->Flags & ImGuiWindowFlags_ChildWindow) && std::string(w->Name) != "##view")
        areas.push_back({w->Name, w->Rect()});
    }
    std::set<ImGuiID> seen;
    const float step = std::max(4.0f, 0.5f * ImGui::GetFrameHeight());
    for (const Area& a : areas) {
      for (float y = a.rect.Min.y + 1; y < a.rect.Max.y; y += step) {
        for (float x = a.rect.Min.x + 1; x < a.rect.Max.x; x += step) {
          ImGui::GetIO().MousePos = ImVec2(x, y);
          screen_.layout([&] { app.build_frame(0.0); }, 1e-4f);
          const ImGuiID id = g.HoveredId;
          if (!id || decorations.count(id) || !seen.insert(id).second) continue;
          ++items;
          bool tip = false;
          for (ImGuiWindow* w : g.Windows)
            tip = tip || (w->Active && (w->Flags & ImGuiWindowFlags_Tooltip) &&
                          w->DC.CursorMaxPos.x > w->DC.CursorStartPos.x);
          if (!tip) {
            char at[64];
            std::snprintf(at, sizeof at, " at (%.0f, %.0f)", double(x), double(y));
            missing.push_back(state + ": an item of " + a.name + at);
          }
        }
      }
    }
    ImGui::GetIO().MousePos = ImVec2(-1, -1);
    frame(app, 0.0);
  };
  std::string error;
  int status = 0;
  {
    cli::FlyOptions o = first_launch_options(1.0);
    o.first_launch = false;
    o.pilot = "keyboard";
    cli::Trainer app(o);
    ASSERT_TRUE(app.open_live(error, status)) << error;
    app.act(ui::LiveRequest{ui::SetTrainee{"Ada"}});
    for (int i = 0; i < 30 && !(app.run_info().history && app.run_info().history->loaded); ++i) {
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    scan(app, "ready");
    key(app, ui::Key::f1);
    scan(app, "help");
    key(app, ui::Key::escape);
    key(app, ui::Key::h);
    scan(app, "progress");
    key(app, ui::Key::escape);
    key(app, ui::Key::i);
    scan(app, "settings");
    key(app, ui::Key::i);
    key(app, ui::Key::o, true);
    frame(app);
    scan(app, "open");
    app.ui_state().open_dialog.open = false;
    frame(app);
    ui::show_welcome(app.ui_state());
    scan(app, "welcome");
    key(app, ui::Key::digit2);
    scan(app, "tour");
    key(app, ui::Key::escape);
    app.start();
    frame(app);
    scan(app, "flying");
    until_over(app);
    scan(app, "finished");
  }
  {
    cli::FlyOptions o;
    o.replay = true;
    o.pilot = rec;
    cli::Trainer app(o);
    ASSERT_TRUE(app.open_replay(rec, error)) << error;
    app.load_replay();
    app.seek(1.0);
    scan(app, "replay");
  }
  std::printf("%d controls hovered\n", items);
  EXPECT_GT(items, 40) << "the scan found hardly any controls";
  for (const std::string& m : missing) ADD_FAILURE() << m << " has no tooltip";
}

// READY's first view: in every shipped scenario with an arena, the chase camera sees the vehicle
// with no obstacle in between (mi_helix's central column stood in front of it), and the window
// at READY uses that camera.
TEST_F(Onboarding, TheChaseCameraAtReadySeesTheVehicle) {
  fresh_user_dirs("chase");
  int arenas = 0, turned = 0;
  for (const auto& entry : fs::directory_iterator(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios")) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().filename().string());
    cli::FlyOptions o;
    o.scenario_path = entry.path().string();
    std::string error;
    int status = 0;
    auto rig = cli::FlightRig::assemble(o, error, status);
    ASSERT_TRUE(rig) << error;
    const ui::Scene sc = ui::scene_of(rig->mode(), "test");
    if (sc.view != ViewKind::arena_3d) continue;
    ++arenas;
    const Telemetry s = rig->mode().telemetry();
    ASSERT_GE(s.x.size(), 3);
    const ui::ChasePose pose = ui::clear_chase_pose(sc, s);
    turned += pose.turn != 0.0 || pose.rise != 0.0;
    EXPECT_FALSE(ui::sight_blocked(sc, s, ui::chase_eye(s, pose)))
        << "an obstacle between the chase camera and the vehicle (turned " << pose.turn
        << " rad, raised " << pose.rise << " m)";
  }
  EXPECT_GE(arenas, 8);
  EXPECT_GE(turned, 1) << "no scenario needed the camera turned: the test tests nothing";
  // The window at READY turns its chase camera so.
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  cli::Trainer app(o);
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  frame(app);
  const ui::Scene& sc = app.live()->scene;
  const Telemetry& s = app.live()->history.newest();
  EXPECT_TRUE(ui::sight_blocked(sc, s, ui::chase_eye(s, {}))) << "mi_helix opens clear anyway";
  const ui::ChasePose pose = ui::clear_chase_pose(sc, s);
  EXPECT_EQ(app.ui_state().chase_turn, pose.turn);
  EXPECT_EQ(app.ui_state().chase_rise, pose.rise);
  save_shot(screen_, "chase_ready");
}

// The text size: Ctrl+= makes it larger, kept in window.toml and read by the next start; laid
// out at 150 % times 1.25 nothing overlaps or is cut.
TEST_F(Onboarding, TheTextSizeIsKeptAndLaidOut) {
  fresh_user_dirs("text_size");
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  std::string error;
  int status = 0;
  {
    cli::Trainer app(o);
    ASSERT_TRUE(app.open_live(error, status)) << error;
    frame(app);
    EXPECT_EQ(app.text_scale(), 1.0f);
    key(app, ui::Key::equal, true);
    EXPECT_FLOAT_EQ(app.text_scale(), 1.1f);
    key(app, ui::Key::equal, true);
    EXPECT_FLOAT_EQ(app.text_scale(), 1.25f);
    EXPECT_NE(slurp_text(window_toml()).find("text_scale = 1.25"), std::string::npos)
        << slurp_text(window_toml());
  }
  cli::Trainer app(o);
  ASSERT_TRUE(app.open_live(error, status)) << error;
  EXPECT_FLOAT_EQ(app.text_scale(), 1.25f);
  screen_.rescale(1.5f * app.text_scale());
  for (int i = 0; i < 4; ++i) frame(app, 0.0);
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << p;
  key(app, ui::Key::f1);
  frame(app, 0.0);
  for (const std::string& p : test::layout_problems()) ADD_FAILURE() << "sheet: " << p;
  save_shot(screen_, "text_scale_150x125_help");
  // A broken value gives the default and says where.
  std::ofstream(window_toml()) << "text_scale = 9\n";
  cli::Trainer broken(o);
  ASSERT_TRUE(broken.open_live(error, status)) << error;
  EXPECT_EQ(broken.text_scale(), 1.0f);
  frame(broken);
  EXPECT_NE(broken.run_info().message.find("window.toml:1:14: text_scale: expected a number from "
                                           "0.5 to 3"),
            std::string::npos)
      << broken.run_info().message;
}

// Keyboard-only panels: Tab puts the keyboard into the panels (the flight keys stop), the
// arrows and Space work the session panel's controls, Esc gives it back to the flight.
TEST_F(Onboarding, TabTakesTheKeyboardIntoThePanelsAndEscBack) {
  fresh_user_dirs("panels");
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  o.duration = 2.0;
  cli::Trainer app(o);
  std::string error;
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  frame(app);
  key(app, ui::Key::tab);
  frame(app);
  frame(app);
  EXPECT_TRUE(app.ui_state().keyboard_in_panels);
  ImGuiContext& g = *GImGui;
  ASSERT_TRUE(g.NavWindow);
  EXPECT_STREQ(g.NavWindow->Name, "Session");
  // 2 would be the orbit camera: in the panels it is nothing.
  key(app, ui::Key::digit2);
  EXPECT_EQ(app.ui_state().camera, ui::Camera::chase);
  // Down through the panel's controls to the record box, Space ticks it.
  const bool was = app.run_info().session->record;
  bool ticked = false;
  for (int i = 0; i < 30 && !ticked; ++i) {
    key(app, ui::Key::down);
    if (g.NavId == g.NavWindow->GetID("record (Ctrl+R)")) {
      key(app, ui::Key::space);
      frame(app);
      ticked = app.run_info().session->record != was;
    }
  }
  EXPECT_TRUE(ticked) << "the arrows never reached the record box, or Space did not tick it";
  save_shot(screen_, "keyboard_in_panels");
  EXPECT_EQ(app.run_info().state, ui::RunState::ready) << "Space in the panels started the flight";
  key(app, ui::Key::escape);
  EXPECT_FALSE(app.ui_state().keyboard_in_panels);
  key(app, ui::Key::digit2);
  EXPECT_EQ(app.ui_state().camera, ui::Camera::orbit);
  key(app, ui::Key::space);
  frame(app);
  EXPECT_NE(app.run_info().state, ui::RunState::ready) << "Space no longer starts the flight";
}

// READY shows what the flight will start with: the authority bar's λ, the λ plot's newest value
// and the first step's λ agree, and so do the status pill and the time.
TEST_F(Onboarding, ReadyShowsWhatTheFlightStartsWith) {
  fresh_user_dirs("ready");
  for (const double ceiling : {1.0, 0.4}) {
    SCOPED_TRACE("ceiling " + std::to_string(ceiling));
    cli::FlyOptions o;
    o.scenario_path = scenario("mi_helix.toml");
    o.pilot = "novice";
    o.bounds.ceiling = ceiling;
    cli::Trainer app(o);
    std::string error;
    int status = 0;
    ASSERT_TRUE(app.open_live(error, status)) << error;
    frame(app);
    frame(app);
    ASSERT_EQ(app.run_info().state, ui::RunState::ready);
    const ui::History& h = app.live()->history;
    ASSERT_EQ(h.size(), 1u);
    const double shown = h.newest().lambda;
    EXPECT_EQ(h.newest().t, 0.0);
    // The first step of the same flight, headless.
    auto rig = cli::FlightRig::assemble(o, error, status);
    ASSERT_TRUE(rig) << error;
    rig->start();
    ASSERT_TRUE(rig->step());
    const double first = rig->mode().telemetry().lambda;
    EXPECT_NEAR(shown, first, 1e-12) << "READY shows λ " << shown << ", the first step flies "
                                     << first;
    EXPECT_LE(shown, ceiling);
    save_shot(screen_, "ready_ceiling_" + std::to_string(int(100 * ceiling)));
  }
}

}  // namespace
}  // namespace mixpilot
