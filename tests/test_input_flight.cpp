// A person flies (SPEC §6), end to end: `mixpilot fly --pilot gamepad --gamepad-script` drives
// SDL's virtual joystick in the mixpilot process through a real-time headless session; the
// recording holds the raw Joy messages and scores as the live run did; unplugging hands the
// vehicle to the planner at once and re-centring returns it without a jump. In-process: the
// latency from an axis change to the controller's use of it, and the haptic cue against λ.
#include <gtest/gtest.h>

#include <SDL2/SDL.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <thread>

#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/recording.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "input/device_pilot.hpp"
#include "input/gamepad.hpp"
#include "input/virtual_gamepad.hpp"
#include "models/mikrokopter.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
const std::string kSrc = MIXPILOT_SOURCE_DIR;
const std::string kMixpilot = MIXPILOT_BINARY;

int run(const std::string& args, const fs::path& home) {
  return test::run_mixpilot(kMixpilot, args, home);
}
using test::numbers;
using test::read_file;

double channel(const ModeChannelsMsg& m, const std::string& name) {
  for (std::size_t i = 0; i < m.names.size(); ++i)
    if (m.names[i] == name) return m.values[i];
  return NAN;
}

// The novice's commands on mi_helix as a script (its first `seconds`).
fs::path novice_script(const fs::path& dir, double seconds) {
  const fs::path rec = dir / "novice.mcap", csv = dir / "novice.csv";
  EXPECT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot novice --headless "
                "--duration " + std::to_string(seconds) + " --record " + rec.string(), dir), 0)
      << read_file(dir / "out.txt");
  EXPECT_EQ(run("gamepad-script " + rec.string() + " -o " + csv.string(), dir), 0)
      << read_file(dir / "out.txt");
  return csv;
}

TEST(GamepadFlight, TheNovicesCommandsThroughSdlInRealTime) {
  const fs::path dir = test::fresh_path("input_flight", "script");
  fs::create_directories(dir);
  const fs::path csv = novice_script(dir, 20);
  const fs::path rec = dir / "pad.mcap", report = dir / "pad.json", score = dir / "score.json";
  ASSERT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot gamepad "
                "--gamepad-script " + csv.string() + " --headless --realtime --duration 20 "
                "--record " + rec.string() + " --report " + report.string(), dir), 0)
      << read_file(dir / "out.txt");
  const auto live = numbers(read_file(report));
  // In real time: 20 s of flight take at least 20 s less a period of wall time.
  std::smatch wall;
  const std::string out = read_file(dir / "out.txt");
  ASSERT_TRUE(std::regex_search(out, wall, std::regex("flown in ([0-9.]+) s of wall time"))) << out;
  EXPECT_GE(std::stod(wall[1]), 20.0 - 0.015);
  EXPECT_NE(out.find("real time: "), std::string::npos) << out;
  // How well it flew depends on when each script row reached the controller, which is the
  // machine's timing, not a property of the path; what holds whatever the timing: nothing is hit
  // (the MPC's safety constraints), and the recording replays to the live score (below).
  EXPECT_EQ(live.at("collisions"), 0.0);
  std::string error;
  const auto r = read_recording(rec.string(), error);
  ASSERT_TRUE(r) << error;
  ASSERT_EQ(r->states.size(), 1333u);  // 20 s of 15 ms steps
  ASSERT_EQ(r->joy.size(), r->states.size());  // the raw pad, every step
  EXPECT_EQ(r->joy[0].axes.size(), 6u);
  EXPECT_EQ(r->pilot[0].source, "gamepad");
  // The sticks moved: the novice's roll reached the right stick.
  double most = 0;
  for (const JoyMsg& j : r->joy) most = std::max(most, double(std::abs(j.axes[2])));
  EXPECT_GT(most, 0.05);
  // `score` of the recording: the live score, field for field.
  ASSERT_EQ(run("score " + rec.string() + " --json " + score.string(), dir), 0)
      << read_file(dir / "out.txt");
  const auto scored = numbers(read_file(score));
  for (const char* k : {"skill", "progress", "time_in_ball", "max_deviation_m", "rms_deviation_m",
                        "mean_lambda", "min_lambda", "collisions", "override_rms"})
    EXPECT_EQ(scored.at(k), live.at(k)) << k;
}

