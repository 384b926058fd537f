// Every mode behind the one Mode interface (core/modes/mode.hpp), made from its shipped
// scenario through make_mode(): two runs are identical bit for bit, step() allocates nothing
// (every malloc is counted, no_malloc.hpp), the metrics show the thesis behaviour, and a
// recording of the run reads back with one state and one channel message per step.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "delayed_plant_link.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "no_malloc.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

using MetricMap = std::map<std::string, double>;

struct ModeCase {
  const char* name;      // test name
  const char* scenario;  // under scenarios/
  const char* pilot;     // mixed initiative only
  ModeKind kind;
  std::function<void(const MetricMap&)> thesis;  // the behaviour the mode's own tests check
};

std::string print_case(const testing::TestParamInfo<ModeCase>& info) { return info.param.name; }
void PrintTo(const ModeCase& c, std::ostream* os) {
  *os << c.scenario << (c.pilot ? std::string(" pilot=") + c.pilot : std::string());
}

std::unique_ptr<Mode> make(const ModeCase& c) {
  ModeRequest request;
  if (c.pilot) request.pilot_name = c.pilot;
  std::string error;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + c.scenario,
                        std::move(request), error);
  EXPECT_TRUE(mode) << error;
  return mode;
}

MetricMap metric_map(const Metrics& metrics) {
  MetricMap m;
  for (const auto& [name, value] : metrics) m[name] = value;
  return m;
}

// Every metric but the timings (which measure the machine, not the flight).
Metrics without_timing(Metrics metrics) {
  std::erase_if(metrics, [](const auto& m) {
    return m.first.ends_with("_us") || m.first == "deadline_misses";
  });
  return metrics;
}

class EveryMode : public testing::TestWithParam<ModeCase> {};

TEST_P(EveryMode, RunsDeterministicallyWithoutAllocatingAndShowsTheThesisBehaviour) {
  const ModeCase& c = GetParam();
  auto a = make(c);
  auto b = make(c);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->kind(), c.kind);
  ASSERT_GT(a->steps_total(), 0);
  ASSERT_FALSE(a->finished());
  const int nx = int(a->telemetry().x.size());
  ASSERT_GT(nx, 0);

  std::vector<Eigen::VectorXd> xa, ua;
  xa.reserve(std::size_t(a->steps_total()));
  ua.reserve(std::size_t(a->steps_total()));
  bool telemetry_ok = true;
  const GuardedSteps run = step_to_end_without_malloc(*a, [&] {
    const Telemetry& t = a->telemetry();
    telemetry_ok = telemetry_ok && t.step == std::int64_t(xa.size()) && t.mode == c.kind &&
                   t.x.size() == nx && t.num_channels <= Telemetry::kMaxChannels;
    xa.push_back(t.x);
    ua.push_back(t.u);
  });
  const std::int64_t steps = run.steps;
  EXPECT_TRUE(telemetry_ok) << "step counter, mode, state size or channel count wrong";
  EXPECT_EQ(run.allocations, 0) << "allocations inside step()";
  EXPECT_TRUE(a->finished());
  EXPECT_FALSE(a->lost());
  EXPECT_EQ(a->steps_done(), steps);
  EXPECT_EQ(steps, a->steps_total());

  std::size_t k = 0;
  while (b->step()) {
    ASSERT_LT(k, xa.size());
    ASSERT_EQ(b->telemetry().x, xa[k]) << "step " << k;  // bit for bit
    ASSERT_EQ(b->telemetry().u, ua[k]) << "step " << k;
    ++k;
  }
  EXPECT_EQ(k, xa.size());
  EXPECT_EQ(without_timing(b->metrics()), without_timing(a->metrics()));
  c.thesis(metric_map(a->metrics()));
  EXPECT_FALSE(a->summary().empty());
}

