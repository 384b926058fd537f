// Snapshots of every mode (core/modes/mode.hpp: Mode::save, Mode::restore). A flight of each
// shipped scenario is recorded with the recorder of core/recording (RecordingSink), snapshots
// being saved while it flies: at an early step, a middle one and the step just before an event
// (a recorded overrun, the safe controller taking over, an input loss, the Pendubot's switch to
// its LQR, a ball thrown). Restored into a fresh mode of the same scenario, into one that flies
// the recording's pilot commands (ReplayPilot) and into the mode that flew on to its end, the
// flight then goes on exactly as recorded: state, input, λ, pilot command, prediction, solver
// status, channels and events of every remaining step, bit for bit, and the same metrics at the
// end. Saving into a sized snapshot, restoring and stepping allocate nothing (every malloc is
// counted, no_malloc.hpp); a snapshot of another kind of mode, scenario or pilot is refused and
// changes nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "core/control/pilot_emulated.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "delayed_plant_link.hpp"
#include "models/crazyflie.hpp"
#include "no_malloc.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

// One recorded flight and where to restore it.
struct Case {
  const char* name;      // test name
  const char* scenario;  // under scenarios/
  const char* pilot;     // mixed initiative only: an emulated pilot of the scenario
  double duration;       // [s]: shorter than the file's, for test time, with the event inside
  // Steps whose solve overran in the recorded (real-time) flight: replayed as such
  // (Mode::replay_timing), they fall back, and five in a row engage the safe controller.
  std::vector<std::int64_t> overruns;
  // The event to restore just before: the first step that raises it, or else the step
  // `event_step` (a ball's throw has no event of its own).
  std::uint32_t event = 0;
  std::int64_t event_step = -1;
  // Keys of the scenario file set to other values ("position_noise", "0.01").
  std::vector<std::pair<std::string, std::string>> set = {};
  // Mixed initiative: the pilot's device is lost over these steps [first, second).
  std::pair<std::int64_t, std::int64_t> input_lost = {-1, -1};
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.scenario << (c.pilot ? std::string(" pilot=") + c.pilot : std::string());
}

std::string scenario_path(const Case& c) {
  return std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + c.scenario;
}

// The case's scenario text: the shipped file with its `set` keys changed.
std::string scenario_text(const Case& c) {
  std::string text, error;
  EXPECT_TRUE(read_text_file(scenario_path(c), text, error)) << error;
  for (const auto& [key, value] : c.set) {
    const auto at = text.find("\n" + key + " = ");
    EXPECT_NE(at, std::string::npos) << key;
    if (at == std::string::npos) continue;
    text.replace(at + 1, text.find('\n', at + 1) - at - 1, key + " = " + value);
  }
  return text;
}

// A pilot whose device is lost over steps [from, to): its command grants no authority and says
// so (SPEC §6), as a device pilot's does. It keeps nothing of its own: it saves and restores
// the pilot it wraps.
class LosesInput final : public PilotSource {
 public:
  LosesInput(std::unique_ptr<PilotSource> pilot, std::int64_t from, std::int64_t to)
      : pilot_(std::move(pilot)), from_(from), to_(to) {}
  std::string name() const override { return pilot_->name(); }
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override {
    if (!pilot_->command(step, t, x, out)) return false;
    if (step >= from_ && step < to_) {
      out.input = InputState::lost;
      out.authority = 0.0;
    }
    return true;
  }
  void save(std::unique_ptr<PilotState>& state) const override { pilot_->save(state); }
  bool restore(const PilotState* state) override { return pilot_->restore(state); }

 private:
  std::unique_ptr<PilotSource> pilot_;
  std::int64_t from_, to_;
};

// The case's own pilot: its emulated pilot, with its input loss.
std::unique_ptr<PilotSource> emulated_pilot(const Case& c, const std::string& text) {
  std::string error;
  const std::optional<Scenario> scenario = parse_scenario(text, scenario_path(c), error);
  EXPECT_TRUE(scenario) << error;
  if (!scenario) return nullptr;
  std::unique_ptr<PilotSource> pilot = make_scenario_pilot(*scenario, c.pilot, error);
  EXPECT_TRUE(pilot) << error;
  if (c.input_lost.first >= 0)
    pilot = std::make_unique<LosesInput>(std::move(pilot), c.input_lost.first, c.input_lost.second);
  return pilot;
}