// Unplugged at 5 s, plugged back at 15 s with the roll stick deflected, centred at 16 s.
TEST(GamepadFlight, UnpluggingHandsThePlannerTheVehicleAndRecentringReturnsIt) {
  const fs::path dir = test::fresh_path("input_flight", "unplug");
  fs::create_directories(dir);
  const fs::path novice = novice_script(dir, 5);
  std::string script = read_file(novice);
  script += "5.0,unplug\n15.0,plug\n15.0,0,0,0.5,0\n16.0,0,0,0,0\n";
  const fs::path csv = dir / "unplug.csv", rec = dir / "unplug.mcap";
  std::ofstream(csv) << script;
  ASSERT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot gamepad "
                "--gamepad-script " + csv.string() + " --headless --realtime --duration 20 "
                "--record " + rec.string(), dir), 0)
      << read_file(dir / "out.txt");
  std::string error;
  const auto r = read_recording(rec.string(), error);
  ASSERT_TRUE(r) << error;
  const double dt = 0.015;
  std::size_t lost = 0;
  while (lost < r->pilot.size() && r->pilot[lost].input_state != 1) ++lost;
  ASSERT_LT(lost, r->pilot.size()) << "the unplug was never seen";
  // Within the input timeout of the unplug (5 s; a device that stops reporting is lost then at
  // the latest, however the threads were scheduled), and the planner has the whole authority
  // from it on.
  const double timeout = input::InputSettings{}.input_timeout_s;
  EXPECT_LE(double(lost) * dt, 5.0 + timeout + dt);
  EXPECT_GT(double(lost) * dt, 5.0 - dt);
  EXPECT_NE(r->channels[lost].events & kEventInputLost, 0u);
  // The summary says for how long (10 s, to a step either side of the unplug's timing).
  const std::string out = read_file(dir / "out.txt");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("input was lost for ([0-9.]+) s in all")))
      << out;
  EXPECT_NEAR(std::stod(m[1]), 10.0, 2 * (timeout + dt));  // each end seen within the timeout
  for (std::size_t k = lost; k < lost + std::size_t(10.0 / dt); ++k) {
    ASSERT_EQ(r->lambda[k].lambda, 0.0) << k;
    EXPECT_EQ(r->pilot[k].authority, 0.0);
    // The planner flies every step: its QP at λ = 0 is solved, never a fallback.
    EXPECT_EQ(r->channels[k].events & kEventFallback, 0u) << k;
    // 10 s in B and nothing hit.
    EXPECT_LE(channel(r->channels[k], "deviation"), channel(r->channels[k], "ball radius r")) << k;
    EXPECT_EQ(r->channels[k].events & kEventCollision, 0u) << k;
  }
  // Plugged back at 15 s: waiting for the sticks (deflected) until 16 s, then returning.
  const auto state_at = [&](double t) { return r->pilot[std::size_t(t / dt)].input_state; };
  EXPECT_EQ(state_at(15.5), 2);  // re-centre
  EXPECT_EQ(state_at(16.5), 3);  // returning (1 s ramp)
  EXPECT_EQ(state_at(17.5), 0);  // the pilot flies again
  // No jump: the MPC's commanded attitude changes per step no more through the return than it
  // did while the novice flew (plus a tenth of a degree of slack).
  const auto largest_step = [&](double t0, double t1) {
    double m = 0;
    for (std::size_t k = std::size_t(t0 / dt) + 1; k < std::size_t(t1 / dt); ++k)
      m = std::max({m, std::abs(r->applied[k].roll - r->applied[k - 1].roll),
                    std::abs(r->applied[k].pitch - r->applied[k - 1].pitch)});
    return m;
  };
  const double flying = largest_step(1.0, 5.0), returning = largest_step(15.0, 18.0);
  std::printf("largest attitude step: %.4f rad while flying, %.4f rad through the return\n",
              flying, returning);
  EXPECT_LE(returning, flying + 0.0017);
  // The recording replays exactly (the authority and the input state included).
  ASSERT_EQ(run("score " + rec.string(), dir), 0) << read_file(dir / "out.txt");
}

// A mixed-initiative session of mi_helix on the real-time runner with a DevicePilot reading a
// Gamepad fed by a virtual pad.
struct PadSession {
  input::VirtualGamepad pad;
  input::Gamepad gamepad;
  input::InputSettings settings;
  std::unique_ptr<Mode> mode;
  input::DevicePilot* pilot = nullptr;