TEST_P(EveryMode, RecordsEveryStepAndReadsItBack) {
  const ModeCase& c = GetParam();
  auto mode = make(c);
  ASSERT_TRUE(mode);
  const std::string path = test::fresh_path("modes", std::string(c.name) + ".mcap").string();
  std::string error, text;
  ASSERT_TRUE(read_text_file(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + c.scenario, text,
                             error));
  RecordingSink recorder;
  RecordingSink::Settings settings;
  settings.slots = 4;  // a small ring: the stepping thread must wait for the writer, not lose
  SessionInfo info{to_string(mode->kind()), text, c.scenario, 1, c.pilot ? c.pilot : ""};
  ASSERT_TRUE(recorder.open(path, *mode, info, error, settings)) << error;
  Session session(*mode);
  session.add_sink(&recorder);
  std::vector<Eigen::VectorXd> states;
  struct Trace final : TelemetrySink {
    std::vector<Eigen::VectorXd>* x;
    void on_sample(const Telemetry& s) override { x->push_back(s.x); }
  } trace;
  trace.x = &states;
  session.add_sink(&trace);
  session.run();
  ASSERT_TRUE(recorder.close(error)) << error;
  EXPECT_EQ(recorder.dropped(), 0);

  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  EXPECT_EQ(rec->metadata.at("mode"), to_string(c.kind));
  EXPECT_EQ(rec->metadata.at("scenario"), text);
  ASSERT_EQ(rec->states.size(), states.size());
  ASSERT_EQ(rec->channels.size(), states.size());
  ASSERT_EQ(rec->solver.size(), states.size());
  EXPECT_EQ(rec->pilot.size(), c.kind == ModeKind::mixed_initiative ? states.size() : 0u);
  for (std::size_t k = 0; k < states.size(); ++k) {
    ASSERT_EQ(rec->states[k].step, k);
    ASSERT_EQ(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(rec->states[k].x.data(),
                                                                   Eigen::Index(rec->states[k].x.size()))),
              states[k])
        << "step " << k;
  }
  const Telemetry& last = mode->telemetry();
  ASSERT_EQ(rec->channels.back().names.size(), std::size_t(last.num_channels));
  for (int i = 0; i < last.num_channels; ++i) {
    EXPECT_EQ(rec->channels.back().names[std::size_t(i)], last.channels[std::size_t(i)].name);
    EXPECT_EQ(rec->channels.back().values[std::size_t(i)], last.channels[std::size_t(i)].value);
  }
  std::filesystem::remove(path);
}

double at(const MetricMap& m, const std::string& name) {
  const auto it = m.find(name);
  EXPECT_NE(it, m.end()) << "no metric " << name;
  return it == m.end() ? 0.0 : it->second;
}

// The thesis behaviour of each mode, as its own tests check it (test_session, test_pendubot,
// test_tracking, test_obstacles), read from the metrics.
const ModeCase kCases[] = {
    {"mi_helix_novice", "mi_helix.toml", "novice", ModeKind::mixed_initiative,
     [](const MetricMap& m) {  // Fig. 7.6: inside B (to 2 cm), nothing hit, authority shared
       EXPECT_EQ(at(m, "collisions"), 0);
       EXPECT_LE(at(m, "max_deviation_m"), 0.175 + 0.02);
       EXPECT_EQ(at(m, "progress"), 1.0);
       EXPECT_LT(at(m, "mean_lambda"), 0.65);
       EXPECT_EQ(at(m, "fallbacks"), 0);
     }},
    {"mi_helix_experienced", "mi_helix.toml", "experienced", ModeKind::mixed_initiative,
     [](const MetricMap& m) {  // Fig. 7.5: the experienced pilot keeps the authority
       EXPECT_EQ(at(m, "collisions"), 0);
       EXPECT_GE(at(m, "mean_lambda"), 0.8);
       EXPECT_EQ(at(m, "progress"), 1.0);
     }},
    {"pendubot_swingup", "pendubot_swingup.toml", nullptr, ModeKind::pendubot_swingup,
     [](const MetricMap& m) {  // ch. 4: up-up within 2.5 s and held; |u| ≤ 0.4 N·m
       EXPECT_GT(at(m, "swingup_time_s"), 0.0);
       EXPECT_LT(at(m, "swingup_time_s"), 2.5);
       EXPECT_GT(at(m, "hold_time_s"), 5.0);
       EXPECT_LE(at(m, "max_abs_u"), 0.4 + 1e-9);
       EXPECT_EQ(at(m, "velocity_violations"), 0);
       EXPECT_GE(at(m, "lqr_entries"), 1);
     }},
    {"pendubot_swingup_encoders", "pendubot_swingup_encoders.toml", nullptr,
     ModeKind::pendubot_swingup,
     [](const MetricMap& m) {  // quantized encoders: still up-up and held
       EXPECT_GT(at(m, "swingup_time_s"), 0.0);
       EXPECT_GT(at(m, "hold_time_s"), 4.0);
       EXPECT_LE(at(m, "max_abs_u"), 0.4 + 1e-9);
     }},
    {"tracking_smooth_step", "tracking_smooth_step.toml", nullptr, ModeKind::crazyflie_tracking,
     [](const MetricMap& m) {  // ch. 5, RTT 60 ms with the predictor: tracks within 1 cm RMS
       EXPECT_LT(at(m, "tracking_rms_m"), 0.01);
       EXPECT_LT(at(m, "final_error_m"), 0.01);
       EXPECT_EQ(at(m, "lost"), 0);
       EXPECT_EQ(at(m, "fallbacks"), 0);
     }},
    {"tracking_helix", "tracking_helix.toml", nullptr, ModeKind::crazyflie_tracking,
     [](const MetricMap& m) {
       EXPECT_LT(at(m, "tracking_rms_m"), 0.01);
       EXPECT_EQ(at(m, "lost"), 0);
     }},
    {"obstacles_thrown_balls", "obstacles_thrown_balls.toml", nullptr,
     ModeKind::obstacle_avoidance,
     [](const MetricMap& m) {  // ch. 6, LCL: the clearance d_C = 0.2 m holds to 1 mm
       EXPECT_GE(at(m, "min_distance_m"), 0.2 - 1e-3);
       EXPECT_EQ(at(m, "violations"), 0);
       EXPECT_EQ(at(m, "fallbacks"), 0);
     }},
    {"obstacles_cluttered", "obstacles_cluttered.toml", nullptr, ModeKind::obstacle_avoidance,
     [](const MetricMap& m) {
       EXPECT_GE(at(m, "min_distance_m"), 0.2 - 1e-3);
       EXPECT_EQ(at(m, "violations"), 0);
     }},
};

