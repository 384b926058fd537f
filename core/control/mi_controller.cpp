#include "core/control/mi_controller.hpp"

#include <algorithm>
#include <numeric>

namespace mixpilot {

namespace {

// y = (η, ν, e, u) as a selection of x = (p, γ, v_b, ω, Ω) and u = τ.
Eigen::VectorXi output_state_index() {
  Eigen::VectorXi idx(16);
  idx << 0, 1, 2,      // η = p
      3, 4,            // ν: φ, θ
      12, 13, 14, 15,  // ν: Ω1..4
      5,               // e: ψ
      6, 7, 8,         // e: v_b
      9, 10, 11;       // e: ω
  return idx;
}

}  // namespace

SetupResult MiController::setup(const models::MikroKopter& model, const MiControllerSettings& settings,
                         const Arena& arena, const HelixReference& reference,
                         const RtiSettings& rti_settings) {
  model_ = model;
  integrator_ = IntegratorErk4<models::MikroKopter>(model);
  settings_ = settings;
  arena_ = arena;
  helix_ = reference;
  output_ = SelectionOutput(output_state_index(), Eigen::VectorXi::LinSpaced(nu, 0, nu - 1));
  terminal_output_ = SelectionOutput(output_state_index(), Eigen::VectorXi());

  const int N = settings.N;
  ocp_ = Ocp{};
  ocp_.integrator = &integrator_;
  ocp_.N = N;
  ocp_.dt = settings.dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::LinSpaced(nu, 0, nu - 1);
  ocp_.lbu = Eigen::VectorXd::Constant(nu, model.p.tau_min);
  ocp_.ubu = Eigen::VectorXd::Constant(nu, model.p.tau_max);

  const bool safety = settings.safety_constraints;
  ocp_.idxbx.resize(safety ? 7 : 4);
  ocp_.lbx.resize(ocp_.idxbx.size());
  ocp_.ubx.resize(ocp_.idxbx.size());
  ocp_.idxbx.head<4>() << 12, 13, 14, 15;
  ocp_.lbx.head<4>().setConstant(model.p.omega_min + settings.rotor_speed_backoff);
  ocp_.ubx.head<4>().setConstant(model.p.omega_max - settings.rotor_speed_backoff);
  const double rv = settings.vehicle_radius;
  const SoftConstraint soft{0, settings.slack_l2, settings.slack_l2, settings.slack_l1,
                            settings.slack_l1};
  if (safety) {
    ocp_.idxbx.tail<3>() << 0, 1, 2;
    ocp_.lbx.tail<3>() = arena.min.array() + rv;
    ocp_.ubx.tail<3>() = arena.max.array() - rv;
    for (int k = 4; k < 7; ++k) {
      ocp_.soft_state_bounds.push_back(soft);
      ocp_.soft_state_bounds.back().index = k;
    }
  }

  num_obstacles_ = safety ? std::min<int>(settings.max_constrained_obstacles,
                                          int(arena.obstacles.size()))
                          : 0;
  if (num_obstacles_ > 0) {
    obstacles_ = ObstacleConstraint(num_obstacles_, settings.obstacle_form);
    ocp_.constraint = &obstacles_;
    ocp_.np = ObstacleConstraint::kParamsPerObstacle * num_obstacles_;
    ocp_.lg = Eigen::VectorXd::Zero(num_obstacles_);
    ocp_.ug = Eigen::VectorXd::Constant(num_obstacles_, 1e20);
    for (int j = 0; j < num_obstacles_; ++j) {
      ocp_.soft_constraints.push_back(soft);
      ocp_.soft_constraints.back().index = j;
    }
  }
  if (SetupResult r = rti_.setup(ocp_, rti_settings); !r) return r;

  const MiWeights& w = settings.weights;
  weights_.resize(ny);
  weights_ << w.q_eta, Eigen::VectorXd::Constant(6, w.q_nu), w.q_e, Eigen::VectorXd::Constant(4, w.r);
  out_.control = model.hover_input();
  out_.applied = model.hover_state(Eigen::Vector3d::Zero());
  out_.predicted.setZero(3, N + 1);
  out_.reference.setZero(3, N + 1);
  nearest_.resize(int(arena.obstacles.size()));
  distance_.resize(int(arena.obstacles.size()));
  out_.lambda_next = out_.lambda_used = settings.ph.initial_lambda;
  out_.reason_next = out_.reason = ph_initial_reason(settings.ph);
  return {};
}

void MiController::reset(const Eigen::VectorXd& x) {
  const Eigen::VectorXd hover = model_.hover_state(x.head<3>());
  for (auto& xi : rti_.trajectory().x) xi = hover;
  for (auto& ui : rti_.trajectory().u) ui = model_.hover_input();
  out_.control = model_.hover_input();
  out_.lambda_next = out_.lambda_used = settings_.ph.initial_lambda;
  out_.reason_next = out_.reason = ph_initial_reason(settings_.ph);
}

void MiController::set_stage_data(double t, const PilotCommand& pilot, const Eigen::VectorXd& x) {
  const int N = settings_.N;
  const double l = out_.lambda_used;
  // e and u: weighted by 1 − λ when assisted; a probe keeps them at a fixed regularizing weight.
  const double keep = settings_.assist == Assistance::on ? 1.0 - l : settings_.probe_regularization;
  OcpStageData& data = rti_.data();
  for (int i = 0; i <= N; ++i) {
    Eigen::VectorXd& y = data.yref[i];
    y.setZero();
    y.head<3>() = helix_.position(t + i * settings_.dt);
    y(3) = pilot.roll;
    y(4) = pilot.pitch;
    y.segment<4>(5) = pilot.rotor_speed;
    auto d = data.W[i].diagonal();
    const int n = int(d.size());  // 20, or 16 at the terminal stage
    d.head<3>() = (1.0 - l) * weights_.head<3>();
    d.segment<6>(3) = l * weights_.segment<6>(3);
    d.segment(9, n - 9) = keep * weights_.segment(9, n - 9);
  }

  if (num_obstacles_ > 0) {
    // The nearest obstacles (by surface distance) to the current position, for all stages.
    const auto& obs = arena_.obstacles;
    for (int j = 0; j < int(obs.size()); ++j) {
      distance_(j) = (x.head<3>() - obs[j].center).norm() - obs[j].radius;
      nearest_(j) = j;
    }
    std::partial_sort(nearest_.data(), nearest_.data() + num_obstacles_,
                      nearest_.data() + nearest_.size(),
                      [&](int a, int b) { return distance_(a) < distance_(b); });
    for (int i = 0; i <= N; ++i) {
      for (int j = 0; j < num_obstacles_; ++j) {
        const Obstacle& o = obs[nearest_(j)];
        auto p = data.p[i].segment<ObstacleConstraint::kParamsPerObstacle>(
            ObstacleConstraint::kParamsPerObstacle * j);
        p.head<3>() = o.center;
        p(3) = o.radius + settings_.vehicle_radius;
      }
    }
  }
}

MiController::NextLambda MiController::next_lambda(double authority) const {
  // SPEC §10: λ = min(max(λ_PH, floor), ceiling, cap). The source's authority caps λ (input
  // loss hands the vehicle to the planner, SPEC §6) below any bound; a probe pins the PH
  // index's part to 1. The reason names what set λ, the PH index's own when nothing did.
  const double cap = std::clamp(authority, 0.0, 1.0);
  const AuthorityBounds& b = out_.bounds;
  const bool assisted = settings_.assist == Assistance::on;
  const double own = assisted ? out_.lambda_next : 1.0;
  const double bounded = std::min(std::max(own, b.floor), b.ceiling);
  NextLambda n;
  n.reason = out_.reason_next;
  n.lambda = std::min(bounded, cap);
  if (cap < bounded) n.reason.cap = LambdaCap::input_lost;
  else if (bounded < own) n.reason.cap = LambdaCap::instructor_ceiling;
  else if (bounded > own) n.reason.cap = LambdaCap::instructor_floor;
  else n.reason.cap = assisted ? LambdaCap::none : LambdaCap::probe;
  return n;
}

RtiStatus MiController::step(double t, const Eigen::VectorXd& x, const PilotCommand& pilot) {
  const NextLambda next = next_lambda(pilot.authority);
  out_.lambda_used = next.lambda;
  out_.reason = next.reason;
  set_stage_data(t, pilot, x);
  rti_.prepare();
  const RtiStatus status = rti_.feedback(x);
  out_.control = rti_.control();

  // The prediction and reference of this step, and from them λ for the next (SPEC §5.4).
  const OcpTrajectory& traj = rti_.trajectory();
  for (int i = 0; i <= settings_.N; ++i) {
    out_.predicted.col(i) = traj.x[i].head<3>();
    out_.reference.col(i) = rti_.data().yref[i].head<3>();
  }
  out_.reason_next = ph_reason(out_.predicted, out_.reference, settings_.dt, settings_.ph);
  out_.lambda_next = out_.reason_next.ph_index;
  out_.applied = traj.x[1];
  rti_.shift();
  return status;
}

PilotCommand MiController::applied_command() const {
  PilotCommand c;
  c.roll = out_.applied(3);
  c.pitch = out_.applied(4);
  c.rotor_speed = out_.applied.segment<4>(12);
  return c;
}

}  // namespace mixpilot