// A fresh mode of the case, with its recorded overruns; mixed initiative flies `pilot`, or the
// case's own.
std::unique_ptr<Mode> make(const Case& c, const std::string& text,
                           std::unique_ptr<PilotSource> pilot = nullptr) {
  ModeRequest request;
  request.duration = c.duration;
  if (c.pilot) request.pilot_source = pilot ? std::move(pilot) : emulated_pilot(c, text);
  std::string error;
  std::unique_ptr<Mode> mode = make_mode(text, scenario_path(c), std::move(request), error);
  EXPECT_TRUE(mode) << error;
  if (mode) mode->replay_timing(c.overruns);
  return mode;
}

// The recorded flight, the snapshots saved while it flew and its mode, flown to its end.
struct Recorded {
  RecordingContents rec;
  std::unique_ptr<Mode> mode;
  Metrics metrics;                     // at its end
  std::vector<ModeSnapshot> snapshots;  // early, middle, just before the event
  std::int64_t event_step = -1;        // the step of the event (its snapshot: before it)
};

Recorded record(const Case& c, const std::string& text) {
  Recorded r;
  r.mode = make(c, text);
  if (!r.mode) return r;
  Mode& mode = *r.mode;
  std::string error;
  const std::string path = test::fresh_path("snapshot", std::string(c.name) + ".mcap").string();
  RecordingSink sink;
  const SessionInfo info{to_string(mode.kind()), text, scenario_path(c), 1, c.pilot ? c.pilot : ""};
  EXPECT_TRUE(sink.open(path, mode, info, error)) << error;
  Session session(mode);
  session.add_sink(&sink);
  const std::int64_t early = 3, middle = mode.steps_total() / 2;
  ModeSnapshot at_early, at_middle, before_event, rolling;
  for (;;) {
    const std::int64_t k = mode.steps_done();
    if (k == early) mode.save(at_early);
    if (k == middle) mode.save(at_middle);
    // Before every step until the event: the snapshot just before it, whichever step it is.
    if (r.event_step < 0) mode.save(rolling);
    if (!session.step()) break;
    const Telemetry& t = mode.telemetry();
    const bool event = c.event != 0 ? (t.events & c.event) != 0 : t.step == c.event_step;
    if (r.event_step < 0 && event) {
      r.event_step = t.step;
      std::swap(before_event, rolling);
    }
  }
  EXPECT_TRUE(sink.close(error)) << error;
  std::optional<RecordingContents> rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  std::filesystem::remove(path);
  if (rec) r.rec = std::move(*rec);
  r.metrics = mode.metrics();
  r.snapshots.push_back(std::move(at_early));
  r.snapshots.push_back(std::move(at_middle));
  r.snapshots.push_back(std::move(before_event));
  return r;
}

// Every metric but the timings (which measure the machine, not the flight).
Metrics without_timing(Metrics metrics) {
  std::erase_if(metrics, [](const auto& m) {
    return m.first.ends_with("_us") || m.first == "deadline_misses";
  });
  return metrics;
}

bool same_bits(const double* a, const double* b, std::size_t n) {
  return std::memcmp(a, b, n * sizeof(double)) == 0;
}
bool same_bits(const std::vector<double>& recorded, const Eigen::Ref<const Eigen::VectorXd>& v) {
  return recorded.size() == std::size_t(v.size()) &&
         same_bits(recorded.data(), v.data(), recorded.size());
}
bool same_bits(double recorded, double v) { return same_bits(&recorded, &v, 1); }