INSTANTIATE_TEST_SUITE_P(Shipped, EveryMode, testing::ValuesIn(kCases), print_case);

// Sustained overload (SPEC §4's failure policy exhausted): every solve of a long stretch overruns,
// as on a machine that cannot keep up. After 5 fallbacks in a row the safe controller flies
// (kEventSafeHold, kEventSwitch where it takes over), nothing is lost, and 5 good solves in a row
// after the stretch hand the vehicle back to the MPC; without allocating, and a second run
// switches at the same steps.
TEST_P(EveryMode, OverrunsInARowHandTheVehicleToTheSafeControllerAndBack) {
  const ModeCase& c = GetParam();
  auto mode = make(c);
  ASSERT_TRUE(mode);
  // A stretch of overruns a third into the run, as long as a third of it; the Pendubot's during
  // its swing-up (its LQR, once it flies, solves no QP to overrun), 0.4 s long.
  const std::int64_t total = mode->steps_total();
  const bool pendubot = c.kind == ModeKind::pendubot_swingup;
  const std::int64_t first = pendubot ? 100 : total / 3;
  const std::int64_t last = first + (pendubot ? 200 : total / 3);
  std::vector<std::int64_t> overruns;
  for (std::int64_t k = first; k <= last; ++k) overruns.push_back(k);
  const std::int64_t safe_from = first + rti_defaults::kSafeAfterFallbacks - 1;
  const std::int64_t safe_to = last + rti_defaults::kSafeAfterFallbacks - 1;  // last safe step
  mode->replay_timing(overruns);

  std::vector<std::uint32_t> events;
  events.reserve(std::size_t(total));
  const GuardedSteps run =
      step_to_end_without_malloc(*mode, [&] { events.push_back(mode->telemetry().events); });
  EXPECT_EQ(run.allocations, 0);
  EXPECT_FALSE(mode->lost());
  ASSERT_EQ(std::int64_t(events.size()), total);
  for (std::int64_t k = 0; k < total; ++k) {
    const bool safe = (events[std::size_t(k)] & kEventSafeHold) != 0;
    ASSERT_EQ(safe, k >= safe_from && k <= safe_to) << "step " << k;
    if (k == safe_from || k == safe_to + 1) {
      EXPECT_NE(events[std::size_t(k)] & kEventSwitch, 0u) << "step " << k;
    }
  }
  const MetricMap m = metric_map(mode->metrics());
  if (c.kind == ModeKind::mixed_initiative) {  // held, then flown back into B: nothing hit
    EXPECT_EQ(at(m, "collisions"), 0);
    EXPECT_NEAR(at(m, "safe_hold_s"), double(safe_to - safe_from + 1) * mode->dt(), 1e-9);
    const Telemetry& end = mode->telemetry();
    EXPECT_LE((end.x.head<3>() - end.reference).norm(), 0.175);
  } else if (c.kind == ModeKind::crazyflie_tracking) {  // the LQR kept tracking the reference
    EXPECT_LT(at(m, "tracking_rms_m"), 0.05);
  }

  auto again = make(c);
  again->replay_timing(overruns);
  std::size_t k = 0;
  while (again->step()) ASSERT_EQ(again->telemetry().events, events[k++]) << "step " << k;
}

