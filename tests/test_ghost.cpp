// The ghost (SPEC §10): a recorded flight of the scenario flying along in step by time, with
// "ahead / behind by X s" along the reference. Progress along the reference against brute force
// (locally: the helix's coils); the figure the HUD and the screenshots' summary give, checked
// against the two recordings alone; the default ghost — the trainee's best flight whose
// recording is still on disk — through the history, in the window's code and on the command
// line; recordings that cannot be a ghost refused with the reason; the translucent vehicle drawn
// where it is projected (EGL offscreen); a replay with a ghost.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <imgui.h>

#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/ghost.hpp"
#include "app/offscreen.hpp"
#include "app/progress.hpp"
#include "app/trainer.hpp"
#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"
#include "core/modes/reference_progress.hpp"
#include "core/recording/recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "models/attitude.hpp"
#include "ui/ghost.hpp"
#include "ui/panels.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"
#include "ui/theme.hpp"

#include "run_mixpilot.hpp"
#include "record_flight.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 1280, kH = 720;
constexpr double kDt = 0.015;  // [s] mi_helix's control period

std::string scenario(const char* name) {
  return std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + name;
}

HelixReference helix_of(const char* name) {
  std::string error;
  const std::optional<Scenario> sc = load_scenario(scenario(name), error);
  EXPECT_TRUE(sc) << error;
  return sc ? sc->reference : HelixReference{};
}

// The test's own answer: the reference sampled every `h` over [lo, hi], the nearest sample.
double brute_force_progress(const HelixReference& helix, const Eigen::Vector3d& p, double lo,
                            double hi, double h) {
  double best = lo, d_best = std::numeric_limits<double>::infinity();
  for (double tau = lo; tau <= hi + 1e-12; tau += h) {
    const double d = (helix.position(tau) - p).squaredNorm();
    if (d < d_best) {
      d_best = d;
      best = tau;
    }
  }
  return best;
}

// A recording of `scenario_file` flown headless by `pilot` for `seconds`.
std::string record(const std::string& scenario_file, const char* pilot, double seconds,
                   const std::string& file) {
  cli::FlyOptions o;
  o.scenario_path = scenario_file;
  o.pilot = pilot;
  o.duration = seconds;
  const std::string path = test::fresh_path("ghost", file).string();
  return test::record_flight(o, path) ? path : "";
}

RecordingContents read(const std::string& path) {
  std::string error;
  std::optional<RecordingContents> rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  return rec ? std::move(*rec) : RecordingContents{};
}

Eigen::Vector3d position_at(const RecordingContents& rec, std::int64_t k) {
  for (const VehicleStateMsg& s : rec.states)
    if (s.step == std::uint64_t(k)) return Eigen::Vector3d(s.x[0], s.x[1], s.x[2]);
  ADD_FAILURE() << "no step " << k << " in the recording";
  return Eigen::Vector3d::Zero();
}