// What of step `s` differs from the recorded step ("" when nothing does).
std::string difference(const Telemetry& s, const RecordingContents& rec) {
  const auto k = std::size_t(s.step);
  if (k >= rec.states.size()) return "no such step was recorded";
  if (!same_bits(rec.states[k].x, s.x)) return "the state";
  const AppliedCommandMsg& applied = rec.applied[k];
  if (!same_bits(applied.u, s.u)) return "the input";
  const SolverStatsMsg& solver = rec.solver[k];
  if (solver.status != std::uint8_t(s.stats.status) ||
      solver.qp_iterations != std::uint32_t(s.stats.qp_iterations))
    return "the solver's status or QP iterations";
  const ModeChannelsMsg& channels = rec.channels[k];
  if (channels.events != s.events) return "the events";
  if (channels.values.size() != std::size_t(s.num_channels)) return "the number of channels";
  for (std::size_t i = 0; i < channels.values.size(); ++i) {
    const Channel& c = s.channels[i];
    if (channels.names[i] != c.name || channels.units[i] != c.unit) return "a channel's name";
    // Times measure this machine now, not the flight.
    if (std::string(c.unit) != "us" && !same_bits(channels.values[i], c.value))
      return std::string("the channel ") + c.name;
  }
  if (s.predicted.cols() > 0) {
    const PredictionMsg* p = k < rec.predictions.size() ? &rec.predictions[k] : nullptr;
    if (!p || p->step != k || p->position.size() != std::size_t(s.predicted.size()) ||
        !same_bits(p->position.data(), s.predicted.data(), p->position.size()) ||
        !same_bits(p->reference.data(), s.predicted_reference.data(), p->reference.size()))
      return "the prediction";
  }
  if (s.mode == ModeKind::mixed_initiative) {
    if (!same_bits(rec.lambda[k].lambda, s.lambda)) return "lambda";
    if (k >= rec.reasons.size()) return "no reason of lambda was recorded";
    const LambdaReasonMsg& why = rec.reasons[k];
    if (!same_bits(why.d_res, s.reason.d_res) || why.node != s.reason.node ||
        !same_bits(why.ph_index, s.reason.ph_index) ||
        !same_bits(why.direction.data(), s.reason.direction.data(), 3) ||
        why.cap != std::uint8_t(s.reason.cap))
      return "the reason of lambda";
    const PilotCommandMsg& pilot = rec.pilot[k];
    if (!same_bits(pilot.roll, s.pilot.roll) || !same_bits(pilot.pitch, s.pilot.pitch) ||
        !same_bits(pilot.rotor_speed.data(), s.pilot.rotor_speed.data(), 4) ||
        !same_bits(pilot.authority, s.pilot.authority) ||
        pilot.input_state != std::uint8_t(s.pilot.input))
      return "the pilot's command";
    if (!same_bits(applied.roll, s.applied.roll) || !same_bits(applied.pitch, s.applied.pitch) ||
        !same_bits(applied.rotor_speed.data(), s.applied.rotor_speed.data(), 4))
      return "the MPC's stage-1 command";
  }
  return "";
}

// Flies `mode` on from `from` to its end: every step as recorded, and the flight as long as the
// recorded one.
void expect_flies_as_recorded(Mode& mode, const RecordingContents& rec, std::int64_t from,
                              const std::string& what) {
  ASSERT_EQ(mode.steps_done(), from) << what;
  std::int64_t k = from;
  while (mode.step()) {
    const Telemetry& s = mode.telemetry();
    ASSERT_EQ(s.step, k) << what;
    const std::string d = difference(s, rec);
    ASSERT_EQ(d, "") << what << ": step " << k << " differs from the recording: " << d;
    ++k;
  }
  EXPECT_EQ(std::size_t(k), rec.states.size()) << what << ": steps flown";
  EXPECT_TRUE(mode.finished()) << what;
}

class Restore : public testing::TestWithParam<Case> {};

std::string print_case(const testing::TestParamInfo<Case>& info) { return info.param.name; }

const char* kWhere[] = {"early", "middle", "before the event"};

std::string where_restored(std::size_t i, const ModeSnapshot& snapshot) {
  return std::string(kWhere[i]) + " (step " + std::to_string(snapshot.step()) + ")";
}