// A session length given apart from the file (fly --duration) obeys the file's own rule: the
// helix reference keeps the ball B and the vehicle in it (r + r_v = 0.175 + 0.3 m) clear of the
// walls, floor and ceiling. mi_helix_slow climbs at 0.016667 m/s from 0.6 m towards its 2.5 m
// ceiling: it comes within 0.475 m of it at t = (2.025 − 0.6) / 0.016667 ≈ 85.498 s (and would
// leave the arena at 114 s). mi_helix (1 m in 30 s) allows 42.75 s: a novice flying 57 s of it
// scraped the ceiling from 36.6 s.
TEST(MakeMode, ASessionLengthThatTakesTheReferenceNearTheWallsIsRefused) {
  const std::string dir = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/";
  struct Case {
    const char* file;
    double seconds;
    const char* refused;  // nullptr: accepted
  };
  for (const Case& c : {Case{"mi_helix_slow.toml", 85.4, nullptr},
                        Case{"mi_helix_slow.toml", 85.6, "ceiling at t = 85.498 s"},
                        Case{"mi_helix_slow.toml", 300.0, "ceiling at t = 85.498 s"},
                        Case{"mi_helix.toml", 42.7, nullptr},
                        Case{"mi_helix.toml", 57.0, "ceiling at t = 42.754 s"}}) {
    ModeRequest request;
    request.duration = c.seconds;
    std::string error;
    const auto mode = load_mode(dir + c.file, std::move(request), error);
    if (!c.refused) {
      EXPECT_TRUE(mode) << c.file << " " << c.seconds << ": " << error;
    } else {
      EXPECT_FALSE(mode) << c.file << " " << c.seconds;
      EXPECT_NE(error.find(std::string("flies the reference closer than 0.475 m (the ball's "
                                       "radius 0.175 m and the vehicle's 0.300 m) to the "
                                       "arena's ") + c.refused),
                std::string::npos)
          << error;
      EXPECT_NE(error.find("this scenario allows at most"), std::string::npos) << error;
    }
  }
}


// --- A remote vehicle (core/modes/vehicle_link.hpp) -------------------------------------

// The modes that fly a remote vehicle step it without allocating, and the mixed-initiative
// mode over a vehicle without delay starts every step from the state its own plant would have
// (the newest state, one period old, predicted over that period): the same states, the same
// commands, the same score.
TEST(RemoteVehicle, TheMixedInitiativeModeFliesItAsItsOwnPlant) {
  const ModeCase c{"mi", "mi_helix.toml", "novice", ModeKind::mixed_initiative, nullptr};
  auto local = make(c), remote = make(c);
  ASSERT_TRUE(local && remote);
  const models::MikroKopter model;
  const auto& mi = dynamic_cast<const MiMode&>(*remote);
  test::DelayedPlantLink<models::MikroKopter> link(model, mi.state(), remote->dt(), 15, 0.0, 0.0,
                                                   std::size_t(remote->steps_total()));
  ASSERT_TRUE(remote->set_vehicle(&link));
  double worst_x = 0, worst_u = 0;
  long steps = 0;
  const GuardedSteps run = step_to_end_without_malloc(*remote, [&] {
    if (!local->step()) return;
    const Telemetry &a = local->telemetry(), &b = remote->telemetry();
    worst_x = std::max(worst_x, (a.x_measured - b.x_measured).lpNorm<Eigen::Infinity>());
    worst_u = std::max(worst_u, (a.u - b.u).lpNorm<Eigen::Infinity>());
    ++steps;
  });
  EXPECT_EQ(run.allocations, 0);
  EXPECT_EQ(run.steps, remote->steps_total());
  EXPECT_EQ(steps, run.steps);
  EXPECT_LE(worst_x, 1e-12);
  EXPECT_LE(worst_u, 1e-12);
  EXPECT_TRUE(link.finished());
  const MetricMap m = metric_map(remote->metrics());
  EXPECT_NEAR(m.at("rtt_s"), 0.0, 1e-12);
  EXPECT_NEAR(m.at("rtt_estimated_s"), 0.0, 1e-12);
  const MetricMap l = metric_map(local->metrics());
  for (const char* key : {"skill", "time_in_ball", "max_deviation_m", "mean_lambda", "collisions"})
    EXPECT_NEAR(m.at(key), l.at(key), 1e-9) << key;
}