// The user's folders of a test, never the machine's.
fs::path fresh_user_dirs(const char* name) {
  const fs::path home = test::fresh_path("ghost_home", name);
  fs::create_directories(home);
  setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
  return home;
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// ---- Progress along the reference (core) ---------------------------------------------------

// On the reference, off it (outward, below), ahead of and behind t, at the flight's start and
// with a non-finite position: the nearest reference point near t, refined between samples to
// well under the brute force's own step.
TEST(Ghost, ProgressIsTheNearestReferencePointNearT) {
  const HelixReference helix = helix_of("mi_helix.toml");
  const ReferencePath ref = [helix](double tau) { return helix.position(tau); };
  for (const double tau : {0.5, 3.3, 10.01, 17.9, 25.4}) {
    const std::optional<double> on = reference_progress(ref, ref(tau), tau);
    ASSERT_TRUE(on);
    EXPECT_NEAR(*on, tau, 1e-6) << "on the reference at " << tau;
    // Off it: outward along the radius and down; the brute force's answer at 10 µs steps.
    const Eigen::Vector3d radial =
        (ref(tau) - Eigen::Vector3d(helix.center.x(), helix.center.y(), ref(tau).z())).normalized();
    const Eigen::Vector3d p = ref(tau) + 0.12 * radial - Eigen::Vector3d(0, 0, 0.05);
    const double expected = brute_force_progress(helix, p, std::max(0.0, tau - 1), tau + 1, 1e-5);
    const std::optional<double> off = reference_progress(ref, p, tau + 0.7);
    ASSERT_TRUE(off);
    EXPECT_NEAR(*off, expected, 2e-5) << "off the reference at " << tau;
  }
  // Ahead of t within the window, and beyond it: the window's end.
  EXPECT_NEAR(*reference_progress(ref, ref(12.0), 10.0), 12.0, 1e-6);
  EXPECT_NEAR(*reference_progress(ref, ref(18.0), 10.0), 15.0, 1e-6);
  EXPECT_NEAR(*reference_progress(ref, ref(3.0), 10.0), 5.0, 1e-6);
  // Behind the start: the reference is not flown before t = 0.
  const Eigen::Vector3d behind = ref(0.0) - 0.2 * helix.velocity(0.0).normalized();
  EXPECT_NEAR(*reference_progress(ref, behind, 0.0), 0.0, 1e-9);
  EXPECT_FALSE(reference_progress(ref, Eigen::Vector3d(NAN, 0, 1), 1.0));
}

// mi_helix_endurance's coils are 0.2 m apart: 0.12 m above the reference at τ = 100 s the
// coil above (τ = 160 s) is nearer. A global search jumps there; the progress stays on the
// coil flown.
TEST(Ghost, ProgressSearchesLocallyNotAcrossTheHelixsCoils) {
  const HelixReference helix = helix_of("mi_helix_endurance.toml");
  const ReferencePath ref = [helix](double tau) { return helix.position(tau); };
  const double turn = 2.0 * M_PI / helix.angular_rate;
  const Eigen::Vector3d p = ref(100.0) + Eigen::Vector3d(0, 0, 0.12);
  const double global = brute_force_progress(helix, p, 0.0, 300.0, 1e-3);
  EXPECT_NEAR(global, 100.0 + turn, 0.5) << "the test's premise: globally the coil above is nearer";
  const std::optional<double> local = reference_progress(ref, p, 100.0);
  ASSERT_TRUE(local);
  EXPECT_NEAR(*local, brute_force_progress(helix, p, 95.0, 105.0, 1e-5), 2e-5);
  EXPECT_LT(std::abs(*local - 100.0), 0.5);
}

// ---- The figure against the two recordings -----------------------------------------------

// What the HUD shows at step k of a live flight (app's snapshot: the scene with its ghost and
// the step's telemetry), kept while the flight flies.
struct Shown {
  std::int64_t k = 0;
  std::optional<ui::GhostGap> gap;
  std::string hud;
};

// The motivating case: the experienced pilot's recording as the ghost of a novice flight. At
// several t the snapshot's τ of each and their gap equal the test's own, found from the two
// recordings' positions alone by brute force over the reference sampled every millisecond
// (globally: a deviation under half the coil spacing keeps the global nearest point local).
// Tolerance: the brute force's step, 1 ms (each of its τ within half of it; the snapshot's
// refined to 0.1 µs).
TEST(Ghost, AheadOrBehindMatchesTheTwoRecordingsByBruteForce) {
  constexpr double kSeconds = 10.0, kStep = 1e-3;
  const std::string experienced = record(scenario("mi_helix.toml"), "experienced", kSeconds,
                                         "experienced.mcap");
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  o.pilot = "novice";
  o.duration = kSeconds;
  std::string error;
  int status = 0;
  auto rig = cli::FlightRig::assemble(o, error, status);
  ASSERT_TRUE(rig) << error;
  const std::string novice = test::fresh_path("ghost", "novice.mcap").string();
  ASSERT_TRUE(rig->record(novice, "", {}, false, error)) << error;
  const std::optional<cli::GhostTarget> target = cli::ghost_target(rig->flight(), error);
  ASSERT_TRUE(target) << error;
  ui::Scene scene = ui::scene_of(rig->mode(), "pilot novice");
  scene.ghost = cli::load_ghost(experienced, *target, "", error);
  ASSERT_TRUE(scene.ghost) << error;
  EXPECT_EQ(scene.ghost->label, "experienced.mcap");

  struct Keep : TelemetrySink {
    const ui::Scene* scene = nullptr;
    std::vector<Shown> shown;
    void on_sample(const Telemetry& s) override {
      if (s.step % 100 != 50) return;  // t = 0.75 s, 2.25 s, ...
      shown.push_back({s.step, ui::ghost_gap(*scene, s), ui::ghost_hud_text(*scene, s)});
    }
  } keep;
  keep.scene = &scene;
  rig->watch(keep);
  rig->start();
  while (rig->step()) {
  }
  ASSERT_EQ(rig->close(false).error, "");
  ASSERT_GE(keep.shown.size(), 6u);

  const RecordingContents live = read(novice), ghost = read(experienced);
  const HelixReference helix = helix_of("mi_helix.toml");
  double largest = 0.0;
  for (const Shown& s : keep.shown) {
    ASSERT_TRUE(s.gap) << "no figure at step " << s.k;
    const double t = double(s.k) * kDt;
    const double hi = kSeconds + 6.0;
    const double tau_live = brute_force_progress(helix, position_at(live, s.k), 0.0, hi, kStep);
    const double tau_ghost = brute_force_progress(helix, position_at(ghost, s.k), 0.0, hi, kStep);
    std::printf("  t = %6.3f s: novice tau %.4f s, experienced tau %.4f s: %+.4f s (brute "
                "force %+.4f s); HUD \"%s\"\n",
                t, s.gap->live, s.gap->ghost, s.gap->ahead, tau_live - tau_ghost, s.hud.c_str());
    EXPECT_NEAR(s.gap->t, t, 1e-9);
    EXPECT_NEAR(s.gap->live, tau_live, 0.5 * kStep + 1e-6) << "t = " << t;
    EXPECT_NEAR(s.gap->ghost, tau_ghost, 0.5 * kStep + 1e-6) << "t = " << t;
    EXPECT_NEAR(s.gap->ahead, tau_live - tau_ghost, kStep) << "t = " << t;
    // The HUD's words for it, at one decimal.
    char words[64];
    const double a = s.gap->ahead;
    if (std::abs(a) < 0.05)
      std::snprintf(words, sizeof words, "ghost: level with you");
    else
      std::snprintf(words, sizeof words, "ghost: you are %s by %.1f s", a > 0 ? "ahead" : "behind",
                    std::abs(a));
    EXPECT_EQ(s.hud.rfind(words, 0), 0u) << s.hud;
    EXPECT_NE(s.hud.find("experienced.mcap"), std::string::npos) << "the HUD names the ghost";
    largest = std::max(largest, std::abs(a));
  }
  EXPECT_GT(largest, 0.01) << "the two pilots never differed: nothing was compared";
}

// The same through `fly --headless --screenshot --ghost`: each screenshot's line of the summary
// gives the figure its HUD shows, to the millisecond, and it matches the recordings.
TEST(Ghost, TheScreenshotsFigureOnTheCommandLineMatchesTheRecordings) {
  const fs::path home = fresh_user_dirs("cli_figure");
  constexpr double kSeconds = 8.0, kStep = 1e-3;
  const std::string experienced = record(scenario("mi_helix.toml"), "experienced", kSeconds,
                                         "experienced_cli.mcap");
  const std::string novice = (home / "novice.mcap").string();
  const std::vector<double> times = {1.0, 3.3, 5.5, 7.9};
  std::string shots;
  for (std::size_t i = 0; i < times.size(); ++i)
    shots += " --screenshot " + std::to_string(times[i]) + ":" +
             quoted((home / ("shot" + std::to_string(i) + ".png")).string());
  ASSERT_EQ(test::run_mixpilot(MIXPILOT_BINARY,
                               "fly --scenario " + quoted(scenario("mi_helix.toml")) +
                                   " --pilot novice --headless --duration 8 --history off"
                                   " --record " + quoted(novice) + " --ghost " +
                                   quoted(experienced) + shots,
                               home),
            0)
      << test::read_file(home / "out.txt");
  const std::string out = test::read_file(home / "out.txt");
  std::printf("%s", out.c_str());
  const RecordingContents live = read(novice), ghost = read(experienced);
  const HelixReference helix = helix_of("mi_helix.toml");
  for (std::size_t i = 0; i < times.size(); ++i) {
    const std::regex line("screenshot [^\\n]*shot" + std::to_string(i) +
                          "\\.png \\(ghost: you are (ahead|behind) by ([0-9.]+) s\\)");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(out, m, line)) << "no figure for screenshot " << i;
    const double said = (m[1] == "ahead" ? 1.0 : -1.0) * std::stod(m[2]);
    const auto k = std::int64_t(std::floor(times[i] / kDt + 1e-9));  // t_k <= T < t_k + dt
    const double expected =
        brute_force_progress(helix, position_at(live, k), 0.0, 14.0, kStep) -
        brute_force_progress(helix, position_at(ghost, k), 0.0, 14.0, kStep);
    // The brute force's step, and the printed figure's rounding to the millisecond.
    EXPECT_NEAR(said, expected, kStep + 0.5e-3) << "screenshot at t = " << times[i];
    EXPECT_TRUE(fs::exists(home / ("shot" + std::to_string(i) + ".png")));
  }
  EXPECT_NE(out.find("ghost experienced_cli.mcap ("), std::string::npos) << "the summary's ghost line";
}

