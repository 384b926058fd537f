// A station obeys an instructor's commands (SPEC §10): taken from the flight's command inbox
// between two steps on the stepping thread, applied from the next step on, carried in that
// step's telemetry, recorded on /instructor/command with the step and in the debrief's
// /rosout, applied again at the same steps by a replay (bit for bit), carried by snapshots.
// Per kind: a λ ceiling; a gust on the simulated plant that the NMPC does not know and
// recovers from; an extra delay on the measurement; a lost input with SPEC §6's recovery; a
// marker; pause, resume and end. Refusals say why; bad command data in a recording and in a
// script is refused with the file and the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/modes/command_inbox.hpp"
#include "core/modes/command_script.hpp"
#include "core/modes/debrief.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"

#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

const std::string kHelix = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";
const std::string kPendubot = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/pendubot_swingup.toml";
const std::string kTracking =
    std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/tracking_smooth_step.toml";
const std::string kObstacles =
    std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/obstacles_thrown_balls.toml";

std::unique_ptr<Mode> load(const std::string& path, double duration,
                           const std::string& pilot = "") {
  ModeRequest r;
  r.pilot_name = pilot;
  r.duration = duration;
  std::string error;
  auto mode = load_mode(path, std::move(r), error);
  EXPECT_TRUE(mode) << error;
  return mode;
}

InstructorCommand ceiling(double c) {
  InstructorCommand cmd;
  cmd.kind = InstructorCommandKind::bounds;
  cmd.bounds = {0.0, c};
  return cmd;
}
InstructorCommand gust(Eigen::Vector3d force, double duration) {
  InstructorCommand cmd;
  cmd.kind = InstructorCommandKind::gust;
  cmd.force = force;
  cmd.duration = duration;
  return cmd;
}
InstructorCommand simple(InstructorCommandKind kind, double value = 0.0) {
  InstructorCommand cmd;
  cmd.kind = kind;
  cmd.duration = value;
  cmd.delay = kind == InstructorCommandKind::extra_delay ? value : 0.0;
  if (kind == InstructorCommandKind::extra_delay) cmd.duration = 0.0;
  return cmd;
}
InstructorCommand marker(std::string_view text) {
  InstructorCommand cmd;
  cmd.kind = InstructorCommandKind::marker;
  cmd.text.assign(text);
  return cmd;
}

// A flight of `mode` through a session whose inbox gets `at[k]` just before step k, recorded
// into `path` (when given); every step's telemetry kept.
struct Flown {
  std::vector<Telemetry> steps;
  std::vector<DebriefEvent> events;
  bool ended_by_instructor = false;
};
Flown fly(Mode& mode, const std::vector<std::pair<std::int64_t, InstructorCommand>>& at,
          const std::string& path = "", const std::string& scenario = kHelix) {
  Flown out;
  CommandInbox inbox;
  Session session(mode);
  session.set_inbox(&inbox);
  RecordingSink sink;
  std::string error;
  if (!path.empty()) {
    std::string text;
    EXPECT_TRUE(read_text_file(scenario, text, error)) << error;
    EXPECT_TRUE(sink.open(path, mode,
                          {to_string(mode.kind()), text, scenario, 1,
                           mode.kind() == ModeKind::mixed_initiative ? "novice" : ""},
                          error))
        << error;
    session.add_sink(&sink);
  }
  std::size_t next = 0;
  for (;;) {
    while (next < at.size() && at[next].first <= mode.steps_done()) inbox.push(at[next++].second);
    if (!session.step()) break;
    if (session.stepped()) out.steps.push_back(mode.telemetry());
  }
  out.ended_by_instructor = session.ended_by_instructor();
  if (!path.empty()) {
    EXPECT_TRUE(sink.close(error, !mode.finished())) << error;
    out.events = sink.events();
  }
  return out;
}

double distance(const Telemetry& a, const Telemetry& b) {
  return (a.x.head<3>() - b.x.head<3>()).norm();
}

