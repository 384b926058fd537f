// Fly from here (SPEC §10) through the window's code (app/trainer.hpp, rendered headless with
// EGL, driven by clicks, keys and the requests the panels make): a replay's moment is made ready
// off the UI thread and becomes a live flight, READY there; the trainee's pilot — an emulated
// profile, the keyboard, a gamepad — flies it on; its recording names its parent and starts at
// the parent's state; its history row is a branch; `score`, `fly --pilot` and the history's
// listings read it. A branch whose parent is gone is a clear error everywhere.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/offscreen.hpp"
#include "app/take_over.hpp"
#include "app/trainer.hpp"
#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"
#include "core/recording/branch_replay.hpp"
#include "core/recording/replay.hpp"

#include "run_mixpilot.hpp"
#include "app_window_test.hpp"
#include "record_flight.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 1280, kH = 720;

std::string scenario(const char* name) {
  return std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + name;
}

// A recording of mi_helix flown headless by `pilot` for `seconds` (`assist` off: a probe).
std::string record(double seconds, const char* pilot, const std::string& file,
                   Assistance assist = Assistance::on) {
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  o.pilot = pilot;
  o.duration = seconds;
  o.assist = assist;
  const std::string path = test::fresh_path("fly_from_here_app", file).string();
  EXPECT_TRUE(test::record_flight(o, path));
  return path;
}

// The user's folders of this test (its history, recordings and settings), never the machine's.
fs::path fresh_user_dirs(const char* name) {
  const fs::path home = test::fresh_path("fly_from_here_app", name);
  fs::create_directories(home);
  setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
  return home;
}

RecordingContents read(const std::string& path) {
  std::string error;
  std::optional<RecordingContents> rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  return rec ? std::move(*rec) : RecordingContents{};
}

// The recording at `path` replayed as `score` replays it (FlightRig): "" when bit for bit.
std::string replay_difference(const std::string& path) {
  cli::FlyOptions o;
  o.pilot = path;
  o.replay = true;
  std::string error;
  int status = 0;
  auto rig = cli::FlightRig::assemble(o, error, status);
  if (!rig) return "not replayed: " + error;
  rig->start();
  while (rig->step()) {
  }
  return rig->replay_difference();
}

// The newest recording in the user's recordings folder.
std::string newest_recording() {
  const fs::path dir = fs::path(std::getenv("XDG_DATA_HOME")) / "mixpilot" / "recordings";
  std::string newest;
  fs::file_time_type when{};
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".mcap" && (newest.empty() || e.last_write_time() > when)) {
      newest = e.path().string();
      when = e.last_write_time();
    }
  return newest;
}

void save_shot(const cli::Offscreen& screen, const std::string& name) {
  const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
  if (!dir || !*dir) return;
  std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen.png();
}

class FlyFromHereApp : public test::AppWindowTest {
 protected:
  void SetUp() override {
    fresh_user_dirs("default");
    std::string error;
    if (!screen_.open(kW, kH, error, scale())) GTEST_SKIP() << "no EGL device: " << error;
  }
  virtual float scale() const { return 1.0f; }