// ---- The default ghost: the trainee's best with a recording, through the history -----------

// With MIXPILOT_SHOT_DIR set, the frame on screen as NAME.png there (to look at).
void save_shot(const cli::Offscreen& screen, const std::string& name) {
  const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
  if (!dir || !*dir) return;
  std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen.png();
}


class GhostApp : public testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    if (!screen_.open(kW, kH, error)) GTEST_SKIP() << "no EGL device: " << error;
  }
  void frame(cli::Trainer& app) {
    screen_.frame([&] { app.build_frame(1.0 / 60.0); });
  }
  // Frames until `done` (the loaders work off the UI thread), at most 30 s; false on time out.
  template <class Done>
  bool frames_until(cli::Trainer& app, Done done) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!done()) {
      if (std::chrono::steady_clock::now() > until) return false;
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
  }
  cli::Offscreen screen_;
};

// Flights of mi_helix in Ada's history: the experienced pilot's (its recording then deleted),
// the novice's, and the experienced pilot's of an edited copy of the file (the same name,
// another text: another scenario to a ghost). ProgressView::best is the first, which has no
// recording left; the default ghost is the novice's flight: the best of this very scenario
// whose recording is on disk. The window's code shows it with the next flight (loaded off the
// UI thread), names it in the session panel, and "none" takes it away; `fly --ghost best` flies
// with the same one.
TEST_F(GhostApp, TheDefaultGhostIsTheTraineesBestFlightWithItsRecording) {
  const fs::path home = fresh_user_dirs("default");
  const std::string bin = MIXPILOT_BINARY;
  const std::string helix = scenario("mi_helix.toml");
  const fs::path edited = home / "mi_helix_edited.toml";
  {
    std::ofstream(edited) << test::read_file(helix) << "\n# edited: the same name, another text\n";
  }
  const auto fly = [&](const std::string& file, const char* pilot, const std::string& rec) {
    EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(file) + " --pilot " + pilot +
                                          " --headless --duration 4 --trainee Ada --record " +
                                          quoted(rec),
                                 home),
              0)
        << test::read_file(home / "out.txt");
  };
  const std::string gone = (home / "experienced.mcap").string();
  const std::string novice = (home / "novice.mcap").string();
  const std::string other = (home / "experienced_edited.mcap").string();
  fly(helix, "experienced", gone);
  fly(helix, "novice", novice);
  fly(edited.string(), "experienced", other);
  fs::remove(gone);

  // The history as the app reads it.
  std::string error;
  auto store = history::open_history("", error);
  ASSERT_TRUE(store) << error;
  std::vector<history::StoredFlight> rows;
  history::Query q;
  q.trainee = "Ada";
  q.scenario = "mi_helix";
  ASSERT_TRUE(store->query(q, rows, error)) << error;
  ASSERT_EQ(rows.size(), 3u);
  const ui::ProgressView view = cli::progress_view(rows, "Ada", "mi_helix");
  ASSERT_GE(view.best, 0);
  EXPECT_EQ(rows[std::size_t(view.best)].recording_path, fs::absolute(gone).string())
      << "the premise: the best of all has no recording left";
  EXPECT_GE(view.flights[2].skill, view.flights[1].skill)
      << "the premise: the edited scenario's flight would win were it the same scenario";
  const std::string hash = sha256_hex(test::read_file(helix));
  const int best = cli::best_recorded(view, hash);
  ASSERT_EQ(best, 1) << "the novice's flight";
  EXPECT_EQ(view.flights[1].recording, fs::absolute(novice).string());

  // The window's code: the live flight of mi_helix for Ada, its ghost the default.
  cli::FlyOptions o;
  o.scenario_path = helix;
  o.trainee = "Ada";
  o.duration = 1.0;
  cli::Trainer app(o);
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.act(ui::SetTrainee{"Ada"});
  const auto ghost_path = [&] {
    const ui::Scene& sc = app.live()->scene;
    return sc.ghost ? sc.ghost->path : std::string();
  };
  ASSERT_TRUE(frames_until(app, [&] { return !ghost_path().empty(); }))
      << "no ghost came: " << app.run_info().session->ghost_note << " / "
      << app.run_info().message;
  EXPECT_EQ(ghost_path(), fs::absolute(novice).string());
  const ui::SessionChoices& c = *app.run_info().session;
  ASSERT_GE(c.ghost, 0);
  ASSERT_LT(std::size_t(c.ghost), c.ghosts.size());
  EXPECT_EQ(c.ghosts[std::size_t(c.ghost)].rfind("your best: attempt 2, skill", 0), 0u)
      << c.ghosts[std::size_t(c.ghost)];
  EXPECT_EQ(app.live()->scene.ghost->label, c.ghosts[std::size_t(c.ghost)]);
  EXPECT_EQ(c.ghosts.front(), "none");
  frame(app);
  save_shot(screen_, "ghost_session");
  // "none": the next flight has no ghost.
  app.act(ui::PickGhost{0});
  frame(app);
  EXPECT_FALSE(app.live()->scene.ghost);
  // ... and the best again.
  app.act(ui::PickGhost{1});
  ASSERT_TRUE(frames_until(app, [&] { return !ghost_path().empty(); }));
  EXPECT_EQ(ghost_path(), fs::absolute(novice).string());
  // Flown (a second, in real time): the ghost flies along to the end; Restart, which starts at
  // once, races it again.
  app.ui_state().score_card_closed = true;
  app.start();
  ASSERT_TRUE(frames_until(app, [&] { return app.over(); }));
  EXPECT_EQ(ghost_path(), fs::absolute(novice).string());
  app.act(ui::RestartFlight{});
  ASSERT_TRUE(app.live()->started());
  ASSERT_TRUE(frames_until(app, [&] { return !ghost_path().empty(); }));
  EXPECT_EQ(ghost_path(), fs::absolute(novice).string());
  ASSERT_TRUE(frames_until(app, [&] { return app.over(); }));

  // The command line's --ghost best: the same flight.
  const std::string shot = (home / "best.png").string();
  ASSERT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) +
                                        " --pilot experienced --headless --duration 2 --trainee "
                                        "Ada --history off --ghost " + quoted(novice) +
                                        " --screenshot 1:" + quoted(shot),
                               home),
            0)
      << test::read_file(home / "out.txt");
  ASSERT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) +
                                        " --pilot experienced --headless --duration 2 --trainee "
                                        "Ada --ghost best --screenshot 1:" + quoted(shot) + " --force",
                               home, "best.txt"),
            0)
      << test::read_file(home / "best.txt");
  const std::string said = test::read_file(home / "best.txt");
  EXPECT_NE(said.find("ghost your best: attempt 2, skill"), std::string::npos) << said;
  EXPECT_NE(said.find("(" + fs::absolute(novice).string() + ")"), std::string::npos) << said;
  // A trainee with no recorded flight: said, and flown without a ghost.
  ASSERT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) +
                                        " --pilot novice --headless --duration 1 --trainee "
                                        "Grace --ghost best",
                               home, "none.txt"),
            0);
  EXPECT_NE(test::read_file(home / "none.txt")
                .find("--ghost best: Grace has no flight of mi_helix in the history"),
            std::string::npos)
      << test::read_file(home / "none.txt");
}

