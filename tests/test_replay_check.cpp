// Replay integrity (core/recording/replay.hpp): a recording flown again is checked step by step, and a
// change to any recorded pilot command — the last one included, whose only trace is the last
// applied input — is caught.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/recording/replay.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot::cli {
namespace {

RecordingContents record(const std::string& scenario, double seconds, const char* pilot,
                         std::vector<std::int64_t> overruns = {}) {
  std::string error, text;
  EXPECT_TRUE(read_text_file(scenario, text, error)) << error;
  ModeRequest request;
  request.duration = seconds;
  if (pilot) request.pilot_name = pilot;
  auto mode = make_mode(text, scenario, std::move(request), error);
  EXPECT_TRUE(mode) << error;
  const std::string path = test::fresh_path("replay_check", "run.mcap").string();
  RecordingSink sink;
  EXPECT_TRUE(sink.open(path, *mode, {to_string(mode->kind()), text, scenario, 1, pilot ? pilot : ""},
                        error))
      << error;
  // Overruns as a real-time run would have them where the clock said so (SPEC §4).
  mode->replay_timing(std::move(overruns));
  Session session(*mode);
  session.add_sink(&sink);
  session.run();
  EXPECT_TRUE(sink.close(error)) << error;
  auto rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  std::filesystem::remove(path);
  return rec ? *rec : RecordingContents{};
}

// Flies `rec` again from its embedded scenario; the check's verdict.
std::string replay(const RecordingContents& rec, const std::string& source) {
  std::string error;
  auto mode = replay_mode(rec, "rec.mcap", rec.metadata.at("scenario"), source, {}, error);
  EXPECT_TRUE(mode) << error;
  if (!mode) return error;
  ReplayCheck check(rec);
  Session session(*mode);
  session.add_sink(&check);
  session.run();
  return check.first_difference(mode->steps_done());
}

const std::string kMi = MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml";

TEST(ReplayCheck, AnUntouchedRecordingReplaysExactly) {
  const RecordingContents rec = record(kMi, 1.5, "novice");
  ASSERT_EQ(rec.pilot.size(), 100u);
  EXPECT_EQ(replay(rec, kMi), "");
}

TEST(ReplayCheck, TheLastPilotCommandIsCovered) {
  RecordingContents rec = record(kMi, 1.5, "novice");
  rec.pilot.back().roll += 1e-3;
  EXPECT_EQ(replay(rec, kMi), "the applied input of step 99 differs from the recorded one");
}

TEST(ReplayCheck, AnEarlierCommandChangesTheStates) {
  const RecordingContents original = record(kMi, 1.5, "novice");
  RecordingContents rec = original;
  rec.pilot[40].pitch -= 1e-3;
  EXPECT_EQ(replay(rec, kMi), "the applied input of step 40 differs from the recorded one");
  // The states flown from the changed command on differ from the recorded ones; before it, not.
  std::string error;
  auto mode = replay_mode(rec, "rec.mcap", rec.metadata.at("scenario"), kMi, {}, error);
  ASSERT_TRUE(mode) << error;
  std::size_t first_different = 0;
  while (mode->step()) {
    const Telemetry& s = mode->telemetry();
    const auto& x = original.states[std::size_t(s.step)].x;
    const bool same = std::equal(x.begin(), x.end(), s.x.data());
    if (!same && first_different == 0) first_different = std::size_t(s.step);
  }
  EXPECT_EQ(first_different, 41u);  // the state after the changed command acted
}

// λ is compared too: a recording whose λ alone was changed (by the last bit) does not replay.
TEST(ReplayCheck, ARecordedLambdaIsCovered) {
  RecordingContents rec = record(kMi, 1.5, "novice");
  rec.lambda[60].lambda = std::nextafter(rec.lambda[60].lambda, 2.0);
  EXPECT_EQ(replay(rec, kMi), "the lambda of step 60 differs from the recorded one");
}

TEST(ReplayCheck, AMissingStepIsCaught) {
  RecordingContents rec = record(kMi, 1.5, "novice");
  rec.states.pop_back();
  EXPECT_NE(replay(rec, kMi), "");
}

// A step whose solve overran (SPEC §4) applies the previous solution's next input and is
// recorded as such; the replay reproduces it, so the recording replays bit for bit — and
// would not if the replay ignored the recorded overruns.
TEST(ReplayCheck, RecordedOverrunsAreReplayed) {
  for (const std::string& scenario :
       {kMi, std::string(MIXPILOT_SOURCE_DIR "/scenarios/obstacles_cluttered.toml"),
        std::string(MIXPILOT_SOURCE_DIR "/scenarios/tracking_helix.toml"),
        std::string(MIXPILOT_SOURCE_DIR "/scenarios/pendubot_swingup.toml")}) {
    const bool mi = scenario == kMi;
    const RecordingContents rec = record(scenario, 0.6, mi ? "novice" : nullptr, {5, 6, 17});
    int overruns = 0;
    for (std::size_t j = 0; j < rec.channels.size(); ++j) {
      const bool overrun = (rec.channels[j].events & kEventOverrun) != 0;
      overruns += overrun ? 1 : 0;
      if (overrun) {
        EXPECT_TRUE(rec.channels[j].events & kEventFallback) << scenario << " step " << j;
      }
    }
    EXPECT_EQ(overruns, 3) << scenario;
    EXPECT_EQ(replay(rec, scenario), "") << scenario;
    // Without the recorded overruns the replay departs from the recording.
    RecordingContents stripped = rec;
    for (auto& c : stripped.channels) c.events &= ~std::uint32_t(kEventOverrun);
    EXPECT_NE(replay(stripped, scenario), "") << scenario;
  }
}

// Seeded measurement noise and an input delay (SPEC §5.4's plant options): two flights of the
// same seed are identical, another seed flies differently (the noise is really there), and a
// recording replays bit for bit.
TEST(Noise, SeededMeasurementNoiseAndInputDelayReplayBitForBit) {
  std::string error, text;
  ASSERT_TRUE(read_text_file(kMi, text, error)) << error;
  const auto with = [&](const char* seed) {
    std::string t = text;
    const auto set = [&](const std::string& key, const std::string& value) {
      const auto at = t.find("\n" + key + " = ");
      ASSERT_NE(at, std::string::npos) << key;
      t.replace(at + 1, t.find('\n', at + 1) - at - 1, key + " = " + value);
    };
    set("input_delay", "0.03");
    set("position_noise", "0.01");
    set("seed", seed);
    const std::string path =
        test::fresh_path("replay_check", std::string("noisy_") + seed + ".toml").string();
    std::ofstream(path) << t;
    return path;
  };
  const std::string one = with("7"), same = with("7"), other = with("8");
  const RecordingContents a = record(one, 1.5, "novice");
  const RecordingContents b = record(same, 1.5, "novice");
  const RecordingContents c = record(other, 1.5, "novice");
  ASSERT_EQ(a.states.size(), 100u);
  bool identical = true, differs = false;
  for (std::size_t k = 0; k < a.states.size(); ++k) {
    identical = identical && a.states[k].x == b.states[k].x;
    differs = differs || a.states[k].x != c.states[k].x;
  }
  EXPECT_TRUE(identical) << "the same seed flew differently";
  EXPECT_TRUE(differs) << "another seed flew the same: no noise?";
  EXPECT_EQ(replay(a, one), "");
  EXPECT_EQ(replay(c, other), "");

  // Recorded by the app, replayed here: another binary draws and adds the same noise (the
  // noise, like the integrator's steps, is compiled once for every binary).
  const std::filesystem::path home = test::fresh_path("replay_check", "noisy_app");
  std::filesystem::create_directories(home);
  const std::string path = (home / "noisy.mcap").string();
  ASSERT_EQ(test::run_mixpilot(MIXPILOT_BINARY, "fly --scenario '" + one +
                                                    "' --pilot novice --headless --duration 1.5"
                                                    " --record '" + path + "'",
                               home),
            0)
      << test::read_file(home / "out.txt");
  const auto app = read_recording(path, error);
  ASSERT_TRUE(app) << error;
  ASSERT_EQ(app->states.size(), a.states.size());
  EXPECT_EQ(replay(*app, one), "");
  bool alike = true;
  for (std::size_t k = 0; k < a.states.size(); ++k)
    alike = alike && app->states[k].x == a.states[k].x;
  EXPECT_TRUE(alike) << "the app flew the seeded noisy flight differently from this binary";
}

TEST(ReplayCheck, OtherModesReplayToo) {
  const std::string pendubot = MIXPILOT_SOURCE_DIR "/scenarios/pendubot_swingup.toml";
  RecordingContents rec = record(pendubot, 0.2, nullptr);
  ASSERT_EQ(rec.states.size(), 100u);
  EXPECT_EQ(replay(rec, pendubot), "");
  rec.states[50].x[1] += 1e-12;
  EXPECT_EQ(replay(rec, pendubot), "the state of step 50 differs from the recorded one");
}

}  // namespace
}  // namespace mixpilot::cli