  // Frames while the moment is made ready: how many, the longest, and the wall time.
  struct Waited {
    int frames = 0;
    double longest_s = 0.0, total_s = 0.0;
  };
  Waited until_ready(cli::Trainer& app) {
    Waited w;
    const auto t0 = std::chrono::steady_clock::now();
    const auto deadline = t0 + std::chrono::seconds(60);
    while (app.taking_over() && std::chrono::steady_clock::now() < deadline) {
      w.longest_s = std::max(w.longest_s, frame(app));
      ++w.frames;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    w.total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    frame(app);
    return w;
  }
  void until_over(cli::Trainer& app) { AppWindowTest::until_over(app, std::chrono::seconds(90)); }
  // A replay of `parent` in the window, its playhead at `t`, taken over with the button in the
  // transport; READY at that moment once the app has made it ready.
  void take_over(cli::Trainer& app, const std::string& parent, double t, Waited* waited = nullptr) {
    std::string error;
    ASSERT_TRUE(app.open_replay(parent, error)) << error;
    app.load_replay();
    app.seek(t);
    frame(app);
    frame(app);
    ASSERT_TRUE(app.run_info().replay && app.run_info().replay->can_fly_from_here);
    save_shot(screen_, std::string("fly_from_here_replay") + (scale() > 1.0f ? "_150" : ""));
    const auto button = locate(app, "##transport", "Fly from here (T)");
    ASSERT_TRUE(button) << "no Fly from here button in the replay's transport";
    click(app, *button);
    ASSERT_TRUE(app.taking_over() || !app.replaying()) << "the click took nothing over";
    const Waited w = until_ready(app);
    if (waited) *waited = w;
    ASSERT_FALSE(app.replaying()) << app.run_info().message;
    ASSERT_TRUE(app.live());
    EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  }
  // The session panel's pick of the pilot `name` (the request its combo makes).
  void pick_pilot(cli::Trainer& app, const std::string& name) {
    const ui::SessionChoices& c = *app.run_info().session;
    const auto it = std::find(c.pilots.begin(), c.pilots.end(), name);
    ASSERT_NE(it, c.pilots.end()) << name << " is no pilot of the session panel";
    app.act(ui::PickPilot{int(it - c.pilots.begin())});
    frame(app);
    ASSERT_EQ(app.live()->flight().pilot, name);
    EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  }

};

// The motivating case: a novice's recording of mi_helix replayed in the window, taken over at
// 10 s with the experienced pilot. The moment is made ready off the UI thread (frames go on
// meanwhile); the window is READY at the moment, showing the novice's path that led there;
// Space starts; the flight completes; its recording's first step is the novice's step at 10 s
// and it names its parent; the history holds it as a branch of the novice's flight; `score` and
// `fly --pilot` replay it exactly, with the live score; the history's listings show the link.
TEST_F(FlyFromHereApp, TakeOverANovicesFlightAt10sWithTheExperiencedPilot) {
  const fs::path home = fresh_user_dirs("experienced");
  constexpr double kSeconds = 12.0, kAt = 10.0;
  const std::string parent = record(kSeconds, "novice", "novice.mcap");
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = parent;
  cli::Trainer app(o);
  Waited waited;
  take_over(app, parent, kAt, &waited);
  ASSERT_FALSE(HasFatalFailure());
  const std::int64_t k = std::int64_t(std::floor(kAt / 0.015 + 1e-9));  // the playhead's step
  std::printf("  the moment at t = %.3f s (step %lld) was ready in %.2f s; %d frames meanwhile, "
              "the longest %.1f ms\n",
              double(k) * 0.015, static_cast<long long>(k), waited.total_s, waited.frames,
              1e3 * waited.longest_s);
  EXPECT_GT(waited.frames, 0) << "the window froze while the moment was made ready";
  // READY at the moment: the screen shows the novice's step k, and the path before it.
  EXPECT_NEAR(app.shown_time(), double(k) * 0.015, 1e-9);
  EXPECT_GT(app.live()->history.size(), 600u) << "the novice's path so far is not shown";
  const std::size_t waited_history = app.live()->history.size();
  EXPECT_NE(app.run_info().session->fly_from.find("from novice.mcap at t = 9.99 s"),
            std::string::npos)
      << app.run_info().session->fly_from;
  EXPECT_FALSE(app.run_info().session->assist_choosable);
  const ui::SessionChoices& c = *app.run_info().session;
  ASSERT_GE(c.scenario, 0);
  EXPECT_TRUE(c.scenarios[std::size_t(c.scenario)].starts_with("mi_helix"))
      << "the panel names the scenario, not " << c.scenarios[std::size_t(c.scenario)];

  pick_pilot(app, "experienced");
  EXPECT_EQ(app.live()->mode().steps_done(), k) << "the flight made again is at the moment";
  EXPECT_EQ(app.live()->history.size(), waited_history) << "the path so far is shown again";
  frame(app);
  save_shot(screen_, "fly_from_here");
  key(app, ui::Key::r, true);  // Ctrl+R: record it
  ASSERT_TRUE(app.run_info().session->record);
  app.ui_state().score_card_closed = true;
  key(app, ui::Key::space);
  ASSERT_TRUE(app.live()->started());
  until_over(app);
  ASSERT_TRUE(app.over());
  EXPECT_EQ(app.run_info().state, ui::RunState::finished);
  const Metrics live = app.live()->metrics;
  ASSERT_FALSE(live.empty());
  app.history()->wait_idle();
  EXPECT_EQ(app.finish(), 0);

  // The recording: the parent named, the first step the parent's step k, flown to the end.
  const std::string branch = newest_recording();
  ASSERT_FALSE(branch.empty());
  EXPECT_NE(branch.find("mi_helix-experienced-from-9.99s-"), std::string::npos) << branch;
  const RecordingContents rec = read(branch), parent_rec = read(parent);
  std::string error;
  const std::string parent_sha = *sha256_file(parent, error);
  EXPECT_EQ(rec.metadata.at("parent_recording"), fs::absolute(parent).lexically_normal().string());
  EXPECT_EQ(rec.metadata.at("parent_sha256"), parent_sha);
  EXPECT_EQ(rec.metadata.at("parent_step"), std::to_string(k));
  ASSERT_FALSE(rec.states.empty());
  EXPECT_EQ(rec.states.front().step, std::uint64_t(k));
  EXPECT_EQ(rec.states.front().x, parent_rec.states[std::size_t(k)].x)
      << "the branch's first step is not the parent's step at 10 s";
  EXPECT_EQ(rec.states.back().step, parent_rec.states.back().step) << "the flight did not complete";
  ASSERT_TRUE(rec.end);
  EXPECT_FALSE(rec.end->interrupted);
  EXPECT_EQ(rec.pilot.front().source, "experienced");

  // The history: a branch of the novice's flight.
  auto store = history::open_history("", error);
  ASSERT_TRUE(store) << error;
  std::vector<history::StoredFlight> rows;
  ASSERT_TRUE(store->query({}, rows, error)) << error;
  ASSERT_EQ(rows.size(), 1u) << "one flight: the replay is none";
  EXPECT_EQ(rows[0].parent_recording_hash, parent_sha);
  EXPECT_EQ(rows[0].parent_step, k);
  EXPECT_TRUE(rows[0].branch());
  EXPECT_EQ(rows[0].ended, history::Ended::completed);
  EXPECT_EQ(rows[0].pilot, "experienced");
  EXPECT_NEAR(rows[0].duration_s, double(rec.states.size()) * 0.015, 1e-9) << "its own time";
  EXPECT_EQ(rows[0].recording_hash, *sha256_file(branch, error));
  EXPECT_EQ(rows[0].metrics, live);

  // `score` replays it exactly, through its parent, with the live score.
  const std::string bin = MIXPILOT_BINARY;
  const std::string json = (home / "score.json").string();
  EXPECT_EQ(test::run_mixpilot(bin, "score '" + branch + "' --json '" + json + "'", home), 0)
      << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("exact"), std::string::npos)
      << test::read_file(home / "out.txt");
  const auto scored = test::numbers(test::read_file(json));
  for (const auto& [name, value] : live) {
    ASSERT_TRUE(scored.count(name)) << name;
    EXPECT_NEAR(scored.at(name), value, 1e-9 * std::max(1.0, std::abs(value))) << name;
  }
  EXPECT_EQ(test::run_mixpilot(bin, "fly --pilot '" + branch + "' --headless", home, "fly.txt"), 0)
      << test::read_file(home / "fly.txt");
  EXPECT_NE(test::read_file(home / "fly.txt").find("replay exact"), std::string::npos);
  // The listings show the link.
  ASSERT_EQ(test::run_mixpilot(bin, "history --json", home, "history.json"), 0);
  const std::string listed = test::read_file(home / "history.json");
  EXPECT_NE(listed.find("\"parent_recording_hash\": \"" + parent_sha + "\", \"parent_step\": " +
                        std::to_string(k)),
            std::string::npos)
      << listed;
  ASSERT_EQ(test::run_mixpilot(bin, "history --csv", home, "history.csv"), 0);
  const std::string csv = test::read_file(home / "history.csv");
  EXPECT_NE(csv.find(",parent_recording_hash,parent_step"), std::string::npos) << csv;
  EXPECT_NE(csv.find("," + parent_sha + "," + std::to_string(k)), std::string::npos) << csv;
}

