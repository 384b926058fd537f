#include "core/nlp/ocp.hpp"

namespace mixpilot {

void SelectionOutput::eval(const Eigen::Ref<const Eigen::VectorXd>& x,
                           const Eigen::Ref<const Eigen::VectorXd>& u,
                           const Eigen::Ref<const Eigen::VectorXd>& /*p*/,
                           Eigen::Ref<Eigen::VectorXd> y, Eigen::Ref<Eigen::MatrixXd> Jx,
                           Eigen::Ref<Eigen::MatrixXd> Ju) const {
  const int nyx = int(state_index_.size());
  Jx.setZero();
  Ju.setZero();
  for (int k = 0; k < nyx; ++k) {
    y(k) = x(state_index_(k));
    Jx(k, state_index_(k)) = 1.0;
  }
  if (u.size() == 0) return;  // terminal stage
  for (int k = 0; k < input_index_.size(); ++k) {
    y(nyx + k) = u(input_index_(k));
    Ju(nyx + k, input_index_(k)) = 1.0;
  }
}

const char* Ocp::check() const {
  if (!integrator) return "no integrator";
  if (N < 1) return "N must be at least 1";
  if (!(dt > 0.0)) return "dt must be positive";
  if (np < 0) return "np must be non-negative";
  if (!output || !terminal_output) return "missing output or terminal output";
  const int nx = this->nx(), nu = this->nu();
  if (idxbu.size() != lbu.size() || idxbu.size() != ubu.size())
    return "idxbu, lbu, ubu differ in size";
  if (idxbx.size() != lbx.size() || idxbx.size() != ubx.size())
    return "idxbx, lbx, ubx differ in size";
  for (int k = 0; k < idxbu.size(); ++k)
    if (idxbu(k) < 0 || idxbu(k) >= nu) return "idxbu entry out of range";
  for (int k = 0; k < idxbx.size(); ++k)
    if (idxbx(k) < 0 || idxbx(k) >= nx) return "idxbx entry out of range";
  if ((lbu.array() > ubu.array()).any() || (lbx.array() > ubx.array()).any())
    return "a lower bound exceeds its upper bound";
  const int ng = this->ng();
  if (lg.size() != ng || ug.size() != ng) return "lg, ug must have ng entries";
  if ((lg.array() > ug.array()).any()) return "lg exceeds ug";
  for (const auto& s : soft_state_bounds)
    if (s.index < 0 || s.index >= idxbx.size()) return "soft state bound index out of range";
  for (const auto& s : soft_constraints)
    if (s.index < 0 || s.index >= ng) return "soft constraint index out of range";
  for (const auto* list : {&soft_state_bounds, &soft_constraints})
    for (const auto& s : *list)
      if (s.Zl < 0 || s.Zu < 0) return "negative ℓ2² slack weight";
  return "";
}

void OcpStageData::resize(const Ocp& ocp) {
  yref.assign(ocp.N + 1, Eigen::VectorXd::Zero(ocp.ny()));
  W.assign(ocp.N + 1, Eigen::MatrixXd::Zero(ocp.ny(), ocp.ny()));
  yref[ocp.N] = Eigen::VectorXd::Zero(ocp.ny_terminal());
  W[ocp.N] = Eigen::MatrixXd::Zero(ocp.ny_terminal(), ocp.ny_terminal());
  p.assign(ocp.N + 1, Eigen::VectorXd::Zero(ocp.np));
}

void OcpTrajectory::resize(const Ocp& ocp) {
  x.assign(ocp.N + 1, Eigen::VectorXd::Zero(ocp.nx()));
  u.assign(ocp.N, Eigen::VectorXd::Zero(ocp.nu()));
}

}  // namespace mixpilot