// Into a fresh mode of the same scenario: with the same pilot (its state restored), and in
// mixed initiative with the recording's pilot commands (ReplayPilot), which takes over from any.
TEST_P(Restore, IntoAFreshModeEveryRemainingStepIsAsRecorded) {
  const Case& c = GetParam();
  const std::string text = scenario_text(c);
  Recorded r = record(c, text);
  ASSERT_TRUE(r.mode);
  ASSERT_GT(r.event_step, 0) << "the event never happened: the test would not cover it";
  ASSERT_EQ(r.rec.states.size(), std::size_t(r.mode->steps_total()));
  std::printf("  %s: restored at steps %lld, %lld and %lld (before the event) of %lld\n", c.name,
              static_cast<long long>(r.snapshots[0].step()),
              static_cast<long long>(r.snapshots[1].step()),
              static_cast<long long>(r.snapshots[2].step()),
              static_cast<long long>(r.mode->steps_total()));
  for (std::size_t i = 0; i < r.snapshots.size(); ++i) {
    const ModeSnapshot& snapshot = r.snapshots[i];
    ASSERT_FALSE(snapshot.empty()) << kWhere[i];
    const std::string where = where_restored(i, snapshot);
    {
      std::unique_ptr<Mode> fresh = make(c, text);
      ASSERT_TRUE(fresh);
      ASSERT_EQ(fresh->restore(snapshot), RestoreStatus::ok) << where;
      // Its telemetry is the saved step's.
      EXPECT_EQ(fresh->telemetry().step, snapshot.step() - 1) << where;
      EXPECT_EQ(difference(fresh->telemetry(), r.rec), "") << where;
      expect_flies_as_recorded(*fresh, r.rec, snapshot.step(), "fresh mode, " + where);
      EXPECT_EQ(without_timing(fresh->metrics()), without_timing(r.metrics)) << where;
    }
    if (c.pilot) {
      auto replay = std::make_unique<ReplayPilot>(r.rec.pilot, "replay:test");
      std::unique_ptr<Mode> fresh = make(c, text, std::move(replay));
      ASSERT_TRUE(fresh);
      ASSERT_EQ(fresh->restore(snapshot), RestoreStatus::ok) << where;
      expect_flies_as_recorded(*fresh, r.rec, snapshot.step(), "recorded pilot, " + where);
      EXPECT_EQ(without_timing(fresh->metrics()), without_timing(r.metrics)) << where;
    }
  }
}

// Into the mode that was saved, after it flew on to its end, over and over: back to the middle,
// to the early step, to just before the event.
TEST_P(Restore, IntoTheModeThatFlewOnEveryRemainingStepIsAsRecorded) {
  const Case& c = GetParam();
  const std::string text = scenario_text(c);
  Recorded r = record(c, text);
  ASSERT_TRUE(r.mode);
  ASSERT_GT(r.event_step, 0) << "the event never happened: the test would not cover it";
  Mode& mode = *r.mode;
  ASSERT_TRUE(mode.finished());
  for (const std::size_t i : {1u, 0u, 2u}) {
    const ModeSnapshot& snapshot = r.snapshots[i];
    const std::string where = where_restored(i, snapshot);
    ASSERT_EQ(mode.restore(snapshot), RestoreStatus::ok) << where;
    EXPECT_FALSE(mode.finished()) << where;
    expect_flies_as_recorded(mode, r.rec, snapshot.step(), "same mode, " + where);
    EXPECT_EQ(without_timing(mode.metrics()), without_timing(r.metrics)) << where;
  }
}

// Most with overruns in a row, so the safe controller takes over (after 5) and hands back (after
// 5 good steps): the safety net's counters, the QP's cold restart after a fallback.
const Case kCases[] = {
    // The novice's device is lost for a while: the restore just before it.
    {"mi_helix_novice", "mi_helix.toml", "novice", 1.5, {30, 31, 32, 33, 34, 35}, kEventInputLost,
     -1, {}, {60, 75}},
    // The restore just before the safe controller takes over.
    {"mi_helix_experienced", "mi_helix.toml", "experienced", 1.5, {40, 41, 42, 43, 44, 45, 46},
     kEventSafeHold},
    // Position noise (the plant's random generator) and an input delay line; just before the
    // first fallback.
    {"mi_helix_noise_and_delay", "mi_helix.toml", "novice", 1.5, {50}, kEventFallback, -1,
     {{"input_delay", "0.03"}, {"position_noise", "0.01"}, {"seed", "7"}}},
    // Just before the NMPC hands over to the LQR near the top (four overruns in a row: the safe
    // controller, whose switch is an event too, stays out).
    {"pendubot_swingup", "pendubot_swingup.toml", nullptr, 1.5, {500, 501, 502, 503},
     kEventSwitch},
    // Encoders and the α-β observer; just before the first overrun.
    {"pendubot_swingup_encoders", "pendubot_swingup_encoders.toml", nullptr, 0.6,
     {100, 101, 102, 103, 104, 105}, kEventOverrun},
    // Just before the first overrun; the round-trip delay's rings and the predictor.
    {"tracking_helix", "tracking_helix.toml", nullptr, 1.5, {60, 61, 62, 63, 64, 65},
     kEventOverrun},
    // Just before the second ball is thrown (t = 1.4 s: during step 93 of 15 ms).
    {"obstacles_thrown_balls", "obstacles_thrown_balls.toml", nullptr, 2.0,
     {20, 21, 22, 23, 24, 25}, 0, 93},
};