// (1) A λ ceiling of 0.3 sent mid-flight: from the step it took effect at on, the recorded λ
// never exceeds 0.3 (read back from the recording), while before it the novice's λ did; the
// step carries the command, the recording holds it at that step and the debrief says it.
TEST(Instructor, CeilingMidFlightHoldsInTheRecordingFromTheNextStep) {
  auto mode = load(kHelix, 4.0, "novice");
  ASSERT_TRUE(mode);
  const std::string path = test::fresh_path("instructor", "ceiling.mcap").string();
  const std::int64_t k = 100;
  const Flown f = fly(*mode, {{k, ceiling(0.3)}}, path);
  ASSERT_EQ(f.steps.size(), std::size_t(mode->steps_total()));
  ASSERT_EQ(f.steps[std::size_t(k)].num_commands, 1);
  EXPECT_EQ(f.steps[std::size_t(k)].commands[0], ceiling(0.3));
  EXPECT_EQ(f.steps[std::size_t(k - 1)].num_commands, 0);
  EXPECT_EQ(f.steps[std::size_t(k)].instructor.bounds, (AuthorityBounds{0.0, 0.3}));

  std::string error;
  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  double before = 0.0;
  for (const LambdaSample& l : rec->lambda) {
    if (std::int64_t(l.step) < k) before = std::max(before, l.lambda);
    else ASSERT_LE(l.lambda, 0.3) << "step " << l.step;
  }
  EXPECT_GT(before, 0.9);  // the ceiling changed something
  ASSERT_EQ(rec->commands.size(), 1u);
  EXPECT_EQ(rec->commands[0].step, std::uint64_t(k));
  EXPECT_EQ(rec->commands[0].ceiling, 0.3);
  bool said = false;
  for (const LogMsg& m : rec->log)
    said |= m.msg == "instructor: ceiling 0.30" && m.function == "instructor" && m.level == 20;
  EXPECT_TRUE(said);
}

// (2) A 2 N gust for 0.5 s, against the identical flight without it: the vehicle is pushed off
// (the NMPC's model does not know the gust) and the planner brings it back. Bounds: the push,
// measured against the calm flight, is more than the ball's radius r = 0.175 m (a free 1.04 kg
// body would move ½·(2/1.04)·0.5² = 0.24 m in the half second; the loop's rotors lag the
// unknown force), so the vehicle leaves the working condition of SPEC §5.4; the PH index sees
// it coming and hands the planner the vehicle (λ below 0.5 where the calm flight's is above
// 0.9); recovered means back in the ball B within 1 s after the gust ends and in it until the
// end. The distance between the two flights is no measure of recovery here: the emulated
// pilot's own lightly damped oscillation (the calm flight's deviation swings between 1 and 9
// cm) goes on with another phase. The replay of the recording repeats the flight, the gust
// included, bit for bit.
TEST(Instructor, GustDeviatesThePlannerRecoversAndTheReplayRepeatsIt) {
  const std::int64_t k = 100;  // 1.5 s
  auto calm = load(kHelix, 6.0, "experienced");
  auto gusty = load(kHelix, 6.0, "experienced");
  ASSERT_TRUE(calm && gusty);
  const Flown a = fly(*calm, {});
  const std::string path = test::fresh_path("instructor", "gust.mcap").string();
  const Flown b = fly(*gusty, {{k, gust({2.0, 0.0, 0.0}, 0.5)}}, path);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  const double dt = calm->dt(), r = calm->view().ball_radius;
  const auto gust_steps = std::int64_t(std::lround(0.5 / dt));
  const auto deviation = [](const Telemetry& s) {
    return (s.x.head<3>() - s.reference.head<3>()).norm();
  };
  double pushed = 0.0, lowest = 1.0, calm_lambda = 1.0, back_in = -1.0;
  for (std::int64_t j = 0; j < std::int64_t(a.steps.size()); ++j) {
    const Telemetry &sa = a.steps[std::size_t(j)], &sb = b.steps[std::size_t(j)];
    const double d = distance(sa, sb);
    if (j <= k) {
      ASSERT_EQ(d, 0.0) << "step " << j;  // identical until the gust acts
    }
    pushed = std::max(pushed, d);
    if (j > k && j <= k + gust_steps) {
      lowest = std::min(lowest, sb.lambda);
      calm_lambda = std::min(calm_lambda, sa.lambda);
    }
    const double after = double(j - k - gust_steps) * dt;
    if (after >= 0.0 && back_in < 0.0 && deviation(sb) <= r) back_in = after;
    if (after >= 1.0) {
      ASSERT_LE(deviation(sb), r) << "step " << j;
    }
  }
  EXPECT_GT(pushed, r);
  EXPECT_LT(lowest, 0.5);
  EXPECT_GT(calm_lambda, 0.9);
  // The HUD's persistent line: the gust in force for its half second, then gone.
  EXPECT_GT(b.steps[std::size_t(k)].instructor.gust_left, 0.49);
  EXPECT_EQ(b.steps[std::size_t(k + gust_steps + 1)].instructor.gust_left, 0.0);
  std::printf("gust 2 N x 0.5 s: pushed %.3f m off the calm flight (r %.3f m), lowest λ %.2f; "
              "back in the ball %.2f s after the gust\n",
              pushed, r, lowest, back_in);

  std::string error, text;
  ASSERT_TRUE(read_text_file(kHelix, text, error)) << error;
  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  ASSERT_EQ(rec->commands.size(), 1u);
  auto replayed = replay_mode(*rec, path, text, kHelix, {}, error);
  ASSERT_TRUE(replayed) << error;
  ReplayCheck check(*rec);
  Session again(*replayed);
  again.add_sink(&check);
  again.run();
  EXPECT_EQ(check.first_difference(replayed->steps_done()), "");
  EXPECT_EQ(replayed->telemetry().x, b.steps.back().x);

  // A replay without the command is no longer the recorded flight: the check sees it.
  RecordingContents without = *rec;
  without.commands.clear();
  auto plain = replay_mode(without, path, text, kHelix, {}, error);
  ASSERT_TRUE(plain) << error;
  ReplayCheck check2(without);
  Session again2(*plain);
  again2.add_sink(&check2);
  again2.run();
  EXPECT_NE(check2.first_difference(plain->steps_done()), "");
}

