// The real-time runner and its hand-over ring (core/runtime/).
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "core/modes/make_mode.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "core/base/spsc_ring.hpp"

namespace mixpilot {
namespace {

TEST(SpscRing, KeepsOrderAndCountsWhatAFullRingDrops) {
  SpscRing<int> ring;
  ring.setup(3, 0);
  for (int i = 0; i < 5; ++i) ring.push(i);  // 3 fit, 2 dropped
  EXPECT_EQ(ring.dropped(), 2);
  int v = -1;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(ring.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(ring.pop(v));
}

// A reader thread sees every value once, in order, while the writer never waits.
TEST(SpscRing, AReaderThreadSeesEveryValueInOrder) {
  SpscRing<long> ring;
  ring.setup(64, 0);
  constexpr long kN = 200000;
  long expected = 0, bad = 0;
  std::thread reader([&] {
    long v = 0;
    while (expected < kN) {
      if (!ring.pop(v)) continue;
      bad += v != expected ? 1 : 0;
      ++expected;
    }
  });
  for (long i = 0; i < kN; ++i)
    while (!ring.push(i)) std::this_thread::yield();  // the test waits; the control thread would drop
  reader.join();
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(expected, kN);
}

std::unique_ptr<Mode> short_flight(double seconds) {
  ModeRequest request;
  request.duration = seconds;
  request.pilot_name = "novice";
  std::string error;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml",
                        std::move(request), error);
  EXPECT_TRUE(mode) << error;
  return mode;
}

// A deadline no solve can meet: every step is an overrun, handled as a fallback (SPEC §4);
// without a deadline (as-fast-as-possible runs) none is.
TEST(RealtimeRunner, ASolveOverItsDeadlineFallsBack) {
  for (const double deadline_us : {0.0, 1e-6}) {
    auto mode = short_flight(0.15);
    ASSERT_TRUE(mode);
    mode->set_deadline_us(deadline_us);
    int overruns = 0, steps = 0;
    while (mode->step()) {
      ++steps;
      const std::uint32_t e = mode->telemetry().events;
      overruns += (e & kEventOverrun) ? 1 : 0;
      if (e & kEventOverrun) {
        EXPECT_TRUE(e & kEventFallback);
      }
    }
    EXPECT_EQ(overruns, deadline_us > 0 ? steps : 0) << "deadline " << deadline_us << " us";
  }
}

// A real-time run flies every step of the mode and hands each one over, in order.
TEST(RealtimeRunner, FliesEveryStepAndHandsEachOver) {
  auto mode = short_flight(0.3);
  ASSERT_TRUE(mode);
  Session session(*mode);
  RealtimeRunner runner(session, 1024);
  runner.start();
  while (runner.running()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  runner.stop();
  EXPECT_TRUE(mode->finished());
  EXPECT_EQ(runner.stats().steps, mode->steps_total());
  Telemetry s = mode->telemetry();
  std::int64_t n = 0, previous = -1;
  while (runner.telemetry().pop(s)) {
    EXPECT_GT(s.step, previous);
    previous = s.step;
    ++n;
  }
  EXPECT_EQ(n, mode->steps_total());
}

// Paused, the runner flies no step at all; resumed, it goes on.
TEST(RealtimeRunner, PauseStopsStepsAndResumeGoesOn) {
  auto mode = short_flight(1.0);
  ASSERT_TRUE(mode);
  Session session(*mode);
  RealtimeRunner runner(session, 1024);
  runner.set_paused(true);
  runner.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(runner.stats().steps, 0);
  runner.set_paused(false);
  while (runner.running() && runner.stats().steps < 3)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_GE(runner.stats().steps, 3);
  runner.stop();
  EXPECT_FALSE(mode->finished());  // stopped early: the run was cut at the next step
}

// A mode whose step costs nothing but what its sink makes it wait: the runner's timing rules
// tested apart from the solver's speed (which a sanitizer build on a loaded machine can make
// longer than a period by itself).
class IdleMode final : public Mode {
 public:
  explicit IdleMode(std::int64_t steps) : steps_(steps) {}
  ModeKind kind() const override { return ModeKind::mixed_initiative; }
  const std::string& scenario_name() const override { return name_; }
  double dt() const override { return 0.015; }
  std::int64_t steps_total() const override { return steps_; }
  std::int64_t steps_done() const override { return done_; }
  bool step() override {
    if (done_ >= steps_) return false;
    telemetry_.step = done_;
    telemetry_.t = double(done_) * dt();
    telemetry_.events = deadline_event(done_, 0.0, false);  // computing takes no time here
    ++done_;
    return true;
  }
  bool finished() const override { return done_ >= steps_; }
  bool lost() const override { return false; }
  double lost_at() const override { return -1.0; }
  const Telemetry& telemetry() const override { return telemetry_; }
  Metrics metrics() const override { return {}; }
  std::string summary() const override { return ""; }
  ModeView view() const override { return {}; }
  void set_deadline_us(double) override {}

 protected:
  struct Saved final : ModeSnapshot::State {
    std::int64_t done = 0;
    Telemetry telemetry;
  };
  void save_state(std::unique_ptr<ModeSnapshot::State>& state) const override {
    if (!state) state = std::make_unique<Saved>();
    static_cast<Saved&>(*state).done = done_;
    static_cast<Saved&>(*state).telemetry = telemetry_;
  }
  RestoreStatus restore_state(const ModeSnapshot::State& state) override {
    done_ = static_cast<const Saved&>(state).done;
    telemetry_ = static_cast<const Saved&>(state).telemetry;
    return RestoreStatus::ok;
  }

 private:
  std::int64_t steps_, done_ = 0;
  std::string name_ = "idle";
  Telemetry telemetry_;
};

// Paced by the wall clock: K steps of Δt at speed s take at least (K − 1) Δt / s of wall time,
// whatever else the machine does (a runner never runs ahead of its schedule; a loaded machine
// can only make it later, so only the lower bound is a verdict). At 1×, 0.5× and 0.25×; a
// runner without its sleep finished 0.3 s of flight in 25 ms.
TEST(RealtimeRunner, PacingFollowsTheWallClockAtEverySpeed) {
  for (const double speed : {1.0, 0.5, 0.25}) {
    IdleMode mode(20);  // 0.3 s of 15 ms steps
    Session session(mode);
    RealtimeRunner runner(session, 64);
    runner.set_speed(speed);
    const auto t0 = std::chrono::steady_clock::now();
    runner.start();
    while (runner.running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    runner.stop();
    EXPECT_EQ(runner.stats().steps, 20);
    EXPECT_GE(wall, 19 * mode.dt() / speed) << "speed " << speed;
  }
}

// A step that ends after its period makes the next one's input late by as much: a deadline
// miss, counted once (the schedule restarts from its end, so the steps after it are on time
// again; were it kept, the six steps due during the 100 ms overrun would all end late), and
// simulated time falls behind the wall clock by the overshoot. Steps that take part of the
// period are not misses, and the p99 step time reflects them, not the one outlier.
TEST(RealtimeRunner, ADeadlineMissIsAStepThatEndsAfterItsPeriod) {
  IdleMode mode(200);  // 3 s of 15 ms steps
  struct Slow : TelemetrySink {
    void on_sample(const Telemetry& s) override {
      std::this_thread::sleep_for(std::chrono::milliseconds(s.step == 50 ? 100 : 4));
    }
  } slow;
  Session session(mode);
  session.add_sink(&slow);
  RealtimeRunner runner(session, 1024);
  runner.start();
  while (runner.running()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  runner.stop();
  const RealtimeStats st = runner.stats();
  EXPECT_EQ(st.steps, 200);
  EXPECT_GE(st.deadline_misses, 1);
  EXPECT_LE(st.deadline_misses, 3);  // the outlier (and at most two strays of a loaded machine)
  EXPECT_GE(st.worst_step_us, 100000.0);
  EXPECT_GE(st.slip_s, 0.085 - 0.004);  // the 100 ms step's overshoot of its 15 ms period
  EXPECT_GE(st.p99_step_us, 4000.0);
  EXPECT_LT(st.p99_step_us, 15000.0);
}

}  // namespace
}  // namespace mixpilot