// ---- Refusals ----------------------------------------------------------------------------

// A recording of another scenario (by name, or the same name with another text), of another
// mode, a file that is no recording, a folder, a missing file and an empty path: each a clear
// error naming the file and why, on the command line (exit 1; 2 for usage) and in the window
// (the session panel's note and the status line; the window flies on without a ghost).
TEST_F(GhostApp, RecordingsThatCannotBeAGhostAreRefusedWithTheReason) {
  const fs::path home = fresh_user_dirs("refused");
  const std::string bin = MIXPILOT_BINARY;
  const std::string helix = scenario("mi_helix.toml");
  const std::string slow = record(scenario("mi_helix_slow.toml"), "novice", 1.0, "slow.mcap");
  const fs::path edited = home / "edited.toml";
  {
    std::ofstream(edited) << test::read_file(helix) << "\n# another version\n";
  }
  const std::string version = record(edited.string(), "novice", 1.0, "version.mcap");
  const std::string tracking = record(scenario("tracking_helix.toml"), "", 0.5, "tracking.mcap");
  const fs::path text = home / "notes.mcap";
  {
    std::ofstream(text) << "not a recording\n";
  }
  fs::create_directories(home / "folder.mcap");
  const std::string missing = (home / "missing.mcap").string();
  struct Case {
    std::string ghost, needle;
  };
  const std::vector<Case> cases = {
      {slow, "a recording of scenario 'mi_helix_slow', not of 'mi_helix'"},
      {version, "a recording of another version of scenario 'mi_helix' (its text differs"},
      {tracking, "a recording of a crazyflie_tracking flight, not of mi_helix"},
      {text.string(), text.string() + ": "},
      {(home / "folder.mcap").string(), (home / "folder.mcap").string() + ": "},
      {missing, missing + ": "},
  };
  for (const Case& c : cases) {
    const int rc = test::run_mixpilot(bin, "fly --scenario " + quoted(helix) +
                                               " --pilot novice --headless --duration 0.5 "
                                               "--history off --ghost " + quoted(c.ghost),
                                      home);
    const std::string out = test::read_file(home / "out.txt");
    std::printf("  %s", out.c_str());
    EXPECT_EQ(rc, 1) << out;
    EXPECT_EQ(out.rfind("mixpilot fly: --ghost ", 0), 0u) << out;
    EXPECT_NE(out.find(c.needle), std::string::npos) << out;
  }
  // The missing file says so in words.
  test::run_mixpilot(bin, "fly --scenario " + quoted(helix) + " --pilot novice --headless "
                          "--duration 0.5 --history off --ghost " + quoted(missing), home);
  EXPECT_NE(test::read_file(home / "out.txt").find("No such file"), std::string::npos)
      << test::read_file(home / "out.txt");
  // Usage: an empty path, best without a history, best for a replay.
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) + " --headless --ghost ''",
                               home),
            2);
  EXPECT_NE(test::read_file(home / "out.txt").find("--ghost needs a value"), std::string::npos);
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) +
                                        " --headless --ghost best --history off",
                               home),
            2);
  EXPECT_EQ(test::run_mixpilot(bin, "replay " + quoted(slow) + " --headless --ghost best", home), 2);
  // A ghost that is also the recording written: refused before anything is written.
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) + " --pilot novice "
                                        "--headless --duration 0.5 --history off --ghost " +
                                        quoted(slow) + " --record " + quoted(slow) + " --force",
                               home),
            2)
      << test::read_file(home / "out.txt");
  EXPECT_NE(test::read_file(home / "out.txt").find("--record"), std::string::npos);

  // The window: --ghost of another scenario is refused, said in the session panel and on the
  // status line; the flight can still start.
  cli::FlyOptions o;
  o.scenario_path = helix;
  o.ghost = slow;
  o.history = "off";
  cli::Trainer app(o);
  int status = 0;
  std::string error;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  ASSERT_TRUE(frames_until(app, [&] {
    return app.run_info().session && app.run_info().session->ghost_note_is_error;
  })) << app.run_info().message;
  const ui::SessionChoices& c = *app.run_info().session;
  EXPECT_NE(c.ghost_note.find("not of 'mi_helix'"), std::string::npos) << c.ghost_note;
  EXPECT_TRUE(app.run_info().message_is_error);
  EXPECT_NE(app.run_info().message.find(slow), std::string::npos) << app.run_info().message;
  EXPECT_FALSE(app.live()->scene.ghost);
  EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  // The window's --ghost of a missing file: said before a window opens.
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario " + quoted(helix) + " --ghost " + quoted(missing),
                               home),
            1);
}

