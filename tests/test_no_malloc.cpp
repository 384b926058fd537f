// "Size once, never allocate in the control loop": hot-path calls run under a NoMalloc scope,
// which counts every malloc of the process (and, in a Debug build, aborts at an Eigen heap
// allocation).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/control/crazyflie_tracking.hpp"
#include "core/control/pendubot_reference.hpp"
#include "core/control/tracking.hpp"
#include "core/modes/debrief.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/pendubot_mode.hpp"
#include "core/modes/tracking_mode.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/nlp/rti.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"
#include "no_malloc.hpp"

namespace mixpilot {
namespace {

TEST(NoMallocGuard, CatchesAnAllocation) {
  if (!kEigenGuardArmed) GTEST_SKIP() << "Eigen's allocation guard is armed in Debug builds only";
  // The check is live in this build: an allocation under the guard aborts.
  EXPECT_DEATH(
      {
        NoMalloc guard;
        Eigen::VectorXd v(64);
        v.setOnes();
      },
      "");
}

template <class M>
void expect_erk4_allocation_free(const M& model, const Eigen::VectorXd& x,
                                 const Eigen::VectorXd& u) {
  const IntegratorErk4<M> erk4(model);
  const Integrator& integ = erk4;
  Eigen::VectorXd xn(M::nx);
  Eigen::MatrixXd A(M::nx, M::nx), B(M::nx, M::nu);
  IntegratorStatus plain{}, sensitivities{};
  long allocations = 0;
  {
    NoMalloc guard;
    plain = integ.step(x, u, 0.01, xn);
    sensitivities = integ.step_sensitivities(x, u, 0.01, xn, A, B);
    allocations = NoMalloc::count();
  }
  EXPECT_EQ(plain, IntegratorStatus::success);
  EXPECT_EQ(sensitivities, IntegratorStatus::success);
  EXPECT_EQ(allocations, 0) << "allocations (any, not only Eigen's) in the ERK4 steps";
}

TEST(NoMalloc, Erk4Pendubot) {
  expect_erk4_allocation_free(models::Pendubot{}, Eigen::Vector4d(0.1, 0.2, 0.3, 0.4),
                              Eigen::VectorXd::Constant(1, 0.1));
}
TEST(NoMalloc, Erk4Crazyflie) {
  const models::Crazyflie cf;
  expect_erk4_allocation_free(cf, cf.hover_state({0, 0, 1}), cf.hover_input());
}
TEST(NoMalloc, Erk4MikroKopter) {
  const models::MikroKopter mk;
  expect_erk4_allocation_free(mk, mk.hover_state({0, 0, 1}), mk.hover_input());
}

// Every QP solver of the RTI: the Riccati IPMs on N = 50, condensing on a short horizon (N = 10)
// where it pays.
TEST(NoMalloc, RtiPrepareFeedbackShift) {
  for (QpSolverKind kind : {QpSolverKind::riccati_ipm, QpSolverKind::riccati_ipm_pairs,
                            QpSolverKind::condensed_dense, QpSolverKind::condensed_active_set}) {
    const bool riccati =
        kind == QpSolverKind::riccati_ipm || kind == QpSolverKind::riccati_ipm_pairs;
    CrazyflieTracking problem(riccati ? 50 : 10, 0.015);
    RtiSolver rti;
    RtiSettings settings;
    settings.qp_solver = kind;
    ASSERT_TRUE(rti.setup(problem.ocp(), settings));
    problem.set_hover_target(rti.data(), {0.1, -0.1, 0.5});
    problem.hover_guess(rti.trajectory(), {0, 0, 0.4});
    Eigen::VectorXd x = problem.model().hover_state({0, 0, 0.4});
    Eigen::VectorXd u(4);
    for (int k = 0; k < 5; ++k) {
      RtiStatus prepared{}, fed{};
      long allocations = 0;
      {
        NoMalloc guard;
        prepared = rti.prepare();
        fed = rti.feedback(x);
        u = rti.control();
        rti.shift();
        allocations = NoMalloc::count();
      }
      ASSERT_EQ(prepared, RtiStatus::success);
      ASSERT_EQ(fed, RtiStatus::success);
      // Any allocation, not only Eigen's (a std::vector growing, operator new).
      ASSERT_EQ(allocations, 0) << "step " << k << ", QP solver " << int(kind);
      x(2) += 0.01;  // a new measurement
    }
    EXPECT_TRUE(u.allFinite());
  }
}

// Tracking under delay: every step() of the helix, NMPC and LQR, with the predictor over a
// 60 ms RTT split so that x(σ = t_k) lies past the step's own boundary (n_c > s).
TEST(NoMalloc, TrackingModeStep) {
  for (TrackingControllerKind kind : {TrackingControllerKind::nmpc, TrackingControllerKind::lqr}) {
    TrackingScenario sc;
    sc.name = "helix";
    sc.duration = 0.6;
    sc.reference.kind = TrackingReferenceKind::helix;
    sc.controller.kind = kind;
    sc.plant.rtt = 0.06;
    sc.plant.measurement_fraction = 0.25;
    sc.reference_trajectory =
        helix_reference(sc.reference.helix, sc.controller.dt, models::Crazyflie{});
    TrackingMode mode;
    const SetupResult r = mode.setup(sc);
    ASSERT_TRUE(r.ok()) << r.reason();
    const GuardedSteps run = step_to_end_without_malloc(mode, [] {});
    EXPECT_EQ(run.steps, mode.steps_total());
    EXPECT_EQ(run.allocations, 0);
    EXPECT_FALSE(mode.lost());
  }
}

// A probe flight (SPEC §10) takes the MI controller's other branch of the cost: every step()
// of one, flown by the novice, allocates nothing either.
TEST(NoMalloc, ProbeFlightStep) {
  ModeRequest request;
  request.duration = 0.6;
  request.pilot_name = "novice";
  request.assist = Assistance::off;
  std::string error;
  auto mode = load_mode(MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml", std::move(request), error);
  ASSERT_TRUE(mode) << error;
  ASSERT_TRUE(mode->identity().probe);
  const GuardedSteps run = step_to_end_without_malloc(*mode, [] {});
  EXPECT_EQ(run.steps, mode->steps_total());
  EXPECT_EQ(run.allocations, 0);
}

// Why λ fell (SPEC §10) is part of each mixed-initiative step: a flight whose pilot's input is
// lost for a while (λ held down by the input's cap), then back, computes its reason every step
// and copies it, with the rest of the telemetry, into a sized slot (as the recorder and the
// UI's ring do) without allocating.
TEST(NoMalloc, MiStepWithItsLambdaReason) {
  struct Dropping final : PilotSource {
    double hover = 0.0;
    std::string name() const override { return "drop"; }
    bool command(std::int64_t step, double, const Eigen::VectorXd&, PilotCommand& out) override {
      const bool lost = step >= 40 && step < 60;
      out.roll = 0.03;
      out.pitch = 0.0;
      out.rotor_speed.setConstant(hover);
      out.authority = lost ? 0.0 : 1.0;
      out.input = lost ? InputState::lost : InputState::ok;
      return true;
    }
  };
  auto source = std::make_unique<Dropping>();
  source->hover = models::MikroKopter().hover_speed();
  ModeRequest request;
  request.duration = 1.2;
  request.pilot_source = std::move(source);
  std::string error;
  auto mode = load_mode(MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml", std::move(request), error);
  ASSERT_TRUE(mode) << error;
  Telemetry slot = mode->telemetry();  // sized by a first copy
  long copy_allocations = 0;
  int capped = 0, explained = 0;
  const GuardedSteps run = step_to_end_without_malloc(*mode, [&] {
    {
      NoMalloc guard;
      slot = mode->telemetry();
      copy_allocations += NoMalloc::count();
    }
    capped += slot.reason.cap == LambdaCap::input_lost;
    explained += slot.reason.node >= 0;
  });
  EXPECT_EQ(run.steps, mode->steps_total());
  EXPECT_EQ(run.allocations, 0);
  EXPECT_EQ(copy_allocations, 0);
  EXPECT_EQ(capped, 20);
  EXPECT_EQ(explained, run.steps - 1);  // all but the first, before any prediction
}

// Pendubot swing-up: every step() of each path — NMPC tracking and past the reference's end
// (warm start re-expressed in wrapped angles), the LQR taking the arm and handing it back, exact
// state and both encoder estimators. The reference is the energy-pumping rollout (0.6 s).
TEST(NoMalloc, PendubotModeStep) {
  PendubotScenario base;
  base.name = "pendubot";
  base.reference.dt = base.controller.dt;
  pendubot_energy_guess(models::Pendubot{}, base.controller.dt, 300, base.controller.u_max,
                        base.reference.trajectory);
  struct Case {
    const char* what;
    void (*edit)(PendubotScenario&);
    bool lqr_exits;
  };
  const Case cases[] = {
      {"NMPC past the reference", [](PendubotScenario& s) { s.lqr.enabled = false; }, false},
      {"encoders, observer",
       [](PendubotScenario& s) {
         s.sensor.quantization = true;
         s.sensor.estimator = "observer";
       },
       false},
      {"encoders, differences", [](PendubotScenario& s) { s.sensor.quantization = true; }, false},
      {"LQR in and out",  // test_pendubot: LqrHandsBackToTheNmpcPastTheExitAngle
       [](PendubotScenario& s) {
         s.plant.initial_state = Eigen::Vector4d(0.05, 0.05, 0.0, 0.0);
         s.lqr.exit_angle = 0.3;
       },
       true},
  };
  for (const Case& c : cases) {
    PendubotScenario sc = base;
    sc.duration = 0.8;
    c.edit(sc);
    PendubotMode mode;
    const SetupResult r = mode.setup(sc);
    ASSERT_TRUE(r.ok()) << c.what << ": " << r.reason();
    int switches = 0;
    const GuardedSteps run = step_to_end_without_malloc(
        mode, [&] { switches += (mode.telemetry().events & kEventSwitch) != 0; });
    EXPECT_EQ(run.steps, mode.steps_total()) << c.what;
    EXPECT_EQ(run.allocations, 0) << c.what;
    if (c.lqr_exits) {
      EXPECT_GE(switches, 2) << c.what;  // the exit path ran
    }
  }
}

// The debrief's builder (SPEC §10, core/modes/debrief.hpp), as the recorder's writer thread runs
// it: after setup, adding the steps of the reckless pilot's flight of mi_helix (a takeover and
// near misses), finishing, a marker and the words of every event allocate nothing.
TEST(Debrief, TheBuilderAllocatesNothingAfterSetup) {
  ModeRequest request;
  request.pilot_name = "reckless";
  std::string error;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml",
                        std::move(request), error);
  ASSERT_TRUE(mode) << error;
  std::vector<Telemetry> steps;
  steps.reserve(std::size_t(mode->steps_total()));
  while (mode->step()) steps.push_back(mode->telemetry());
  DebriefBuilder builder(debrief_settings(*mode));
  long allocations = 0;
  char words[320];
  std::size_t said = 0;
  {
    NoMalloc guard;
    for (const Telemetry& s : steps) builder.add(s);
    builder.mark("an instructor's note");
    builder.finish();
    for (const DebriefEvent& e : builder.events())
      said += describe(e, builder.settings().ball_radius, words, sizeof words);
    allocations = NoMalloc::count();
  }
  EXPECT_EQ(allocations, 0) << "allocations in the builder or its words";
  EXPECT_GE(builder.events().size(), 3u);
  EXPECT_GT(said, 0u);
  EXPECT_TRUE(std::any_of(builder.events().begin(), builder.events().end(),
                          [](const DebriefEvent& e) { return e.kind == DebriefKind::takeover; }));
}

}  // namespace
}  // namespace mixpilot