INSTANTIATE_TEST_SUITE_P(Shipped, Restore, testing::ValuesIn(kCases), print_case);

const Case& find_case(const std::string& name) {
  for (const Case& c : kCases)
    if (name == c.name) return c;
  return kCases[0];
}

// Saving into a sized snapshot, restoring it and stepping on allocate nothing, in every mode.
// The first save sizes the snapshot: its bytes are what a snapshot of the mode weighs.
TEST(Snapshot, SavingIntoASizedSnapshotRestoringAndSteppingAllocateNothing) {
  for (const Case& c : kCases) {
    const std::string text = scenario_text(c);
    std::unique_ptr<Mode> mode = make(c, text);
    ASSERT_TRUE(mode);
    const std::int64_t half = mode->steps_total() / 2;
    while (mode->steps_done() < half) ASSERT_TRUE(mode->step());
    ModeSnapshot snapshot;
    long first_allocations = 0, first_bytes = 0;
    {
      AllocationCount count;
      mode->save(snapshot);
      count.stop();
      first_allocations = AllocationCount::count();
      first_bytes = AllocationCount::bytes();
    }
    // The first save sizes the snapshot (under AddressSanitizer nothing is counted).
    if (kAllocationsCounted) {
      EXPECT_GT(first_allocations, 0) << c.name;
    }
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(mode->step());
    long allocations = 0;
    double save_us = 0.0, restore_us = 0.0;
    {
      NoMalloc guard;
      const auto t0 = std::chrono::steady_clock::now();
      mode->save(snapshot);
      const auto t1 = std::chrono::steady_clock::now();
      const RestoreStatus restored = mode->restore(snapshot);
      const auto t2 = std::chrono::steady_clock::now();
      const bool stepped = mode->step() && mode->step();
      allocations = NoMalloc::count();
      EXPECT_EQ(restored, RestoreStatus::ok) << c.name;
      EXPECT_TRUE(stepped) << c.name;
      save_us = std::chrono::duration<double, std::micro>(t1 - t0).count();
      restore_us = std::chrono::duration<double, std::micro>(t2 - t1).count();
    }
    EXPECT_EQ(allocations, 0) << c.name << ": allocations in save(), restore() or step()";
    std::printf("  %-26s step %4lld of %4lld: snapshot %7ld bytes (%ld allocations, first save), "
                "save %6.1f us, restore %6.1f us\n",
                c.name, static_cast<long long>(half + 5),
                static_cast<long long>(mode->steps_total()),
                long(sizeof(ModeSnapshot)) + first_bytes, first_allocations, save_us, restore_us);
  }
}