// The keyboard takes the flight over (the default pilot without a gamepad); T, the key, as the
// button; the recording replays exactly. Restart (R) after it flies the same moment again.
TEST_F(FlyFromHereApp, TakeOverWithTheKeyboard) {
  fresh_user_dirs("keyboard");
  const std::string parent = record(4.0, "novice", "kb_parent.mcap");
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = parent;
  o.record = test::fresh_path("fly_from_here_app", "kb_branch.mcap").string();
  cli::Trainer app(o);
  std::string error;
  ASSERT_TRUE(app.open_replay(parent, error)) << error;
  app.load_replay();
  app.seek(2.0);
  frame(app);
  key(app, ui::kFlyFromHereKey);
  until_ready(app);
  ASSERT_FALSE(app.replaying()) << app.run_info().message;
  if (app.live()->flight().pilot != "keyboard") pick_pilot(app, "keyboard");
  const std::int64_t k = app.live()->mode().steps_done();
  EXPECT_EQ(k, std::int64_t(std::floor(2.0 / 0.015 + 1e-9)));
  app.ui_state().score_card_closed = true;
  // A few taps on the keys while it flies.
  key(app, ui::Key::space);
  ASSERT_TRUE(app.live()->started());
  ImGuiIO& io = ImGui::GetIO();
  ui::set_key(io, ui::kFlightKeys[int(input::Key::roll_right)], true);
  for (int i = 0; i < 20; ++i) {
    frame(app);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ui::set_key(io, ui::kFlightKeys[int(input::Key::roll_right)], false);
  until_over(app);
  ASSERT_TRUE(app.over());
  const RecordingContents rec = read(o.record), parent_rec = read(parent);
  ASSERT_FALSE(rec.states.empty());
  EXPECT_EQ(rec.states.front().x, parent_rec.states[std::size_t(k)].x);
  EXPECT_EQ(rec.pilot.front().source, "keyboard");
  EXPECT_EQ(rec.joy.size(), rec.states.size()) << "the keyboard's raw sticks are recorded";
  EXPECT_EQ(replay_difference(o.record), "");
  // R: the same moment again, READY there... and started at once, as Restart does.
  key(app, ui::Key::r);
  ASSERT_TRUE(app.live());
  EXPECT_EQ(app.live()->flight().from->step, k);
  app.live()->rig->stop();
  EXPECT_EQ(app.finish(), 0);
}

// A gamepad (an SDL virtual pad playing a script) takes the flight over; the raw axes are
// recorded from the take-over on, and the recording replays exactly.
TEST_F(FlyFromHereApp, TakeOverWithAGamepad) {
  fresh_user_dirs("gamepad");
  const std::string parent = record(4.0, "novice", "pad_parent.mcap");
  const fs::path script = test::fresh_path("fly_from_here_app", "pad.csv");
  std::ofstream(script) << "t,left_x,left_y,right_x,right_y\n0,0,0,0.2,0\n0.5,0,0,-0.2,0.1\n";
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = parent;
  o.gamepad_script = script.string();
  o.record = test::fresh_path("fly_from_here_app", "pad_branch.mcap").string();
  cli::Trainer app(o);
  take_over(app, parent, 2.5);
  ASSERT_FALSE(HasFatalFailure());
  pick_pilot(app, "gamepad");
  const std::int64_t k = app.live()->mode().steps_done();
  app.ui_state().score_card_closed = true;
  key(app, ui::Key::space);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!app.live()->started() && std::chrono::steady_clock::now() < deadline) frame(app);
  ASSERT_TRUE(app.live()->started()) << "the virtual pad never connected";
  until_over(app);
  ASSERT_TRUE(app.over());
  EXPECT_EQ(app.finish(), 0);
  const RecordingContents rec = read(o.record), parent_rec = read(parent);
  ASSERT_FALSE(rec.states.empty());
  EXPECT_EQ(rec.states.front().step, std::uint64_t(k));
  EXPECT_EQ(rec.states.front().x, parent_rec.states[std::size_t(k)].x);
  EXPECT_EQ(rec.pilot.front().source, "gamepad");
  ASSERT_EQ(rec.joy.size(), rec.states.size());
  EXPECT_NE(rec.joy.back().axes, rec.joy.front().axes) << "the script's sticks moved";
  EXPECT_EQ(replay_difference(o.record), "");
}

