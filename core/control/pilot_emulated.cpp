#include "core/control/pilot_emulated.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mixpilot {

SetupResult EmulatedPilot::setup(const models::MikroKopter& model, const PilotProfile& profile,
                          const HelixReference& reference, double dt) {
  constexpr int nx = models::MikroKopter::nx, nu = models::MikroKopter::nu;
  model_ = model;
  integrator_ = IntegratorErk4<models::MikroKopter>(model);
  profile_ = profile;
  helix_ = reference;
  dt_ = dt;
  output_ = SelectionOutput(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1),
                            Eigen::VectorXi::LinSpaced(nu, 0, nu - 1));
  terminal_output_ = SelectionOutput(Eigen::VectorXi::LinSpaced(nx, 0, nx - 1), Eigen::VectorXi());
  ocp_ = Ocp{};
  ocp_.integrator = &integrator_;
  ocp_.N = profile.N;
  ocp_.dt = dt;
  ocp_.output = &output_;
  ocp_.terminal_output = &terminal_output_;
  ocp_.idxbu = Eigen::VectorXi::LinSpaced(nu, 0, nu - 1);
  ocp_.lbu = Eigen::VectorXd::Constant(nu, model.p.tau_min);
  ocp_.ubu = Eigen::VectorXd::Constant(nu, model.p.tau_max);
  ocp_.idxbx = Eigen::VectorXi::LinSpaced(4, 12, 15);
  ocp_.lbx = Eigen::VectorXd::Constant(4, model.p.omega_min);
  ocp_.ubx = Eigen::VectorXd::Constant(4, model.p.omega_max);
  if (SetupResult r = rti_.setup(ocp_); !r) return r;

  Eigen::VectorXd w(nx + nu);
  w << profile.q1, profile.q2, profile.q3, profile.q4, Eigen::Vector4d::Constant(profile.q5),
      Eigen::Vector4d::Constant(profile.r1);
  OcpStageData& data = rti_.data();
  for (int i = 0; i <= profile.N; ++i) {
    const int n = int(data.W[i].rows());
    data.W[i].diagonal() = w.head(n);
    data.yref[i].setZero();
    data.yref[i].segment<4>(12).setConstant(model.hover_speed());
  }
  const int delay_steps = int(std::lround(profile.reaction_delay / dt));
  hover_ = PilotCommand{};
  hover_.rotor_speed.setConstant(model.hover_speed());
  delay_line_.assign(delay_steps + 1, hover_);
  started_ = false;
  initial_ = rti_.state();
  return {};
}

bool EmulatedPilot::command(std::int64_t step, double t, const Eigen::VectorXd& x,
                            PilotCommand& out) {
  if (!started_) {
    const models::MikroKopter::State hover = model_.hover_state(x.head<3>());
    for (auto& xi : rti_.trajectory().x) xi = hover;
    for (auto& ui : rti_.trajectory().u) ui = model_.hover_input();
    started_ = true;
  }
  OcpStageData& data = rti_.data();
  for (int i = 0; i <= profile_.N; ++i) data.yref[i].head<3>() = helix_.position(t + i * dt_);
  rti_.prepare();
  rti_.feedback(x);
  const Eigen::VectorXd& x1 = rti_.trajectory().x[1];
  // Write this step's command into slot k mod (D+1); slot (k+1) mod (D+1) was written at step
  // k − D (or still holds the initial hover command).
  const std::int64_t n = std::int64_t(delay_line_.size());
  PilotCommand& slot = delay_line_[step % n];
  slot.roll = x1(3);
  slot.pitch = x1(4);
  slot.rotor_speed = x1.segment<4>(12);
  rti_.shift();
  out = delay_line_[(step + 1) % n];
  return true;
}

void EmulatedPilot::save(std::unique_ptr<PilotState>& state) const {
  auto* s = dynamic_cast<State*>(state.get());
  if (!s) {
    state = std::make_unique<State>();
    s = static_cast<State*>(state.get());
  }
  s->rti = rti_.state();
  s->delay_line = delay_line_;
  s->started = started_;
}

bool EmulatedPilot::restore(const PilotState* state) {
  const auto* s = dynamic_cast<const State*>(state);
  if (!s || s->delay_line.size() != delay_line_.size() || !rti_.fits(s->rti)) return false;
  rti_.restore(s->rti);
  delay_line_ = s->delay_line;
  started_ = s->started;
  return true;
}

void EmulatedPilot::take_over() {
  (void)rti_.restore(initial_);  // saved from this solver: it fits
  std::fill(delay_line_.begin(), delay_line_.end(), hover_);
  started_ = false;
}

bool RecklessPilot::command(std::int64_t, double, const Eigen::VectorXd& x, PilotCommand& out) {
  out.rotor_speed.setConstant(model_.hover_speed());
  out.roll = out.pitch = 0.0;
  const Obstacle* target = nullptr;
  double best = std::numeric_limits<double>::infinity();
  for (const Obstacle& o : arena_.obstacles) {
    const double d = (x.head<3>() - o.center).norm() - o.radius;
    if (d < best) {
      best = d;
      target = &o;
    }
  }
  if (!target) return true;
  // Thrust tilts along R e3 ≈ (θ cosψ + φ sinψ, θ sinψ − φ cosψ, 1) for small φ, θ (ZYX):
  // rotate the horizontal direction to the target into the yaw frame and tilt fully along it.
  const Eigen::Vector3d d = target->center - x.head<3>();
  const double psi = x(5);
  const double fx = std::cos(psi) * d.x() + std::sin(psi) * d.y();
  const double fy = -std::sin(psi) * d.x() + std::cos(psi) * d.y();
  const double h = std::hypot(fx, fy);
  if (h > 1e-9) {
    out.pitch = max_tilt_ * fx / h;
    out.roll = -max_tilt_ * fy / h;
  }
  // Enough thrust to hold altitude at full tilt, plus a climb/descent towards the target.
  const double lift = 1.0 / std::cos(max_tilt_) + 0.5 * std::clamp(d.z(), -1.0, 1.0);
  out.rotor_speed.setConstant(model_.hover_speed() * std::sqrt(std::max(lift, 0.2)));
  return true;
}

}  // namespace mixpilot