// (3) A marker is a debrief event with its text: in the recording's /rosout (as an INFO
// rcl_interfaces/msg/Log, kind "marker") and rebuilt by the replay's debrief.
TEST(Instructor, MarkerIsInTheRecordingsDebriefList) {
  auto mode = load(kHelix, 2.0, "novice");
  ASSERT_TRUE(mode);
  const std::string path = test::fresh_path("instructor", "marker.mcap").string();
  const Flown f = fly(*mode, {{60, marker("watch the column")}}, path);
  std::string error;
  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  int found = 0;
  for (const LogMsg& m : rec->log) {
    if (m.function != "marker") continue;
    ++found;
    EXPECT_EQ(m.msg, "marker: watch the column");
    EXPECT_EQ(m.level, 20);
    EXPECT_EQ(m.name, kDebriefLogger);
    EXPECT_EQ(ros_time_to_ns(m.stamp), 60u * rec->control_period_ns);
  }
  EXPECT_EQ(found, 1);
  ASSERT_EQ(rec->commands.size(), 1u);
  EXPECT_EQ(rec->commands[0].text, "watch the column");
  // The replay's own debrief (the window's Debrief panel) has it too.
  std::string text;
  ASSERT_TRUE(read_text_file(kHelix, text, error)) << error;
  auto replayed = replay_mode(*rec, path, text, kHelix, {}, error);
  ASSERT_TRUE(replayed) << error;
  DebriefBuilder debrief(debrief_settings(*replayed));
  while (replayed->step()) debrief.add(replayed->telemetry());
  debrief.finish();
  found = 0;
  for (const DebriefEvent& e : debrief.events())
    found += e.kind == DebriefKind::marker && e.note.view() == "watch the column" &&
             e.start_step == 60;
  EXPECT_EQ(found, 1);
}

// (4) Extra delay: the controller starts from the state `delay` old. With 45 ms = 3 control
// steps on the mixed-initiative mode (no position noise), the measured state of step k is the
// true state of step k − 3 exactly, from the step it took effect at; 0 removes it.
TEST(Instructor, ExtraDelayDelaysTheMeasurement) {
  auto mode = load(kHelix, 3.0, "experienced");
  ASSERT_TRUE(mode);
  const std::int64_t k = 60, off = 120;
  const Flown f = fly(*mode, {{k, simple(InstructorCommandKind::extra_delay, 0.045)},
                              {off, simple(InstructorCommandKind::extra_delay, 0.0)}});
  for (std::int64_t j = 1; j < std::int64_t(f.steps.size()); ++j) {
    const Telemetry& s = f.steps[std::size_t(j)];
    if (j >= k && j < off) {
      ASSERT_EQ(s.x_measured, f.steps[std::size_t(j - 3)].x) << "step " << j;
      ASSERT_NEAR(s.instructor.extra_delay, 0.045, 1e-12);
    } else {
      ASSERT_EQ(s.x_measured, s.x) << "step " << j;
      ASSERT_EQ(s.instructor.extra_delay, 0.0);
    }
  }
  // Tracking under delay: the compensation predicts over the scenario's rtt only, so an
  // unknown extra 5 ms costs tracking accuracy (SPEC §5.2's degradation; 15 ms more loses the
  // vehicle).
  auto calm = load(kTracking, 3.0);
  auto late = load(kTracking, 3.0);
  ASSERT_TRUE(calm && late);
  const Flown a = fly(*calm, {});
  const Flown b = fly(*late, {{0, simple(InstructorCommandKind::extra_delay, 0.005)}});
  ASSERT_EQ(a.steps.size(), b.steps.size());
  double ea = 0.0, eb = 0.0;
  for (std::size_t j = 0; j < a.steps.size(); ++j) {
    ea += (a.steps[j].x.head<3>() - a.steps[j].reference.head<3>()).squaredNorm();
    eb += (b.steps[j].x.head<3>() - b.steps[j].reference.head<3>()).squaredNorm();
  }
  std::printf("tracking error sum of squares: %.4g m^2 as flown, %.4g m^2 with 5 ms more\n", ea, eb);
  EXPECT_GT(eb, ea);
  // Beyond the delay lines' size it is refused, changing nothing.
  auto m = load(kHelix, 1.0, "novice");
  ASSERT_TRUE(m);
  EXPECT_EQ(m->instruct(simple(InstructorCommandKind::extra_delay, 0.6)),
            InstructorStatus::bad_value);
  EXPECT_EQ(m->commands_pending(), 0);
}

