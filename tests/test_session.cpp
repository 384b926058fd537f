// Mixed-initiative sessions on the shipped mi_helix scenario (SPEC §5.4): the thesis's
// behaviour with the emulated pilots, the safety constraints against a reckless pilot, plant
// bounds, determinism, and record → replay → identical telemetry and score.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "core/control/hover_lqr.hpp"
#include "core/control/pilot_emulated.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/score.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "models/mikrokopter.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

const Scenario& mi_helix() {
  static const Scenario sc = [] {
    std::string error;
    auto s = load_scenario(MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml", error);
    if (!s) ADD_FAILURE() << error;
    return s ? *s : Scenario{};
  }();
  return sc;
}

// Extremes of the plant's rotor speeds and torques over a session.
struct BoundsSink final : TelemetrySink {
  double omega_min = 1e9, omega_max = -1e9, tau_min = 1e9, tau_max = -1e9;
  void on_sample(const Telemetry& s) override {
    omega_min = std::min(omega_min, s.x.tail<4>().minCoeff());
    omega_max = std::max(omega_max, s.x.tail<4>().maxCoeff());
    tau_min = std::min(tau_min, s.u.minCoeff());
    tau_max = std::max(tau_max, s.u.maxCoeff());
  }
};

std::unique_ptr<PilotSource> make_pilot(const Scenario& sc, const std::string& name) {
  const models::MikroKopter model;
  if (name == "reckless")
    return std::make_unique<RecklessPilot>(model, sc.arena, sc.pilots.at("reckless").max_tilt);
  auto p = std::make_unique<EmulatedPilot>();
  PilotProfile profile = sc.pilots.at(name);
  profile.name = name;
  EXPECT_TRUE(p->setup(model, profile, sc.reference, sc.controller.dt));
  return p;
}

struct Flight {
  Score score;
  BoundsSink bounds;
  bool lost = false;
};

Flight fly(const Scenario& sc, const std::string& pilot_name) {
  MiMode mode;
  const SetupResult r = mode.setup(sc, make_pilot(sc, pilot_name));
  EXPECT_TRUE(r) << r.reason();
  Session session(mode);
  Flight f;
  session.add_sink(&f.bounds);
  session.run();
  f.score = mode.score();
  f.lost = mode.lost();
  return f;
}

void expect_plant_bounds(const Flight& f) {
  const models::MikroKopterParams p;
  EXPECT_GE(f.bounds.omega_min, p.omega_min);
  EXPECT_LE(f.bounds.omega_max, p.omega_max);
  EXPECT_GE(f.bounds.tau_min, p.tau_min - 1e-9);  // QP tolerance on the input bounds
  EXPECT_LE(f.bounds.tau_max, p.tau_max + 1e-9);
}

// Figs. 7.5–7.7: both pilots stay inside B (to 2 cm) and hit nothing; the experienced pilot
// keeps authority (λ̄ ≥ 0.8), the novice loses it (λ̄ at least 0.15 lower) and scores lower.
void expect_thesis_behaviour(const Scenario& sc) {
  const double r = sc.controller.ph.r;
  const Flight novice = fly(sc, "novice");
  const Flight experienced = fly(sc, "experienced");
  for (const Flight* f : {&novice, &experienced}) {
    EXPECT_FALSE(f->lost);
    EXPECT_LE(f->score.max_deviation_m, r + 0.02);
    EXPECT_EQ(f->score.collisions, 0);
    EXPECT_EQ(f->score.fallbacks, 0);
    EXPECT_DOUBLE_EQ(f->score.progress, 1.0);
    expect_plant_bounds(*f);
  }
  EXPECT_GE(experienced.score.mean_lambda, 0.8);
  EXPECT_LE(novice.score.mean_lambda, experienced.score.mean_lambda - 0.15);
  EXPECT_LT(novice.score.skill, experienced.score.skill);
  std::printf("safety %s: novice lambda %.3f dev %.3f skill %.1f | experienced lambda %.3f "
              "dev %.3f skill %.1f\n",
              sc.controller.safety_constraints ? "on" : "off", novice.score.mean_lambda,
              novice.score.max_deviation_m, novice.score.skill, experienced.score.mean_lambda,
              experienced.score.max_deviation_m, experienced.score.skill);
}

TEST(MixedInitiative, ThesisBehaviourWithSafetyConstraints) {
  ASSERT_TRUE(mi_helix().controller.safety_constraints);
  expect_thesis_behaviour(mi_helix());
}

TEST(MixedInitiative, ThesisBehaviourInThePureFormulation) {
  Scenario sc = mi_helix();
  sc.controller.safety_constraints = false;
  expect_thesis_behaviour(sc);
}

TEST(MixedInitiative, RecklessPilotHitsNothingAndStaysInTheArena) {
  const Flight f = fly(mi_helix(), "reckless");
  EXPECT_FALSE(f.lost);
  EXPECT_EQ(f.score.collisions, 0);  // obstacles, walls and floor
  EXPECT_GT(f.score.min_clearance_m, 0.0);
  EXPECT_LT(f.score.mean_lambda, 0.3);  // the planner has the authority
  expect_plant_bounds(f);
  std::printf("reckless: lambda %.3f, min clearance %.3f m, max deviation %.3f m\n",
              f.score.mean_lambda, f.score.min_clearance_m, f.score.max_deviation_m);
}

// The safety layer is what stops a pilot when the PH index alone does not: an extra obstacle
// only 0.3 m from the reference (closer than mi_helix allows) is within the reckless pilot's
// reach at λ_min. Without the constraints it is hit; with them the clearance holds to 1 mm.
TEST(MixedInitiative, SafetyConstraintsStopARecklessPilotNearAnObstacle) {
  Scenario sc = mi_helix();
  const double a = 0.5236, t = 5.0;  // 30° along the helix, reached at t = 5 s
  const double R = sc.reference.radius + 0.3 + 0.15;
  sc.arena.obstacles.push_back(
      {Eigen::Vector3d(R * std::cos(a), R * std::sin(a), sc.reference.position(t).z()), 0.15});
  sc.controller.safety_constraints = false;
  const Flight unsafe = fly(sc, "reckless");
  sc.controller.safety_constraints = true;
  const Flight safe = fly(sc, "reckless");
  std::printf("near obstacle: min clearance %.4f m without, %.4f m with safety constraints\n",
              unsafe.score.min_clearance_m, safe.score.min_clearance_m);
  EXPECT_GE(unsafe.score.collisions, 1);
  EXPECT_LT(unsafe.score.min_clearance_m, -0.05);
  EXPECT_EQ(safe.score.collisions, 0);
  EXPECT_GT(safe.score.min_clearance_m, -1e-3);
  expect_plant_bounds(safe);
}

// The novice until t_lost, then its input lost (authority 0, as a device reports it): λ = 0.
class LosesInput final : public PilotSource {
 public:
  LosesInput(std::unique_ptr<PilotSource> pilot, double t_lost)
      : pilot_(std::move(pilot)), t_lost_(t_lost) {}
  std::string name() const override { return "loses-input"; }
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override {
    if (!pilot_->command(step, t, x, out)) return false;
    if (t >= t_lost_) {
      out.authority = 0.0;
      out.input = InputState::lost;
    }
    return true;
  }

 private:
  std::unique_ptr<PilotSource> pilot_;
  double t_lost_;
};

// While the input is lost the planner flies alone (λ = 0: the pilot's ν has no weight, so φ, θ
// and Ω carry no cost at the last node): every QP of the 10 s is solved, warm-started as the
// loop does, and the vehicle stays inside B.
TEST(MixedInitiative, ThePlannerFliesEveryStepWhileTheInputIsLost) {
  Scenario sc = mi_helix();
  sc.duration = 15.0;
  MiMode mode;
  ASSERT_TRUE(mode.setup(sc, std::make_unique<LosesInput>(make_pilot(sc, "novice"), 5.0)));
  int lost_steps = 0, fallbacks = 0;
  double deviation = 0.0;
  while (mode.step()) {
    const Telemetry& s = mode.telemetry();
    if (s.pilot.input != InputState::lost) continue;
    ++lost_steps;
    EXPECT_EQ(s.lambda, 0.0);
    fallbacks += s.stats.status != RtiStatus::success;
    deviation = std::max(deviation, (s.x.head<3>() - s.reference).norm());
  }
  EXPECT_EQ(lost_steps, 666);  // t = 5.01 s (step 334) to the end (step 999)
  EXPECT_EQ(fallbacks, 0);
  EXPECT_EQ(mode.score().fallbacks, 0);
  EXPECT_LE(deviation, sc.controller.ph.r);
  EXPECT_FALSE(mode.lost());
}

// The mixed-initiative mode's safe controller: its LQR stabilizes the hover linearization, and
// from 0.3 m off the point it holds, with some yaw and speed, the plant comes back to within
// 1 cm in 5 s without leaving the torque bounds.
TEST(MixedInitiative, TheHoverHoldLqrHoldsAPosition) {
  const models::MikroKopter model;
  HoverLqr lqr;
  ASSERT_TRUE(lqr.setup(model, MiWeights{}, 0.015));
  EXPECT_LT(lqr.spectral_radius(), 1.0);
  const IntegratorErk4<models::MikroKopter> erk4(model);
  const Eigen::Vector3d hold(1.0, -0.5, 1.2);
  models::MikroKopter::State x = model.hover_state(hold + Eigen::Vector3d(0.3, 0.0, -0.1));
  x(5) = 0.3;   // yaw
  x(6) = 0.5;   // forward speed
  models::MikroKopter::Input u;
  for (int k = 0; k < 333; ++k) {
    lqr.control(x, hold, u);
    EXPECT_LE(u.cwiseAbs().maxCoeff(), model.p.tau_max + 1e-12);
    for (int j = 0; j < 15; ++j) {
      models::MikroKopter::State xn;
      erk4.step(x, u, 0.001, xn);
      x = xn;
    }
  }
  EXPECT_LT((x.head<3>() - hold).norm(), 0.01);
  EXPECT_LT(std::abs(x(5)), 0.01);
}

// A pilot who holds the roll stick at φ_h and hover thrust, with a fixed authority.
class HoldsRoll final : public PilotSource {
 public:
  HoldsRoll(double roll, double authority) : roll_(roll), authority_(authority) {}
  std::string name() const override { return "holds-roll"; }
  bool command(std::int64_t, double, const Eigen::VectorXd&, PilotCommand& out) override {
    out.roll = roll_;
    out.pitch = 0.0;
    out.rotor_speed.setConstant(models::MikroKopter{}.hover_speed());
    out.authority = authority_;
    return true;
  }

 private:
  double roll_, authority_;
};

// λ blends the pilot's reference and the planner's inside the cost (SPEC §5.4). With the ball
// so wide that the PH index stays at 1, λ is the pilot's authority: near 1 the MPC's attitude
// follows the pilot's (the planner's reference has no weight), near 0 it ignores it and the
// vehicle tracks the planner's reference.
TEST(Blend, ThePilotFliesAtLambdaNearOneAndThePlannerNearZero) {
  Scenario sc = mi_helix();
  sc.duration = 1.0;
  sc.controller.ph.r = 100.0;
  constexpr double kRoll = 0.15;  // [rad]
  struct Result {
    double lambda = 0, roll_gap = 0, deviation = 0;
  };
  const auto fly_with = [&](double authority) {
    MiMode mode;
    EXPECT_TRUE(mode.setup(sc, std::make_unique<HoldsRoll>(kRoll, authority)));
    Result r;
    while (mode.step()) {
      const Telemetry& s = mode.telemetry();
      if (s.t < 0.5) continue;  // the attitude has settled
      r.lambda = std::max(r.lambda, s.lambda);
      r.roll_gap = std::max(r.roll_gap, std::abs(s.applied.roll - kRoll));
      r.deviation = std::max(r.deviation, (s.x.head<3>() - s.reference).norm());
    }
    return r;
  };
  const Result pilot = fly_with(1.0), planner = fly_with(0.0);
  std::printf("λ %.4f: roll gap %.4f rad, deviation %.3f m | λ %.4f: roll gap %.4f rad, "
              "deviation %.3f m\n", pilot.lambda, pilot.roll_gap, pilot.deviation, planner.lambda,
              planner.roll_gap, planner.deviation);
  EXPECT_GT(pilot.lambda, 0.999);
  EXPECT_EQ(planner.lambda, 0.0);
  EXPECT_LT(pilot.roll_gap, 0.02);        // the MPC flies the pilot's roll
  EXPECT_GT(pilot.deviation, 0.2);        // and the vehicle leaves the planner's path
  EXPECT_GT(planner.roll_gap, 0.1);       // the pilot's roll is ignored
  EXPECT_LT(planner.deviation, 0.06);     // the planner's reference is tracked (its own lag)
}

// Every sample of a session, for exact comparisons.
struct TraceSink final : TelemetrySink {
  std::vector<Eigen::VectorXd> x, u;
  std::vector<double> lambda;
  void on_sample(const Telemetry& s) override {
    x.push_back(s.x);
    u.push_back(s.u);
    lambda.push_back(s.lambda);
  }
};

Score without_timing(Score s) {
  s.rti_median_us = s.rti_p99_us = 0;
  s.deadline_misses = 0;
  return s;
}

TEST(Session, RecordThenReplayReproducesTelemetryAndScore) {
  Scenario sc = mi_helix();
  sc.duration = 4.0;
  const std::string path = test::fresh_path("session", "replay.mcap").string();

  TraceSink original;
  Score original_score;
  {
    MiMode mode;
    const SetupResult r = mode.setup(sc, make_pilot(sc, "novice"));
    ASSERT_TRUE(r) << r.reason();
    Session session(mode);
    std::string error;
    RecordingSink recorder;
    SessionInfo info{"mixed_initiative", sc.source_text, sc.source_path, sc.plant.seed, "novice"};
    ASSERT_TRUE(recorder.open(path, mode, info, error)) << error;
    session.add_sink(&original);
    session.add_sink(&recorder);
    session.run();
    ASSERT_TRUE(recorder.close(error)) << error;
    EXPECT_EQ(recorder.dropped(), 0);
    original_score = mode.score();
  }

  std::string error;
  const auto rec = read_recording(path, error);
  ASSERT_TRUE(rec) << error;
  ASSERT_EQ(rec->pilot.size(), original.x.size());
  EXPECT_EQ(rec->metadata.at("scenario"), sc.source_text);
  EXPECT_EQ(rec->metadata.at("pilot"), "novice");

  // A fresh session of the embedded scenario, driven by the recorded commands.
  auto embedded = parse_scenario(rec->metadata.at("scenario"), "embedded", error);
  ASSERT_TRUE(embedded) << error;
  embedded->duration = sc.duration;
  TraceSink replayed;
  MiMode mode;
  const SetupResult r =
      mode.setup(*embedded, std::make_unique<ReplayPilot>(rec->pilot, "replay"));
  ASSERT_TRUE(r) << r.reason();
  Session session(mode);
  session.add_sink(&replayed);
  session.run();

  ASSERT_EQ(replayed.x.size(), original.x.size());
  for (std::size_t k = 0; k < original.x.size(); ++k) {
    ASSERT_EQ(replayed.x[k], original.x[k]) << "step " << k;  // bit for bit
    ASSERT_EQ(replayed.u[k], original.u[k]) << "step " << k;
    ASSERT_EQ(replayed.lambda[k], original.lambda[k]) << "step " << k;
    ASSERT_EQ(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(rec->states[k].x.data(), 16)),
              original.x[k]);
  }
  EXPECT_EQ(to_metrics(without_timing(mode.score())), to_metrics(without_timing(original_score)));
  ASSERT_EQ(rec->channels.size(), original.x.size());
  EXPECT_EQ(rec->channels[0].names.size(), std::size_t(mode.telemetry().num_channels));
  EXPECT_EQ(rec->metadata.at("mode"), "mixed_initiative");
  std::filesystem::remove(path);
}

TEST(Session, ReplayStopsAtTheEndOfTheRecording) {
  const Scenario& sc = mi_helix();
  std::vector<PilotCommandMsg> commands(10);
  for (std::size_t k = 0; k < commands.size(); ++k) {
    commands[k].step = k;
    commands[k].rotor_speed.fill(models::MikroKopter{}.hover_speed());
  }
  MiMode mode;
  const SetupResult r = mode.setup(sc, std::make_unique<ReplayPilot>(commands, "replay"));
  ASSERT_TRUE(r) << r.reason();
  Session session(mode);
  session.run();
  EXPECT_EQ(mode.steps_done(), 10);
  EXPECT_TRUE(mode.finished());
}

TEST(Session, RejectsAPlantRateThatDoesNotDivideTheControlPeriod) {
  Scenario sc = mi_helix();
  sc.plant.rate_hz = 1234.0;
  MiMode mode;
  const SetupResult r = mode.setup(sc, make_pilot(sc, "novice"));
  EXPECT_FALSE(r);
  EXPECT_NE(r.reason().find("rate_hz"), std::string::npos) << r.reason();
  EXPECT_TRUE(mode.finished());
  EXPECT_FALSE(mode.step());
}

}  // namespace
}  // namespace mixpilot