TEST(RemoteVehicle, TheTrackingModeStepsItWithoutAllocating) {
  const ModeCase c{"tracking", "tracking_helix.toml", nullptr, ModeKind::crazyflie_tracking,
                   nullptr};
  auto mode = make(c);
  ASSERT_TRUE(mode);
  const models::Crazyflie model;
  test::DelayedPlantLink<models::Crazyflie> link(model, model.hover_state({0.0, 0.0, 0.38}),
                                                 mode->dt(), 15, 0.03, 0.03,
                                                 std::size_t(mode->steps_total()));
  ASSERT_TRUE(mode->set_vehicle(&link));
  const GuardedSteps run = step_to_end_without_malloc(*mode, [] {});
  EXPECT_EQ(run.allocations, 0);
  EXPECT_EQ(run.steps, mode->steps_total());
  EXPECT_FALSE(mode->lost());
  const MetricMap m = metric_map(mode->metrics());
  EXPECT_NEAR(m.at("rtt_estimated_s"), 0.06, 1e-12);
  EXPECT_LT(m.at("tracking_rms_m"), 0.05);
}

// A remote MikroKopter that keeps talking but is of no use ends the mixed-initiative flight as
// lost with its reason, within the link's timeout (plus the longest round trip when it never
// acknowledges), instead of flying on with fallbacks: one that sits still, never acknowledges,
// or jumps to exactly the loss margin outside the arena.
TEST(RemoteVehicle, AMixedInitiativeVehicleOfNoUseIsLostWithItsReason) {
  const ModeCase c{"mi", "mi_helix.toml", "novice", ModeKind::mixed_initiative, nullptr};
  struct Case {
    const char* name;
    std::function<void(std::int64_t, VehicleSample&)> mutate;
    const char* reason;  // how the lost reason starts
    double lost_by;      // [s]
  };
  const auto probe = make(c);
  ASSERT_TRUE(probe);
  const auto& mi0 = dynamic_cast<const MiMode&>(*probe);
  const Eigen::VectorXd x0 = mi0.state();
  const double edge = mi0.scenario().arena.max.x() + mi_defaults::kLostMargin;
  const Case cases[] = {
      {"sits still", [&](std::int64_t, VehicleSample& v) { v.x = x0; }, "it does not move", 0.35},
      // Its state held as well: the controller flies it blind (no command acknowledged, no round
      // trip measured), its QPs fail and the plant may tumble into a non-finite state before the
      // acknowledgement check's 0.75 s, earlier or later with the solver's last digits; held, the
      // loss can only be the one this case is about.
      {"never acknowledges",
       [&](std::int64_t, VehicleSample& v) {
         v.x = x0;
         v.command = -1;
         v.command_stamp_ns = 0;
       },
       "it never acknowledged a command", 0.8},
      {"jumps to exactly the loss margin",
       [&](std::int64_t k, VehicleSample& v) {
         if (k >= 40) v.x(0) = edge;
       },
       "it left the arena", 40 * 0.015 + 0.05},
  };
  for (const Case& cs : cases) {
    auto mode = make(c);
    ASSERT_TRUE(mode);
    const models::MikroKopter model;
    test::DelayedPlantLink<models::MikroKopter> link(model, x0, mode->dt(), 15, 0.0, 0.0,
                                                     std::size_t(mode->steps_total()));
    link.timeout = 0.25;
    link.mutate = cs.mutate;
    ASSERT_TRUE(mode->set_vehicle(&link));
    while (mode->step()) {
    }
    const std::string summary = mode->summary();
    std::printf("%s:\n%s", cs.name, summary.c_str());
    EXPECT_TRUE(mode->lost()) << cs.name;
    EXPECT_NE(summary.find(std::string(" s: ") + cs.reason), std::string::npos) << cs.name;
    EXPECT_LE(mode->lost_at(), cs.lost_by) << cs.name;
    EXPECT_TRUE(link.finished()) << cs.name;
  }
}

// Modes without a remote vehicle say so.
TEST(RemoteVehicle, OtherModesRefuseIt) {
  for (const char* scenario : {"pendubot_swingup.toml", "obstacles_cluttered.toml"}) {
    auto mode = make({"other", scenario, nullptr, ModeKind::pendubot_swingup, nullptr});
    ASSERT_TRUE(mode);
    test::DelayedPlantLink<models::Crazyflie> link(models::Crazyflie{},
                                                   models::Crazyflie{}.hover_state({0, 0, 1}),
                                                   0.015, 15, 0, 0, 1);
    EXPECT_FALSE(mode->set_vehicle(&link)) << scenario;
  }
}

}  // namespace
}  // namespace mixpilot