// A snapshot of another kind of mode, of another scenario or length, or saved with a pilot the
// mode's own cannot continue from is refused, and the mode is left as it was.
TEST(Snapshot, OfAnotherKindScenarioOrPilotIsRefusedAndChangesNothing) {
  const Case& mi = find_case("mi_helix_novice");
  const Case& pendubot = find_case("pendubot_swingup");
  const std::string mi_text = scenario_text(mi), pendubot_text = scenario_text(pendubot);
  std::unique_ptr<Mode> a = make(mi, mi_text);
  std::unique_ptr<Mode> other_kind = make(pendubot, pendubot_text);
  ASSERT_TRUE(a && other_kind);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(a->step() && other_kind->step());
  ModeSnapshot of_mi, of_pendubot, empty;
  a->save(of_mi);
  other_kind->save(of_pendubot);
  EXPECT_EQ(of_mi.kind(), ModeKind::mixed_initiative);
  EXPECT_EQ(of_mi.step(), 10);
  EXPECT_EQ(of_mi.scenario_name(), "mi_helix");

  // `b` flew on from the same start; each refusal leaves it where it was.
  std::unique_ptr<Mode> b = make(mi, mi_text);
  ASSERT_TRUE(b);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(b->step());
  const Eigen::VectorXd x = b->telemetry().x;
  const auto unchanged = [&b, &x](const char* what) {
    EXPECT_EQ(b->steps_done(), 20) << what;
    EXPECT_EQ(b->telemetry().x, x) << what;
  };
  EXPECT_EQ(b->restore(empty), RestoreStatus::empty);
  unchanged("empty");
  EXPECT_EQ(b->restore(of_pendubot), RestoreStatus::other_kind);
  unchanged("other kind");
  EXPECT_EQ(other_kind->restore(of_mi), RestoreStatus::other_kind);
  EXPECT_NE(std::string(to_string(RestoreStatus::other_kind)), "");

  // The same scenario flown for another length.
  Case longer = mi;
  longer.duration = 3.0;
  std::unique_ptr<Mode> c = make(longer, mi_text);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->restore(of_mi), RestoreStatus::other_scenario);
  EXPECT_EQ(c->steps_done(), 0);
  // The same scenario with another input delay: the delay line has another length.
  Case delayed = mi;
  delayed.set = {{"input_delay", "0.03"}};
  std::unique_ptr<Mode> d = make(delayed, scenario_text(delayed));
  ASSERT_TRUE(d);
  EXPECT_EQ(d->restore(of_mi), RestoreStatus::other_scenario);
  EXPECT_EQ(d->steps_done(), 0);

  // The experienced pilot reacts without delay: it cannot continue the novice's delay line.
  Case experienced = mi;
  experienced.pilot = "experienced";
  experienced.input_lost = {-1, -1};
  std::unique_ptr<Mode> e = make(experienced, mi_text);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->restore(of_mi), RestoreStatus::pilot);
  EXPECT_EQ(e->steps_done(), 0);
  // The reckless pilot keeps nothing: it takes over the novice's flight; but the novice cannot
  // continue the reckless pilot's, which saved no NMPC.
  std::string error;
  const std::optional<Scenario> scenario = parse_scenario(mi_text, scenario_path(mi), error);
  ASSERT_TRUE(scenario) << error;
  std::unique_ptr<Mode> reckless =
      make(mi, mi_text, make_scenario_pilot(*scenario, "reckless", error));
  ASSERT_TRUE(reckless);
  EXPECT_EQ(reckless->restore(of_mi), RestoreStatus::ok);
  EXPECT_EQ(reckless->steps_done(), 10);
  ModeSnapshot of_reckless;
  reckless->save(of_reckless);
  EXPECT_EQ(b->restore(of_reckless), RestoreStatus::pilot);
  unchanged("a reckless pilot's snapshot");

  // A remote vehicle's plant runs elsewhere: it cannot go back, nor be put back here.
  const Case& tracking = find_case("tracking_helix");
  const std::string tracking_text = scenario_text(tracking);
  std::unique_ptr<Mode> local = make(tracking, tracking_text);
  std::unique_ptr<Mode> remote = make(tracking, tracking_text);
  ASSERT_TRUE(local && remote);
  const models::Crazyflie model;
  test::DelayedPlantLink<models::Crazyflie> link(model, model.hover_state({0.0, 0.0, 0.4}),
                                                 remote->dt(), 15, 0.03, 0.03,
                                                 std::size_t(remote->steps_total()));
  ASSERT_TRUE(remote->set_vehicle(&link));
  for (int k = 0; k < 5; ++k) ASSERT_TRUE(local->step() && remote->step());
  ModeSnapshot of_local, of_remote;
  local->save(of_local);
  remote->save(of_remote);
  EXPECT_EQ(remote->restore(of_local), RestoreStatus::remote_vehicle);
  EXPECT_EQ(local->restore(of_remote), RestoreStatus::remote_vehicle);
  EXPECT_EQ(local->steps_done(), 5);
  EXPECT_EQ(local->restore(of_local), RestoreStatus::ok);

  // A snapshot saved into again, from a mode of another kind, becomes that mode's.
  other_kind->save(of_mi);
  EXPECT_EQ(of_mi.kind(), ModeKind::pendubot_swingup);
  EXPECT_EQ(b->restore(of_mi), RestoreStatus::other_kind);
  EXPECT_EQ(other_kind->restore(of_mi), RestoreStatus::ok);
}

}  // namespace
}  // namespace mixpilot