// (5) Input loss: the emulated pilot's input is lost for 1 s from the step it took effect at
// (authority 0, λ = 0, "input lost"), then the authority ramps back over kInputReturnS as a
// device's does after re-centring, never jumping; the debrief has one input-lost event of 1 s.
TEST(Instructor, InputLossHandsThePlannerTheVehicleThenRampsBack) {
  auto mode = load(kHelix, 4.0, "experienced");
  ASSERT_TRUE(mode);
  const std::string path = test::fresh_path("instructor", "loss.mcap").string();
  const std::int64_t k = 80;
  const Flown f = fly(*mode, {{k, simple(InstructorCommandKind::input_loss, 1.0)}}, path);
  const double dt = mode->dt();
  const auto lost = std::int64_t(std::lround(1.0 / dt)), ramp = std::int64_t(std::lround(kInputReturnS / dt));
  double previous = 0.0;
  for (std::int64_t j = 0; j < std::int64_t(f.steps.size()); ++j) {
    const Telemetry& s = f.steps[std::size_t(j)];
    if (j < k) {
      ASSERT_EQ(s.pilot.input, InputState::ok) << j;
    } else if (j < k + lost) {
      ASSERT_EQ(s.pilot.input, InputState::lost) << j;
      ASSERT_EQ(s.pilot.authority, 0.0) << j;
      ASSERT_EQ(s.lambda, 0.0) << j;
      ASSERT_EQ(s.reason.cap, LambdaCap::input_lost) << j;
      ASSERT_NEAR(s.instructor.input_loss_left, double(k + lost - j) * dt, 1e-9);
    } else if (j < k + lost + ramp - 1) {
      ASSERT_EQ(s.pilot.input, InputState::returning) << j;
      ASSERT_GT(s.pilot.authority, previous) << j;  // rising, by one step's share
      ASSERT_NEAR(s.pilot.authority - previous, dt / kInputReturnS, 1e-9) << j;
    } else {
      ASSERT_EQ(s.pilot.input, InputState::ok) << j;
      ASSERT_EQ(s.pilot.authority, 1.0) << j;
    }
    previous = s.pilot.authority;
  }
  int events = 0;
  for (const DebriefEvent& e : f.events) {
    if (e.kind != DebriefKind::input_lost) continue;
    ++events;
    EXPECT_EQ(e.start_step, k);
    EXPECT_EQ(e.end_step, k + lost);
  }
  EXPECT_EQ(events, 1);
  // The mode without a pilot refuses it and says why.
  auto t = load(kTracking, 1.0);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->instruct(simple(InstructorCommandKind::input_loss, 1.0)),
            InstructorStatus::no_pilot);
}

// (6) Pause, resume and end through the inbox: no step flies while paused; the pause and the
// resume are recorded with the step after them; the step that carries the end is the last, and
// the session says the instructor ended it.
TEST(Instructor, PauseResumeAndEnd) {
  auto mode = load(kHelix, 3.0, "novice");
  ASSERT_TRUE(mode);
  CommandInbox inbox;
  Session session(*mode);
  session.set_inbox(&inbox);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(session.step());
  inbox.push(simple(InstructorCommandKind::pause));
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(session.step());
    ASSERT_FALSE(session.stepped());
  }
  EXPECT_TRUE(session.paused());
  EXPECT_EQ(mode->steps_done(), 10);
  inbox.push(marker("while paused"));
  inbox.push(simple(InstructorCommandKind::resume));
  ASSERT_TRUE(session.step());
  ASSERT_TRUE(session.stepped());
  EXPECT_FALSE(session.paused());
  const Telemetry& s = mode->telemetry();
  ASSERT_EQ(s.num_commands, 3);
  EXPECT_EQ(s.step, 10);
  EXPECT_EQ(s.commands[0].kind, InstructorCommandKind::pause);
  EXPECT_EQ(s.commands[1].kind, InstructorCommandKind::marker);
  EXPECT_EQ(s.commands[2].kind, InstructorCommandKind::resume);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(session.step());
  inbox.push(simple(InstructorCommandKind::end));
  ASSERT_TRUE(session.step());
  EXPECT_EQ(mode->telemetry().commands[0].kind, InstructorCommandKind::end);
  EXPECT_EQ(mode->steps_done(), 17);
  EXPECT_FALSE(session.step());
  EXPECT_TRUE(session.ended_by_instructor());
  EXPECT_FALSE(mode->finished());
  EXPECT_EQ(mode->steps_done(), 17);
  inbox.push(marker("too late"));
  EXPECT_FALSE(session.step());
  EXPECT_EQ(inbox.applied(), 4);
}

