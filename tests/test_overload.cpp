// Sustained overload in real time (SPEC §4, §8): a solver slowed artificially — its deadline cut
// to 1 µs for two seconds, so every solve there overruns as on a machine that cannot keep up —
// hands the vehicle to the safe controller after the rule's fallbacks in a row, the vehicle is
// not lost, the events are in the recording, and the recording replays bit for bit with the
// same score, deadline misses included. Outside the stretch the deadline is a second, so a
// machine too loaded (or sanitized) to solve within Δt cannot start the overload early.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "core/modes/report.hpp"
#include "core/recording/replay.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "temp_files.hpp"

namespace mixpilot::cli {
namespace {

TEST(Overload, TheSafeControllerFliesWhileTheSolverCannotKeepUpAndTheReplayIsExact) {
  const std::string scenario = MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml";
  std::string error, text;
  ASSERT_TRUE(read_text_file(scenario, text, error)) << error;
  ModeRequest request;
  request.duration = 5.0;
  request.pilot_name = "novice";
  auto mode = make_mode(text, scenario, std::move(request), error);
  ASSERT_TRUE(mode) << error;
  const std::int64_t slow_from = 60, slow_to = 193;  // 0.9 s to 2.9 s

  // The slow solver: its deadline from step slow_from to slow_to (a sink runs after a step,
  // so it sets the next one's); a second before and after.
  constexpr double kGenerousUs = 1e6;
  struct SlowSolver final : TelemetrySink {
    Mode* mode;
    std::int64_t from, to;
    void on_sample(const Telemetry& s) override {
      if (s.step == from - 1) mode->set_deadline_us(1.0);
      if (s.step == to) mode->set_deadline_us(kGenerousUs);
    }
  } slow;
  slow.mode = mode.get();
  slow.from = slow_from;
  slow.to = slow_to;

  const std::string path = test::fresh_path("overload", "flight.mcap").string();
  RecordingSink recorder;
  RecordingSink::Settings rs;
  rs.when_full = RecordingSink::FullRing::drop;
  ASSERT_TRUE(recorder.open(path, *mode, {to_string(mode->kind()), text, scenario, 1, "novice"},
                            error, rs))
      << error;
  Session session(*mode);
  session.add_sink(&recorder);
  session.add_sink(&slow);
  RealtimeRunner runner(session, 1024);  // sets the deadline Δt
  mode->set_deadline_us(kGenerousUs);
  runner.start();
  while (runner.running()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  runner.stop();
  ASSERT_TRUE(recorder.close(error)) << error;
  EXPECT_EQ(recorder.dropped(), 0);
  EXPECT_FALSE(mode->lost());
  const RealtimeStats st = runner.stats();

  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  ASSERT_EQ(std::int64_t(rec->channels.size()), mode->steps_total());
  // Every slowed solve overran, and only those; the safe controller took over at the rule's
  // fifth one and held until five good solves after the stretch.
  std::int64_t first_safe = -1, last_safe = -1, misses = 0;
  for (std::int64_t k = 0; k < std::int64_t(rec->channels.size()); ++k) {
    const std::uint32_t e = rec->channels[std::size_t(k)].events;
    const bool slowed = k >= slow_from && k <= slow_to;
    EXPECT_EQ((e & kEventOverrun) != 0, slowed) << "step " << k;
    if (e & kEventSafeHold) {
      if (first_safe < 0) first_safe = k;
      last_safe = k;
    }
    misses += (e & kEventDeadlineMiss) != 0;
  }
  const std::int64_t after = rti_defaults::kSafeAfterFallbacks;
  EXPECT_EQ(first_safe, slow_from + after - 1);
  EXPECT_NE(rec->channels[std::size_t(first_safe)].events & kEventSwitch, 0u);
  EXPECT_EQ(last_safe, slow_to + after - 1);
  EXPECT_GE(misses, slow_to - slow_from + 1);  // every overrun computed past Δt
  // One count of deadline misses: the runner's, the recording's and the score's.
  EXPECT_EQ(st.deadline_misses, misses);
  const auto* mi = dynamic_cast<const MiMode*>(mode.get());
  ASSERT_TRUE(mi);
  EXPECT_EQ(mi->score().deadline_misses, misses);
  EXPECT_EQ(mi->score().collisions, 0);
  EXPECT_GE(st.safe_hold_steps, slow_to - slow_from);

  // The replay: the recorded overruns forced, every step bit for bit, the same score.
  auto replayed = replay_mode(*rec, path, rec->metadata.at("scenario"), scenario, {}, error);
  ASSERT_TRUE(replayed) << error;
  ReplayCheck check(*rec);
  Session again(*replayed);
  again.add_sink(&check);
  again.run();
  EXPECT_EQ(check.first_difference(replayed->steps_done()), "");
  EXPECT_EQ(replay_metrics(*replayed, *rec), with_lost_fields(to_metrics(mi->score()), *mode));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mixpilot::cli