// A probe flown on is a probe: its history row says so, and it replays as one.
TEST_F(FlyFromHereApp, AProbesBranchIsAProbe) {
  fresh_user_dirs("probe");
  const std::string parent = record(3.0, "novice", "probe_parent.mcap", Assistance::off);
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = parent;
  o.record = test::fresh_path("fly_from_here_app", "probe_branch.mcap").string();
  cli::Trainer app(o);
  take_over(app, parent, 1.0);
  ASSERT_FALSE(HasFatalFailure());
  pick_pilot(app, "experienced");
  EXPECT_TRUE(app.live()->mode().identity().probe);
  EXPECT_TRUE(app.live()->scene.probe);
  app.ui_state().score_card_closed = true;
  key(app, ui::Key::space);
  until_over(app);
  ASSERT_TRUE(app.over());
  app.history()->wait_idle();
  EXPECT_EQ(app.finish(), 0);
  EXPECT_EQ(read(o.record).metadata.at("assist"), "off");
  EXPECT_EQ(replay_difference(o.record), "");
  std::string error;
  auto store = history::open_history("", error);
  ASSERT_TRUE(store) << error;
  std::vector<history::StoredFlight> rows;
  ASSERT_TRUE(store->query({}, rows, error)) << error;
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0].probe);
  EXPECT_TRUE(rows[0].branch());
}