// More commands than a step takes wait, in order, for the next steps; values out of range and
// kinds a mode does not have are refused, counted, with the reason.
TEST(Instructor, ABurstWaitsForTheNextStepsAndRefusalsSayWhy) {
  auto mode = load(kHelix, 1.0, "novice");
  ASSERT_TRUE(mode);
  CommandInbox inbox;
  Session session(*mode);
  session.set_inbox(&inbox);
  for (int i = 0; i < 6; ++i) inbox.push(marker(std::string("m") + char('0' + i)));
  InstructorCommand bad = gust({30.0, 0.0, 0.0}, 0.5);
  inbox.push(bad);
  ASSERT_TRUE(session.step());
  ASSERT_EQ(mode->telemetry().num_commands, kMaxCommandsPerStep);
  EXPECT_EQ(mode->telemetry().commands[0].text.view(), "m0");
  ASSERT_TRUE(session.step());
  ASSERT_EQ(mode->telemetry().num_commands, 2);
  EXPECT_EQ(mode->telemetry().commands[1].text.view(), "m5");
  EXPECT_EQ(inbox.refused(), 1);
  EXPECT_EQ(inbox.last_refusal(), InstructorStatus::bad_value);
  EXPECT_STREQ(invalid_reason(bad), "the gust's force is above 20 N");

  auto p = load(kPendubot, 1.0);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->instruct(gust({2.0, 0.0, 0.0}, 0.5)), InstructorStatus::fixed_base);
  EXPECT_NE(std::string(to_string(InstructorStatus::fixed_base)).find("Pendubot"),
            std::string::npos);
  EXPECT_EQ(p->instruct(simple(InstructorCommandKind::extra_delay, 0.1)), InstructorStatus::no_link);
  EXPECT_EQ(p->instruct(ceiling(0.3)), InstructorStatus::no_authority);
  EXPECT_EQ(p->instruct(marker("fine")), InstructorStatus::applied);
  EXPECT_EQ(p->commands_pending(), 1);
}

// (7) A snapshot taken in the middle of a gust, with an extra delay and an input loss in force,
// carries them: restored into a fresh flight, the rest is flown bit for bit.
TEST(Instructor, SnapshotMidGustRestoresBitForBit) {
  auto first = load(kHelix, 3.0, "experienced");
  ASSERT_TRUE(first);
  CommandInbox inbox;
  Session session(*first);
  session.set_inbox(&inbox);
  ModeSnapshot snap;
  std::vector<Telemetry> after;
  const std::int64_t k = 50, at = 60;
  while (true) {
    if (first->steps_done() == k) {
      inbox.push(gust({0.0, -2.0, 1.0}, 0.5));
      inbox.push(simple(InstructorCommandKind::extra_delay, 0.03));
      inbox.push(simple(InstructorCommandKind::input_loss, 0.5));
    }
    if (first->steps_done() == at) first->save(snap);
    if (!session.step()) break;
    if (first->steps_done() > at) after.push_back(first->telemetry());
  }
  ASSERT_EQ(snap.step(), at);
  auto second = load(kHelix, 3.0, "experienced");
  ASSERT_TRUE(second);
  ASSERT_EQ(second->restore(snap), RestoreStatus::ok);
  // In force at the snapshot: the gust's time left, the delay, the loss left.
  std::size_t i = 0;
  while (second->step()) {
    const Telemetry& s = second->telemetry();
    ASSERT_LT(i, after.size());
    if (i == 0) {
      EXPECT_NEAR(s.instructor.gust_left, 0.5 - double(at - k) * second->dt(), 1e-9);
      EXPECT_NEAR(s.instructor.extra_delay, 0.03, 1e-12);
      EXPECT_NEAR(s.instructor.input_loss_left, 0.5 - double(at - k) * second->dt(), second->dt());
    }
    ASSERT_EQ(s.x, after[i].x) << "step " << s.step;
    ASSERT_EQ(s.u, after[i].u) << "step " << s.step;
    ASSERT_EQ(s.lambda, after[i].lambda) << "step " << s.step;
    ASSERT_EQ(s.pilot.authority, after[i].pilot.authority) << "step " << s.step;
    ++i;
  }
  EXPECT_EQ(i, after.size());
}

