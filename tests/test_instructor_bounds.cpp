// The instructor's bounds on λ (SPEC §10): λ_applied = min(max(λ_PH, floor), ceiling, the
// input's cap), from the step after they are set; the reason names the bound that set λ; a
// flight's first bounds are in its recording and its replay flies with them bit for bit; a
// snapshot carries them; bounds that are not 0 ≤ floor ≤ ceiling ≤ 1, or on a mode without λ,
// or unreadable in a recording, are refused with the reason.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/control/ph_index.hpp"
#include "core/modes/debrief.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"

#include "temp_files.hpp"

namespace mixpilot {
namespace {

const std::string kHelix = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";
const std::string kPendubot = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/pendubot_swingup.toml";

ModeRequest novice(double duration, AuthorityBounds bounds = {}) {
  ModeRequest r;
  r.pilot_name = "novice";
  r.duration = duration;
  r.bounds = bounds;
  return r;
}

std::unique_ptr<Mode> load(ModeRequest request) {
  std::string error;
  auto mode = load_mode(kHelix, std::move(request), error);
  EXPECT_TRUE(mode) << error;
  return mode;
}

// λ of one step from its own reason and the bounds in force (SPEC §10), the input's cap 1.
double bounded(const Telemetry& s, const AuthorityBounds& b) {
  return std::min(std::max(s.reason.ph_index, b.floor), b.ceiling);
}

// Set between two steps, the bounds hold from the next step on, exactly by SPEC §10's
// formula, and the reason says which one set λ; before them λ is the PH index's own.
TEST(InstructorBounds, CeilingAndFloorHoldFromTheNextStep) {
  auto mode = load(novice(10.0));
  ASSERT_TRUE(mode);
  EXPECT_EQ(mode->authority_bounds(), AuthorityBounds{});
  const AuthorityBounds ceiling{0.0, 0.3}, floor{0.6, 1.0};
  int capped_by_ceiling = 0, raised_by_floor = 0;
  while (!mode->finished()) {
    const std::int64_t k = mode->steps_done();
    if (k == 100) {
      ASSERT_TRUE(mode->set_authority_bounds(ceiling));
    }
    if (k == 300) {
      ASSERT_TRUE(mode->set_authority_bounds(floor));
    }
    ASSERT_TRUE(mode->step());
    const Telemetry& s = mode->telemetry();
    const AuthorityBounds in_force = k < 100 ? AuthorityBounds{} : k < 300 ? ceiling : floor;
    if (!s.solved || s.reason.node < 0) continue;
    ASSERT_EQ(s.lambda, bounded(s, in_force)) << "step " << k;
    if (k < 100) {
      ASSERT_EQ(s.reason.cap, LambdaCap::none) << k;
    } else if (k < 300) {
      ASSERT_LE(s.lambda, 0.3) << k;
      const bool held = s.reason.ph_index > 0.3;
      ASSERT_EQ(s.reason.cap, held ? LambdaCap::instructor_ceiling : LambdaCap::none) << k;
      capped_by_ceiling += held;
    } else {
      ASSERT_GE(s.lambda, 0.6) << k;
      const bool held = s.reason.ph_index < 0.6;
      ASSERT_EQ(s.reason.cap, held ? LambdaCap::instructor_floor : LambdaCap::none) << k;
      raised_by_floor += held;
    }
  }
  EXPECT_EQ(mode->authority_bounds(), floor);
  // The novice's PH index crosses both bounds, so both were seen to act.
  EXPECT_GT(capped_by_ceiling, 20);
  EXPECT_GT(raised_by_floor, 20);
}

// READY (before the first step) says what the flight starts with: the telemetry's λ is the one
// the first step uses — the initial λ within the bounds (a ceiling below it, a floor above it),
// 1 for a probe — with the bound or the probe as its reason and the bounds in force; without
// bounds it is the initial λ. The first step then flies with exactly that λ (the emulated
// pilot's input is never lost), and bounds set at READY move it at once.
TEST(InstructorBounds, ReadyShowsTheLambdaTheFirstStepUses) {
  struct Case {
    AuthorityBounds bounds;
    Assistance assist;
    double lambda;
    LambdaCap cap;
  };
  const double initial = ph_defaults::kInitialLambda;
  ASSERT_GT(initial, 0.3);
  ASSERT_LT(initial, 0.7);
  const Case cases[] = {{{}, Assistance::on, initial, LambdaCap::none},
                        {{0.0, 0.3}, Assistance::on, 0.3, LambdaCap::instructor_ceiling},
                        {{0.7, 1.0}, Assistance::on, 0.7, LambdaCap::instructor_floor},
                        {{0.0, 0.9}, Assistance::on, initial, LambdaCap::none},
                        {{}, Assistance::off, 1.0, LambdaCap::probe}};
  for (const Case& c : cases) {
    ModeRequest r = novice(1.0, c.bounds);
    r.assist = c.assist;
    auto mode = load(std::move(r));
    ASSERT_TRUE(mode);
    const Telemetry ready = mode->telemetry();
    const std::string what = "bounds " + std::to_string(c.bounds.floor) + ".." +
                             std::to_string(c.bounds.ceiling) +
                             (c.assist == Assistance::off ? " (probe)" : "");
    EXPECT_FALSE(ready.solved) << what;
    EXPECT_EQ(ready.lambda, c.lambda) << what;
    EXPECT_EQ(ready.reason.cap, c.cap) << what;
    EXPECT_EQ(ready.instructor.bounds, c.bounds) << what;
    ASSERT_GE(ready.num_channels, 1);
    EXPECT_EQ(ready.channels[0].value, c.lambda) << what << ": the λ plot's first point";
    ASSERT_TRUE(mode->step());
    EXPECT_EQ(mode->telemetry().lambda, ready.lambda) << what << ": the first step's λ";
    EXPECT_EQ(mode->telemetry().reason.cap, ready.reason.cap) << what;
  }
  // Bounds set at READY (a lesson step, an instructor's command before the start) show at once.
  auto mode = load(novice(1.0));
  ASSERT_TRUE(mode);
  ASSERT_TRUE(mode->set_authority_bounds({0.0, 0.25}));
  EXPECT_EQ(mode->telemetry().lambda, 0.25);
  EXPECT_EQ(mode->telemetry().instructor.bounds, (AuthorityBounds{0.0, 0.25}));
  ASSERT_TRUE(mode->step());
  EXPECT_EQ(mode->telemetry().lambda, 0.25);
  // After the first step, bounds take effect from the next one: the telemetry is that step's.
  const double flown = mode->telemetry().lambda;
  ASSERT_TRUE(mode->set_authority_bounds({0.0, 0.1}));
  EXPECT_EQ(mode->telemetry().lambda, flown);
}

// A ceiling holds λ down by the instructor's choice: the debrief does not call that a takeover.
TEST(InstructorBounds, ACeilingIsNoTakeoverInTheDebrief) {
  auto mode = load(novice(4.0, {0.0, 0.2}));
  ASSERT_TRUE(mode);
  DebriefBuilder debrief(debrief_settings(*mode));
  std::vector<Telemetry> steps;
  while (mode->step()) {
    debrief.add(mode->telemetry());
    steps.push_back(mode->telemetry());
  }
  debrief.finish();
  int held = 0;
  for (const Telemetry& s : steps) held += s.reason.cap == LambdaCap::instructor_ceiling;
  EXPECT_GT(held, 100);  // λ = 0.2 < λ_T for most of the flight
  for (const DebriefEvent& e : debrief.events()) {
    if (e.kind != DebriefKind::takeover) continue;
    // Only where the PH index itself fell below λ_T.
    ASSERT_LT(std::size_t(e.start_step), steps.size());
    EXPECT_NE(steps[std::size_t(e.start_step)].reason.cap, LambdaCap::instructor_ceiling)
        << e.start;
    EXPECT_NE(e.reason.cap, LambdaCap::instructor_ceiling) << e.start;
  }
}

// A flight asked with bounds records them and its replay flies with them, bit for bit; a
// snapshot restores the bounds in force into a fresh flight.
TEST(InstructorBounds, RequestedBoundsAreRecordedReplayedAndSnapshotted) {
  const AuthorityBounds b{0.1, 0.4};
  auto mode = load(novice(3.0, b));
  ASSERT_TRUE(mode);
  EXPECT_EQ(mode->authority_bounds(), b);
  const std::string path = test::fresh_path("instructor_bounds", "bounded.mcap").string();
  std::string error, text;
  ASSERT_TRUE(read_text_file(kHelix, text, error)) << error;
  RecordingSink sink;
  ASSERT_TRUE(sink.open(path, *mode, {"mixed_initiative", text, kHelix, 1, "novice"}, error))
      << error;
  Session session(*mode);
  session.add_sink(&sink);
  session.run();
  ASSERT_TRUE(sink.close(error)) << error;

  auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  EXPECT_EQ(rec->metadata.at("authority_floor"), "0.1");
  EXPECT_EQ(rec->metadata.at("authority_ceiling"), "0.4");
  auto replayed = replay_mode(*rec, path, text, kHelix, {}, error);
  ASSERT_TRUE(replayed) << error;
  EXPECT_EQ(replayed->authority_bounds(), b);
  ReplayCheck check(*rec);
  Session again(*replayed);
  again.add_sink(&check);
  again.run();
  EXPECT_EQ(check.first_difference(replayed->steps_done()), "");

  // The snapshot: saved with the bounds in force, restored into a flight without any.
  auto first = load(novice(3.0));
  ASSERT_TRUE(first);
  for (int k = 0; k < 50; ++k) ASSERT_TRUE(first->step());
  ASSERT_TRUE(first->set_authority_bounds({0.2, 0.7}));
  ModeSnapshot snap;
  first->save(snap);
  auto second = load(novice(3.0));
  ASSERT_TRUE(second);
  ASSERT_EQ(second->restore(snap), RestoreStatus::ok);
  EXPECT_EQ(second->authority_bounds(), (AuthorityBounds{0.2, 0.7}));
  ASSERT_TRUE(first->step());
  ASSERT_TRUE(second->step());
  EXPECT_EQ(first->telemetry().lambda, second->telemetry().lambda);
}

// Every way in refuses bounds it cannot fly, and says why.
TEST(InstructorBounds, BadBoundsAreRefusedWithTheReason) {
  std::string error;
  for (const AuthorityBounds& bad : {AuthorityBounds{0.5, 0.4}, AuthorityBounds{-0.1, 1.0},
                                     AuthorityBounds{0.0, 1.5},
                                     AuthorityBounds{0.0, std::nan("")}}) {
    error.clear();
    EXPECT_FALSE(load_mode(kHelix, novice(1.0, bad), error));
    EXPECT_NE(error.find("0 <= floor <= ceiling <= 1"), std::string::npos) << error;
  }
  auto mode = load(novice(1.0));
  ASSERT_TRUE(mode);
  EXPECT_FALSE(mode->set_authority_bounds({0.9, 0.1}));
  EXPECT_EQ(mode->authority_bounds(), AuthorityBounds{});

  ModeRequest pendubot;
  pendubot.bounds = {0.0, 0.5};
  error.clear();
  EXPECT_FALSE(load_mode(kPendubot, std::move(pendubot), error));
  EXPECT_NE(error.find("authority bounds are for mixed_initiative"), std::string::npos) << error;
  auto p = load_mode(kPendubot, {}, error);
  ASSERT_TRUE(p) << error;
  EXPECT_FALSE(p->set_authority_bounds({0.0, 0.5}));

  // A recording's bounds: not a number, out of range, or crossed.
  const std::string path = test::fresh_path("instructor_bounds", "plain.mcap").string();
  std::string text;
  ASSERT_TRUE(read_text_file(kHelix, text, error)) << error;
  {
    auto m = load(novice(0.5));
    ASSERT_TRUE(m);
    RecordingSink sink;
    ASSERT_TRUE(sink.open(path, *m, {"mixed_initiative", text, kHelix, 1, "novice"}, error))
        << error;
    Session session(*m);
    session.add_sink(&sink);
    session.run();
    ASSERT_TRUE(sink.close(error)) << error;
  }
  auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  EXPECT_EQ(rec->metadata.count("authority_ceiling"), 0u);  // [0, 1] is not written
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"abc", "'authority_ceiling' metadata is 'abc', expected a number from 0 to 1"},
      {"0.5x", "'authority_ceiling' metadata is '0.5x'"},
      {"inf", "'authority_ceiling' metadata is 'inf'"},
      {"1.5", "(floor 0, ceiling 1.5) are not 0 <= floor <= ceiling <= 1"},
  };
  for (const auto& [value, expected] : cases) {
    RecordingContents bad = *rec;
    bad.metadata["authority_ceiling"] = value;
    error.clear();
    EXPECT_FALSE(replay_mode(bad, path, text, kHelix, {}, error)) << value;
    EXPECT_NE(error.find(path + ": its "), std::string::npos) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace mixpilot