// The window at 150 % (a newcomer's display): the replay with its Fly from here button and the
// moment taken over, READY, lay out with nothing overlapping or cut (tests/ui_layout.hpp).
class FlyFromHereApp150 : public FlyFromHereApp {
 protected:
  float scale() const override { return 1.5f; }
};

TEST_F(FlyFromHereApp150, NothingOverlapsOrIsCut) {
  fresh_user_dirs("scale150");
  const std::string parent = record(12.0, "novice", "novice150.mcap");
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = parent;
  cli::Trainer app(o);
  std::string error;
  ASSERT_TRUE(app.open_replay(parent, error)) << error;
  app.load_replay();
  app.seek(10.0);
  frame(app);
  frame(app);
  for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << "replay: " << problem;
  take_over(app, parent, 10.0);
  ASSERT_FALSE(HasFatalFailure());
  frame(app);
  frame(app);
  for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << "READY: " << problem;
  save_shot(screen_, "fly_from_here_150");
}

// A branch without its parent: `score`, `replay` and the window say which parent is missing,
// and which has changed. The branch is flown headless from the take-over's moment (the app's
// TakeOver and a FlightRig, as the window makes it).
TEST(FlyFromHereCli, AMissingOrChangedParentIsNamed) {
  const fs::path home = fresh_user_dirs("missing");
  const std::string parent = record(3.0, "novice", "gone_parent.mcap");
  cli::TakeOver job(parent, 100);
  while (!job.done()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(job.moment()) << job.error();
  cli::FlyOptions o;
  o.pilot = "experienced";
  o.from = job.moment();
  std::string error;
  int status = 0;
  auto rig = cli::FlightRig::assemble(o, error, status);
  ASSERT_TRUE(rig) << error;
  const std::string branch = test::fresh_path("fly_from_here_app", "gone_branch.mcap").string();
  ASSERT_TRUE(rig->record(branch, "", {}, false, error)) << error;
  rig->start();
  while (rig->step()) {
  }
  ASSERT_EQ(rig->close(false).error, "");
  EXPECT_EQ(replay_difference(branch), "");

  const std::string bin = MIXPILOT_BINARY;
  const std::string abs = fs::absolute(parent).lexically_normal().string();
  fs::rename(parent, parent + ".away");
  for (const std::string& args : {"score '" + branch + "'", "replay '" + branch + "' --headless"}) {
    EXPECT_EQ(test::run_mixpilot(bin, args, home), 1) << args;
    const std::string out = test::read_file(home / "out.txt");
    EXPECT_NE(out.find(branch + " is a branch of " + abs + " (taken over at t = 1.500 s, step 100)"
                                 ", which is missing"),
              std::string::npos)
        << args << ": " << out;
  }
  {
    cli::FlyOptions r;
    r.replay = true;
    r.pilot = branch;
    cli::Trainer app(r);
    EXPECT_FALSE(app.open_replay(branch, error));
    EXPECT_NE(error.find("which is missing"), std::string::npos) << error;
  }
  // Another flight where the parent was.
  const std::string other = record(3.0, "experienced", "other.mcap");
  fs::rename(other, parent);
  EXPECT_EQ(test::run_mixpilot(bin, "score '" + branch + "'", home), 1);
  const std::string out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("which has changed since the branch was flown (SHA-256 " +
                     read(branch).metadata.at("parent_sha256") + " expected, " +
                     *sha256_file(parent, error) + " found)"),
            std::string::npos)
      << out;
  // Put back, it replays again: in score, and in replay, whose tape shows the parent's flight
  // up to the take-over and the branch after it.
  fs::rename(parent + ".away", parent);
  EXPECT_EQ(test::run_mixpilot(bin, "score '" + branch + "'", home), 0)
      << test::read_file(home / "out.txt");
  EXPECT_EQ(test::run_mixpilot(bin, "replay '" + branch + "' --headless", home), 0)
      << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("replay exact"), std::string::npos)
      << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("taken over at t = 1.500 s (step 100) from " +
                                                   abs),
            std::string::npos)
      << test::read_file(home / "out.txt");
}

// How long the moment takes to make ready, at the start, the middle and the end of a whole
// mi_helix flight (30 s): a fresh replay flown to the step, on the worker thread.
TEST(FlyFromHereCli, TimeToReachTheMoment) {
  fresh_user_dirs("timing");
  const std::string parent = record(30.0, "novice", "whole.mcap");
  for (const double t : {1.0, 10.0, 29.9}) {
    const auto k = std::int64_t(std::floor(t / 0.015 + 1e-9));
    cli::TakeOver job(parent, k);
    while (!job.done()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ASSERT_TRUE(job.moment()) << job.error();
    EXPECT_EQ(job.moment()->snapshot->step(), k);
    std::printf("  fly from here at t = %4.1f s (step %4lld): ready in %.3f s\n", t,
                static_cast<long long>(k), job.seconds());
  }
}

}  // namespace
}  // namespace mixpilot