// The thesis's quadrotor modes take a gust too: the obstacle mode's Crazyflie is pushed off the
// path a calm flight keeps (an 0.05 N push on a 33 g vehicle).
TEST(Instructor, ObstacleModeTakesAGust) {
  auto calm = load(kObstacles, 1.5);
  auto gusty = load(kObstacles, 1.5);
  ASSERT_TRUE(calm && gusty);
  const Flown a = fly(*calm, {});
  const Flown b = fly(*gusty, {{20, gust({0.0, 0.05, 0.0}, 0.3)}});
  ASSERT_EQ(a.steps.size(), b.steps.size());
  double pushed = 0.0;
  for (std::size_t j = 0; j < a.steps.size(); ++j) pushed = std::max(pushed, distance(a.steps[j], b.steps[j]));
  EXPECT_EQ(distance(a.steps[20], b.steps[20]), 0.0);
  EXPECT_GT(pushed, 0.01);
}

// (8) Recordings: one older than the topic replays as before; bad command data is refused with
// the path and the reason.
TEST(Instructor, RecordedCommandsAreCheckedOnTheWayIn) {
  auto mode = load(kHelix, 1.0, "novice");
  ASSERT_TRUE(mode);
  const std::string path = test::fresh_path("instructor", "checked.mcap").string();
  fly(*mode, {{10, gust({1.0, 0.0, 0.0}, 0.2)}, {20, marker("ok")}}, path);
  std::string error, text;
  ASSERT_TRUE(read_text_file(kHelix, text, error)) << error;
  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  ASSERT_EQ(rec->commands.size(), 2u);
  const auto refused = [&](auto&& change, const std::string& expected) {
    RecordingContents bad = *rec;
    change(bad.commands);
    error.clear();
    EXPECT_FALSE(replay_mode(bad, path, text, kHelix, {}, error)) << expected;
    EXPECT_NE(error.find(path + ": its /instructor/command message "), std::string::npos) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  };
  using Msgs = std::vector<InstructorCommandMsg>;
  refused([](Msgs& c) { c[0].kind = 8; }, "its kind is 8, expected 0 to 7");
  refused([](Msgs& c) { c[0].duration = std::nan(""); }, "not finite");
  refused([](Msgs& c) { c[0].force[1] = 25.0; }, "the gust's force is above 20 N");
  refused([](Msgs& c) { c[0].duration = 11.0; }, "not in (0, 10] s");
  refused([](Msgs& c) { c[1].text = std::string(200, 'x'); }, "200 bytes long");
  refused([](Msgs& c) { c[1].text = "bell\a"; }, "control characters");
  refused([](Msgs& c) { c[1].step = 5; }, "out of order");
  refused(
      [](Msgs& c) {
        c[1].kind = 0;
        c[1].floor = 0.8;
        c[1].ceiling = 0.2;
      },
      "0 <= floor <= ceiling <= 1");

  // Without the topic (a recording made before it): no commands, replayed as ever.
  RecordingContents old = *rec;
  old.commands.clear();
  auto plain = load(kHelix, 1.0, "novice");
  const std::string old_path = test::fresh_path("instructor", "old.mcap").string();
  fly(*plain, {}, old_path);
  const auto old_rec = read_recording(old_path, error);
  ASSERT_TRUE(old_rec) << error;
  RecordingContents stripped = *old_rec;
  stripped.message_counts.erase("/instructor/command");
  auto replayed = replay_mode(stripped, old_path, text, kHelix, {}, error);
  ASSERT_TRUE(replayed) << error;
  ReplayCheck check(stripped);
  Session again(*replayed);
  again.add_sink(&check);
  again.run();
  EXPECT_EQ(check.first_difference(replayed->steps_done()), "");
}