// ---- Drawn -------------------------------------------------------------------------------

// The ghost (the experienced pilot's recording) over a flight of the reckless pilot, rendered
// as the window renders it, against the same screen whose ghost has not started yet. Where its
// rotors and arms project, each pixel clear of everything else is the ghost's colour over the
// scene beneath at one opacity for all three channels, between 15 % and 90 %: a translucent
// vehicle of that colour, neither opaque nor missing. Its trail and rotors change pixels to its
// hue; the HUD says the figure in its colour.
TEST_F(GhostApp, TheGhostIsDrawnTranslucentWhereItIsProjected) {
  constexpr double kSeconds = 6.0;
  const std::string experienced =
      record(scenario("mi_helix.toml"), "experienced", kSeconds, "drawn_experienced.mcap");
  // The reckless pilot unassisted (a probe) strays far from it: the ghost stands clear of the
  // vehicle, for pixels of the ghost alone.
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  o.pilot = "reckless";
  o.assist = Assistance::off;
  o.duration = kSeconds;
  std::string error;
  int status = 0;
  auto rig = cli::FlightRig::assemble(o, error, status);
  ASSERT_TRUE(rig) << error;
  const std::optional<cli::GhostTarget> target = cli::ghost_target(rig->flight(), error);
  ASSERT_TRUE(target) << error;
  struct Keep : TelemetrySink {
    std::vector<Telemetry> tape;
    void on_sample(const Telemetry& s) override { tape.push_back(s); }
  } keep;
  rig->watch(keep);
  rig->start();
  while (rig->step()) {
  }
  (void)rig->close(false);
  ui::Scene with = ui::scene_of(rig->mode(), "pilot reckless");
  with.ghost = cli::load_ghost(experienced, *target, "experienced", error);
  ASSERT_TRUE(with.ghost) << error;
  // The scene to compare with: the same ghost, not yet flying (its HUD line is as tall, so
  // the layout is the same), nothing of it on the arena.
  ui::Scene without = with;
  auto later = std::make_shared<ui::Ghost>(*with.ghost);
  later->first_step = 1000000;
  without.ghost = later;
  // The first moment the two are 0.6 m apart: the ghost clear of the vehicle, in the view.
  std::size_t shown = 0;
  double apart = 0.0;
  for (std::size_t k = 0; k < keep.tape.size() && apart < 0.6; ++k) {
    const std::optional<std::size_t> j = ui::ghost_column(*with.ghost, keep.tape[k].t);
    if (!j) continue;
    apart = (with.ghost->states.col(Eigen::Index(*j)).head<3>() - keep.tape[k].x.head<3>()).norm();
    shown = k;
  }
  std::printf("  at t = %.3f s the ghost is %.3f m from the vehicle\n", keep.tape[shown].t, apart);
  const ui::History h = ui::History::view(keep.tape, shown + 1);

  ui::UiState st;
  ui::RunInfo run;
  run.state = ui::RunState::flying;
  const auto render = [&](const ui::Scene& sc) {
    ui::Requests ignored;
    for (int f = 0; f < 2; ++f) screen_.frame([&] { ui::draw_screen(sc, h, run, st, ignored); });
    return screen_.pixels();
  };
  const std::vector<std::uint8_t> a = render(without), b = render(with);
  save_shot(screen_, "ghost_drawn");
  ImVec2 vmin, vmax;
  ui::view_rect(ImVec2(kW, kH), run, vmin, vmax);
  const Telemetry& now = h.newest();
  const std::optional<std::size_t> j = ui::ghost_column(*with.ghost, now.t);
  ASSERT_TRUE(j);
  const Eigen::VectorXd x = with.ghost->states.col(Eigen::Index(*j));
  const Eigen::Matrix3d R = models::attitude(x).toRotationMatrix();
  const Eigen::Vector3d p = x.head<3>();
  const double arm = 0.23;  // ui/arena_view.cpp's
  // The rotors' centres and the arms' middles (the hub is where its trail ends).
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(arm, 0, 0), Eigen::Vector3d(0, arm, 0),
                                   Eigen::Vector3d(-arm, 0, 0), Eigen::Vector3d(0, -arm, 0)}) {
    points.push_back(p + R * d);
    points.push_back(p + 0.62 * R * d);
  }
  const auto at = [&](const std::vector<std::uint8_t>& img, int px, int py) {
    return &img[(std::size_t(py) * kW + std::size_t(px)) * 4];
  };
  const ImVec4 g4 = ImGui::ColorConvertU32ToFloat4(ui::colour::kGhost);
  const double g[3] = {255.0 * g4.x, 255.0 * g4.y, 255.0 * g4.z};
  int clean = 0, translucent = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    ImVec2 q;
    ASSERT_TRUE(ui::project_in_arena(with, now, st, vmin, vmax, points[i], q));
    const int px = int(q.x), py = int(q.y);
    // Clear of the rest: nothing else drawn within 4 px in the scene without the ghost, and
    // not by the ghost's name tag, whose dark backing darkens what it covers in all three
    // channels (the ghost's colour over anything never does).
    bool uniform = px > 4 && py > 4 && px < kW - 4 && py < kH - 4;
    bool tag = false;
    for (int dy = -4; uniform && dy <= 4; ++dy)
      for (int dx = -4; uniform && dx <= 4; ++dx) {
        const std::uint8_t *u = at(a, px + dx, py + dy), *w = at(b, px + dx, py + dy);
        for (int c = 0; c < 3; ++c) uniform = uniform && std::abs(u[c] - at(a, px, py)[c]) <= 6;
        tag = tag || (w[0] + 6 < u[0] && w[1] + 6 < u[1] && w[2] + 6 < u[2]);
      }
    if (!uniform || tag) continue;
    ++clean;
    // over = α G + (1 − α) under, one α for the three channels.
    double lo = 1.0, hi = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double under = at(a, px, py)[c], over = at(b, px, py)[c];
      if (std::abs(g[c] - under) < 40.0) continue;
      const double alpha = (over - under) / (g[c] - under);
      lo = std::min(lo, alpha);
      hi = std::max(hi, alpha);
    }
    std::printf("  ghost point %zu at (%d, %d): opacity %.2f to %.2f\n", i, px, py, lo, hi);
    EXPECT_GT(lo, 0.15) << "point " << i << ": the ghost is not drawn there";
    EXPECT_LT(hi, 0.9) << "point " << i << ": (nearly) opaque, not translucent";
    EXPECT_LT(hi - lo, 0.12) << "point " << i << ": not the ghost's colour over the scene";
    translucent += lo > 0.15 && hi < 0.9 ? 1 : 0;
  }
  EXPECT_GE(clean, 2) << "too few of the ghost's points clear of the rest to check";
  EXPECT_EQ(translucent, clean);
  // Pixels the ghost changed: many, most of its hue (blue above red above green: lavender).
  int changed = 0, lavender = 0;
  for (int yy = int(vmin.y); yy < int(vmax.y); ++yy)
    for (int xx = int(vmin.x); xx < int(vmax.x); ++xx) {
      const std::uint8_t* pb = at(b, xx, yy);
      const std::uint8_t* pa = at(a, xx, yy);
      if (std::abs(pb[0] - pa[0]) + std::abs(pb[1] - pa[1]) + std::abs(pb[2] - pa[2]) < 24) continue;
      ++changed;
      lavender += pb[2] > pb[0] && pb[0] > pb[1] ? 1 : 0;
    }
  std::printf("  %d pixels changed by the ghost, %d of them lavender\n", changed, lavender);
  EXPECT_GT(changed, 300);
  EXPECT_GT(lavender, changed / 2);
  // The HUD's line in the ghost's colour (its text's full-coverage pixels).
  int hud = 0;
  for (int yy = 0; yy < int(vmin.y) + 200; ++yy)
    for (int xx = 0; xx < kW; ++xx) {
      const std::uint8_t* pb = at(b, xx, yy);
      hud += std::abs(pb[0] - int(g[0] + 0.5)) <= 4 && std::abs(pb[1] - int(g[1] + 0.5)) <= 4 &&
                     std::abs(pb[2] - int(g[2] + 0.5)) <= 4
                 ? 1
                 : 0;
    }
  EXPECT_GT(hud, 40) << "no HUD line in the ghost's colour";
}