  explicit PadSession(double seconds) {
    std::string error;
    EXPECT_TRUE(pad.plug(error)) << error;
    EXPECT_TRUE(gamepad.start({}, error)) << error;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (!gamepad.connected() && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_TRUE(gamepad.connected());
    auto p = std::make_unique<input::DevicePilot>(gamepad, settings, 0.015,
                                                  models::MikroKopter().hover_speed());
    pilot = p.get();
    ModeRequest request;
    request.duration = seconds;
    request.pilot_source = std::move(p);
    mode = load_mode(kSrc + "/scenarios/mi_helix.toml", std::move(request), error);
    EXPECT_TRUE(mode) << error;
  }
};

// What each step's command was made of: when the step read the device, and the roll stick.
struct StepLog : TelemetrySink {
  input::DevicePilot* pilot = nullptr;
  input::Gamepad* gamepad = nullptr;
  input::HapticSettings haptic;
  std::vector<std::int64_t> read_ns;    // steady ns when the step read the device
  std::vector<std::int64_t> sample_ns;  // steady ns when the sample it read was taken
  std::vector<double> roll_stick, lambda;
  void on_sample(const Telemetry& s) override {
    read_ns.push_back(pilot->read_ns());
    sample_ns.push_back(pilot->reading().alive_ns);
    roll_stick.push_back(pilot->reading().sticks.right_x);
    lambda.push_back(s.lambda);
    if (gamepad) gamepad->set_rumble(input::rumble_intensity(s.lambda, haptic));
  }
};

TEST(GamepadLatency, AnAxisChangeIsUsedWithinOneControlPeriod) {
  constexpr double kSeconds = 6.0;
  PadSession ps(kSeconds);
  ASSERT_TRUE(ps.mode);
  Session session(*ps.mode);
  StepLog log;
  log.pilot = ps.pilot;
  const std::size_t steps = std::size_t(ps.mode->steps_total());
  log.read_ns.reserve(steps);
  log.sample_ns.reserve(steps);
  log.roll_stick.reserve(steps);
  log.lambda.reserve(steps);
  session.add_sink(&log);
  // Changes at random phases: every 3–11 ms a new roll-stick value, stamped before and after
  // it is set. The changer may lose its core between the two (the control and poll threads
  // take precedence), so a change is known to be made between its stamps, not at either.
  struct Change {
    std::int64_t begun_ns, made_ns;
    double value;
  };
  std::vector<Change> changes;
  changes.reserve(4000);
  std::atomic<bool> stop{false};
  RealtimeRunner runner(session, 64);
  std::thread changer([&] {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> wait_us(3000, 11000);
    for (int i = 1; !stop.load(); ++i) {
      const double v = 0.001 * double(i % 400 - 200);  // distinct from its neighbours
      const std::int64_t begun = input::steady_ns();
      ps.pad.set_axis(SDL_CONTROLLER_AXIS_RIGHTX, v);
      changes.push_back({begun, input::steady_ns(), v});
      std::this_thread::sleep_for(std::chrono::microseconds(wait_us(rng)));
    }
  });
  runner.start();
  while (runner.running()) {
    Telemetry t;
    while (runner.telemetry().pop(t)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  stop = true;
  changer.join();
  runner.stop();
  // Change i is used by the first step whose reading holds it or a later change; its latency
  // runs from when it was certainly made to that step's read.
  std::vector<double> latency_ms, age_ms;
  std::size_t next = 0;        // the first change not yet used
  std::size_t missed = 0;      // changes a sample taken after them did not hold
  double worst_miss_ms = 0.0;  // by how much the worst of them missed
  for (std::size_t k = 0; k < log.read_ns.size(); ++k) {
    age_ms.push_back(1e-6 * double(log.read_ns[k] - log.sample_ns[k]));
    // The newest change this step saw: the last one begun before its read with its value.
    std::size_t seen = next;
    bool found = false;
    for (std::size_t i = next; i < changes.size() && changes[i].begun_ns < log.read_ns[k]; ++i)
      if (std::abs(changes[i].value - log.roll_stick[k]) < 2e-5) seen = i, found = true;
    if (!found) continue;
    for (std::size_t i = next; i <= seen; ++i) {
      latency_ms.push_back(1e-6 * double(log.read_ns[k] - changes[i].made_ns));
      // A change made before the previous step's sample was taken: that sample, and that
      // step, had to hold it.
      if (k > 0 && changes[i].made_ns < log.sample_ns[k - 1]) {
        ++missed;
        worst_miss_ms =
            std::max(worst_miss_ms, 1e-6 * double(log.sample_ns[k - 1] - changes[i].made_ns));
      }
    }
    next = seen + 1;
  }
  ASSERT_GT(latency_ms.size(), 400u);
  std::sort(latency_ms.begin(), latency_ms.end());
  std::sort(age_ms.begin(), age_ms.end());
  const auto at = [](const std::vector<double>& v, int percent) {
    return v[v.size() * std::size_t(percent) / 100];
  };
  std::printf("axis change → controller: %zu changes, p50 %.2f ms, p99 %.2f ms, max %.2f ms "
              "(control period 15 ms; to the read of the step that uses it)\n"
              "age of the sample a step reads: p50 %.3f ms, p99 %.3f ms, max %.3f ms; "
              "changes a later sample missed: %zu (worst by %.3f ms)\n",
              latency_ms.size(), at(latency_ms, 50), at(latency_ms, 99), latency_ms.back(),
              at(age_ms, 50), at(age_ms, 99), age_ms.back(), missed, worst_miss_ms);
  // No change is lost on the way: every sample holds every change set before it was taken, so
  // a change waits at most for the next step's read after the sample the previous step read.
  EXPECT_EQ(missed, 0u);
  // The sample a step reads is fresh: the device is sampled read_lead before each read (or, that
  // sample late, the regular poll before it is used). Without the sample before the read the
  // age would spread evenly over a poll interval: the median is held to halfway between the two
  // designs' medians. Its tail is how late the kernel wakes the poll thread, not this code's.
  const input::Gamepad::Options pad;
  EXPECT_LE(at(age_ms, 50), 1e3 * (pad.read_lead_s + pad.poll_interval_s / 2) / 2);
  // Hence a change reaches the controller within one control period: a change just after a
  // step's sample is in the next step's. The sleeping threads may wake late under a
  // general-purpose kernel, which stretches the worst changes (a preemption, not a lost
  // change: that is `missed` above), not the 99th percentile. A controller reading the
  // previous step's stick gave a median of 22.8 ms.
  const double bound_ms = 1e3 * (ps.mode->dt() + pad.poll_interval_s + pad.read_lead_s);
  EXPECT_LE(at(latency_ms, 99), bound_ms);
  EXPECT_LE(at(latency_ms, 50), bound_ms / 2);
}

TEST(GamepadHaptic, TheRumbleFollowsLambdaBelowTheThreshold) {
  // The novice's commands make λ fall well below 0.5 on mi_helix (SPEC §5.4).
  const fs::path dir = test::fresh_path("input_flight", "haptic");
  fs::create_directories(dir);
  std::string error;
  const auto script = input::load_script(novice_script(dir, 12).string(), error);
  ASSERT_TRUE(script) << error;
  PadSession ps(12.0);
  ASSERT_TRUE(ps.mode);
  Session session(*ps.mode);
  StepLog log;
  log.pilot = ps.pilot;
  log.gamepad = &ps.gamepad;
  log.read_ns.reserve(1000);
  log.sample_ns.reserve(1000);
  log.roll_stick.reserve(1000);
  log.lambda.reserve(1000);
  session.add_sink(&log);
  RealtimeRunner runner(session, 64);
  ps.pad.play(*script, input::steady_ns());
  runner.start();
  while (runner.running()) {
    Telemetry t;
    while (runner.telemetry().pop(t)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  runner.stop();
  ps.pad.stop();
  std::this_thread::sleep_for(std::chrono::milliseconds(400));  // past the cue's hold time
  const auto rumbles = ps.pad.rumbles();
  ASSERT_FALSE(rumbles.empty());
  // Each rumble the pad received during the flight is the intensity of the λ of a step that
  // had just ended. After the last step the pad holds the last cue at most for the hold time,
  // then stops (one zero), and nothing follows.
  const double last_cue = input::rumble_intensity(log.lambda.back(), log.haptic);
  const std::int64_t end_ns = log.read_ns.back() + 40'000'000;
  std::size_t matched = 0, strong = 0, after_end = 0;
  for (const input::RumbleEvent& e : rumbles) {
    if (e.at_ns > end_ns) {
      ++after_end;
      EXPECT_LE(e.at_ns - end_ns, input::Gamepad::kRumbleHoldNs + 20'000'000);
      if (&e == &rumbles.back())
        EXPECT_EQ(e.intensity, 0.0) << "the cue stops after the flight";
      else
        EXPECT_NEAR(e.intensity, last_cue, 1.0 / 256) << "only the last cue is held";
      continue;
    }
    bool ok = false;
    for (std::size_t k = 0; k < log.read_ns.size() && !ok; ++k) {
      const double age_ms = 1e-6 * double(e.at_ns - log.read_ns[k]);
      if (age_ms < 0 || age_ms > 40) continue;
      ok = std::abs(e.intensity - input::rumble_intensity(log.lambda[k], log.haptic)) <= 1.0 / 256;
    }
    matched += ok;
    if (!ok)
      std::printf("unmatched rumble %.4f at %.1f ms after the first step\n", e.intensity,
                  1e-6 * double(e.at_ns - log.read_ns.front()));
    strong += e.intensity > 0.3;
  }
  EXPECT_GE(after_end, 1u);
  const double min_lambda = *std::min_element(log.lambda.begin(), log.lambda.end());
  std::printf("%zu rumbles, %zu matched to a step's λ, %zu above 0.3; min λ %.3f\n",
              rumbles.size(), matched, strong, min_lambda);
  EXPECT_EQ(matched, rumbles.size() - after_end);
  EXPECT_LT(min_lambda, 0.3);
  EXPECT_GT(strong, 0u);  // λ well below the threshold: a strong cue
}

}  // namespace
}  // namespace mixpilot