// (9) The command script: commands at flight times, taken at the first step at or after them;
// errors name file:line:col, the key and what was expected.
TEST(Instructor, CommandScriptsAreReadAndCheckedWithFileAndLine) {
  std::string error;
  const auto ok = parse_command_script(R"([[command]]
at = 2.0
kind = "gust"
force = [2.0, 0.0, 0.0]
duration = 0.5

[[command]]
at = 0.3
kind = "bounds"
floor = 0.0
ceiling = 0.3

[[command]]
at = 1.0
kind = "marker"
text = "watch the column"

[[command]]
at = 1.5
kind = "extra_delay"
delay = 0.1

[[command]]
at = 1.5
kind = "input_loss"
duration = 2.0

[[command]]
at = 3.0
kind = "end"
)",
                                       "script.toml", error);
  ASSERT_TRUE(ok) << error;
  ASSERT_EQ(ok->size(), 6u);
  EXPECT_EQ((*ok)[0].command.kind, InstructorCommandKind::gust);
  EXPECT_EQ((*ok)[0].line, 1);
  EXPECT_EQ((*ok)[1].command.bounds, (AuthorityBounds{0.0, 0.3}));
  EXPECT_EQ(CommandInbox::step_of(2.0, 0.015), 134);
  EXPECT_EQ(CommandInbox::step_of(0.3, 0.015), 20);

  // Scheduled into an inbox, each comes out at its step, in time order.
  CommandInbox inbox;
  inbox.schedule(*ok);
  InstructorCommand c;
  EXPECT_FALSE(inbox.pop(19, 0.015, c));
  ASSERT_TRUE(inbox.pop(20, 0.015, c));
  EXPECT_EQ(c.kind, InstructorCommandKind::bounds);
  EXPECT_FALSE(inbox.pop(20, 0.015, c));
  ASSERT_TRUE(inbox.pop(100, 0.015, c));
  EXPECT_EQ(c.kind, InstructorCommandKind::marker);
  ASSERT_TRUE(inbox.pop(100, 0.015, c));
  EXPECT_EQ(c.kind, InstructorCommandKind::extra_delay);  // at 1.5 s, in the file's order
  ASSERT_TRUE(inbox.pop(100, 0.015, c));
  EXPECT_EQ(c.kind, InstructorCommandKind::input_loss);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"[[command]]\nat = 1.0\nkind = \"gust\"\nforce = [30.0, 0.0, 0.0]\nduration = 0.5\n",
       "script.toml:4:10: command[0].force[0]: value outside [-20, 20], got 30.0"},
      {"[[command]]\nat = 1.0\nkind = \"gust\"\nforce = [15.0, 15.0, 0.0]\nduration = 0.5\n",
       "script.toml:4:9: command[0].force: the force's magnitude [N]"},
      {"[[command]]\nat = 1.0\nkind = \"gust\"\nforce = [1.0, 0.0, 0.0]\n",
       "script.toml:1:1: command[0].duration: missing required key (expected a number)"},
      {"[[command]]\nat = 1.0\nkind = \"wind\"\n", "script.toml:3:8: command[0].kind: expected one of"},
      {"[[command]]\nat = 1.0\nkind = \"pause\"\n", "is a live command only"},
      {"[[command]]\nat = 1.0\nkind = \"bounds\"\nfloor = 0.5\nceiling = 0.2\n",
       "script.toml:4:9: command[0].floor: expected floor <= ceiling"},
      {"[[command]]\nat = 1.0\nkind = \"bounds\"\n", "needs floor, ceiling or both"},
      {"[[command]]\nat = 1.0\nkind = \"marker\"\ntext = \"a\"\nforce = [1.0, 0.0, 0.0]\n",
       "script.toml:5:1: command[0].force: unknown key"},
      {"[[command]]\nat = -1.0\nkind = \"end\"\n", "script.toml:2:6: command[0].at: value outside"},
      {"[[command]]\nat = 1.0\nkind = \"extra_delay\"\ndelay = 0.7\n",
       "command[0].delay: value outside [0, 0.5]"},
      {"at = 1.0\n", "script.toml:1:1: at: unknown key"},
      {"", "command: missing required key"},
      {"command = 3\n", "expected an array of tables ([[command]])"},
  };
  for (const auto& [text, expected] : bad) {
    error.clear();
    EXPECT_FALSE(parse_command_script(text, "script.toml", error)) << text;
    EXPECT_NE(error.find(expected), std::string::npos) << "got: " << error << "\nfor:\n" << text;
  }
}