// ---- A replay with a ghost -----------------------------------------------------------------

// `replay --ghost`: the ghost flies along a replay too (its screenshot is written; the window's
// code has it in the replay's scene once loaded); a ghost of another scenario is refused.
TEST_F(GhostApp, AReplayCanHaveAGhost) {
  const fs::path home = fresh_user_dirs("replay");
  const std::string novice = record(scenario("mi_helix.toml"), "novice", 4.0, "replay_novice.mcap");
  const std::string experienced =
      record(scenario("mi_helix.toml"), "experienced", 4.0, "replay_experienced.mcap");
  const std::string slow = record(scenario("mi_helix_slow.toml"), "novice", 1.0, "replay_slow.mcap");
  const std::string shot = (home / "replay.png").string();
  EXPECT_EQ(test::run_mixpilot(MIXPILOT_BINARY, "replay " + quoted(novice) + " --headless --ghost " +
                                                    quoted(experienced) + " --screenshot 2:" +
                                                    quoted(shot),
                               home),
            0)
      << test::read_file(home / "out.txt");
  EXPECT_TRUE(fs::exists(shot));
  EXPECT_EQ(test::run_mixpilot(MIXPILOT_BINARY, "replay " + quoted(novice) + " --headless --ghost " +
                                                    quoted(slow) + " --screenshot 2:" +
                                                    quoted(shot) + " --force",
                               home),
            1);
  EXPECT_NE(test::read_file(home / "out.txt").find("not of 'mi_helix'"), std::string::npos)
      << test::read_file(home / "out.txt");

  cli::FlyOptions o;
  o.replay = true;
  o.pilot = novice;
  o.ghost = experienced;
  o.command = "replay";
  o.history = "off";
  cli::Trainer app(o);
  std::string error;
  ASSERT_TRUE(app.open_replay(novice, error)) << error;
  ASSERT_TRUE(frames_until(app, [&] { return app.replay() && app.replay()->scene().ghost; }))
      << app.run_info().message;
  EXPECT_EQ(app.replay()->scene().ghost->path, experienced);
}

}  // namespace
}  // namespace mixpilot