// `mixpilot fly --commands FILE.toml` as a user runs it: the commands applied and said in the
// summary, recorded, and the recording scored bit for bit; `--ceiling` bounds the whole flight;
// a bad script and one the flight would refuse are errors naming file:line; a script goes with
// a new flight, not a replay. Then the history: the instructor's end is remembered as such.
TEST(Instructor, CommandScriptFromTheCommandLine) {
  const test::fs::path home = test::fresh_path("instructor", "cli");
  test::fs::create_directories(home);
  const std::string script = (home / "commands.toml").string();
  std::ofstream(script) << "[[command]]\nat = 0.5\nkind = \"gust\"\nforce = [2.0, 0.0, 0.0]\n"
                           "duration = 0.5\n\n[[command]]\nat = 1.0\nkind = \"marker\"\n"
                           "text = \"look\"\n\n[[command]]\nat = 1.5\nkind = \"end\"\n";
  const std::string rec = (home / "flight.mcap").string();
  const std::string bin = MIXPILOT_BINARY;
  ASSERT_EQ(test::run_mixpilot(bin,
                               "fly --scenario '" + kHelix + "' --pilot novice --headless "
                               "--duration 3 --ceiling 0.8 --commands '" + script +
                                   "' --record '" + rec + "' --trainee ann",
                               home),
            0)
      << test::read_file(home / "out.txt");
  const std::string out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("instructor: 3 commands applied, 0 refused"), std::string::npos) << out;
  EXPECT_NE(out.find("ended by the instructor at t = 1.515 s"), std::string::npos) << out;
  std::string error;
  const auto contents = read_recording(rec, error);
  ASSERT_TRUE(contents) << error;
  ASSERT_EQ(contents->commands.size(), 3u);
  EXPECT_EQ(contents->commands[0].step, 34u);  // 0.5 s / 15 ms → the step at 0.51 s
  EXPECT_EQ(contents->metadata.at("authority_ceiling"), "0.8");
  EXPECT_EQ(contents->states.size(), 101u);  // steps 0 … 100: the end (at 1.5 s) is in the last
  ASSERT_TRUE(contents->end);
  EXPECT_TRUE(contents->end->interrupted);
  EXPECT_EQ(test::run_mixpilot(bin, "score '" + rec + "'", home, "score.txt"), 0)
      << test::read_file(home / "score.txt");
  EXPECT_EQ(test::run_mixpilot(bin, "history --trainee ann", home, "history.txt"), 0);
  EXPECT_NE(test::read_file(home / "history.txt").find("instructor"), std::string::npos)
      << test::read_file(home / "history.txt");

  std::ofstream(script) << "[[command]]\nat = 0.5\nkind = \"gust\"\nforce = [2.0, 0.0]\n";
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario '" + kHelix + "' --headless --commands '" +
                                        script + "' --history off",
                               home),
            1);
  EXPECT_NE(test::read_file(home / "out.txt").find(script + ":4:9: command[0].force: expected an array of 3 numbers"),
            std::string::npos)
      << test::read_file(home / "out.txt");
  std::ofstream(script) << "[[command]]\nat = 0.5\nkind = \"gust\"\nforce = [0.0, 0.0, 1.0]\n"
                           "duration = 0.5\n";
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario '" + kPendubot + "' --headless --commands '" +
                                        script + "' --history off",
                               home),
            1);
  EXPECT_NE(test::read_file(home / "out.txt").find(script + ":1: a gust command, which this flight (pendubot_swingup) refuses: the Pendubot is an arm"),
            std::string::npos)
      << test::read_file(home / "out.txt");
  EXPECT_EQ(test::run_mixpilot(bin, "fly --pilot '" + rec + "' --headless --commands '" + script + "'", home), 2);
  EXPECT_NE(test::read_file(home / "out.txt").find("--commands is for a new flight"), std::string::npos);
  EXPECT_EQ(test::run_mixpilot(bin, "fly --scenario '" + kHelix + "' --headless --floor 0.5 --ceiling 0.4", home), 2);
  EXPECT_NE(test::read_file(home / "out.txt").find("expected floor <= ceiling"), std::string::npos);
}

// The words of each kind, as the HUD and the debrief say them.
TEST(Instructor, CommandsInWords) {
  EXPECT_EQ(describe(ceiling(0.3)), "ceiling 0.30");
  InstructorCommand both;
  both.kind = InstructorCommandKind::bounds;
  both.bounds = {0.2, 0.8};
  EXPECT_EQ(describe(both), "floor 0.20, ceiling 0.80");
  both.bounds = {};
  EXPECT_EQ(describe(both), "bounds lifted");
  EXPECT_EQ(describe(gust({2.0, 0.0, 0.0}, 0.5)), "gust 2.0 N for 0.50 s");
  EXPECT_EQ(describe(simple(InstructorCommandKind::extra_delay, 0.1)), "extra delay 0.100 s");
  EXPECT_EQ(describe(simple(InstructorCommandKind::extra_delay, 0.0)), "extra delay removed");
  EXPECT_EQ(describe(simple(InstructorCommandKind::input_loss, 2.0)), "input loss for 2.0 s");
  EXPECT_EQ(describe(marker("look")), "marker: look");
  EXPECT_EQ(describe(simple(InstructorCommandKind::end)), "end");
}

}  // namespace
}  // namespace mixpilot
