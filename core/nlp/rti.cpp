#include "core/nlp/rti.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/numerics/matrix_checks.hpp"

namespace mixpilot {

namespace {

using Clock = std::chrono::steady_clock;

double micros_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
}

// Moves v[1..] one place forward and doubles the last entry; swaps, so no allocation.
template <class T>
void shift_left(std::vector<T>& v) {
  if (v.size() < 2) return;
  std::rotate(v.begin(), v.begin() + 1, v.end());
  v.back() = v[v.size() - 2];
}

}  // namespace

const char* to_string(RtiStatus status) {
  switch (status) {
    case RtiStatus::success: return "success";
    case RtiStatus::fallback: return "fallback";
    case RtiStatus::not_prepared: return "not_prepared";
    case RtiStatus::invalid: return "invalid";
  }
  return "unknown";
}

SetupResult RtiSolver::setup(const Ocp& ocp, const Settings& settings) {
  ocp_ = nullptr;
  if (const char* problem = ocp.check(); *problem != '\0')
    return SetupResult::failure(std::string("the OCP is invalid: ") + problem);
  settings_ = settings;
  const int N = ocp.N, nx = ocp.nx(), nu = ocp.nu(), ng = ocp.ng();
  const int nbx = int(ocp.idxbx.size()), nbu = int(ocp.idxbu.size());
  const int ns = int(ocp.soft_state_bounds.size() + ocp.soft_constraints.size());

  OcpQpDims dims(N);
  for (int i = 0; i <= N; ++i) {
    dims.nx[i] = nx;
    dims.nu[i] = i < N ? nu : 0;
    dims.nbu[i] = i < N ? nbu : 0;
    dims.nbx[i] = i > 0 ? nbx : 0;  // x_0 is fixed by the embedding
    dims.ng[i] = i > 0 ? ng : 0;
    dims.ns[i] = i > 0 ? ns : 0;
  }
  if (!dims.valid()) return SetupResult::failure("the OCP gives invalid QP dimensions");
  qp_.resize(dims);
  state_.qp_solution.resize(dims);
  qp_dense_.set_method(settings.qp_solver == QpSolverKind::condensed_active_set
                           ? CondensedQpMethod::active_set
                           : CondensedQpMethod::ipm);
  qp_pairs_.set_levels(settings.qp_pair_levels);
  if (!qp_solver().setup(dims, settings.qp))
    return SetupResult::failure("the QP solver cannot be set up for these dimensions");

  // Constant parts of the QP: index lists and slack weights.
  for (int i = 0; i <= N; ++i) {
    OcpQpStage& s = qp_.stage[i];
    if (dims.nbu[i] > 0) s.idxbu = ocp.idxbu;
    if (dims.nbx[i] > 0) s.idxbx = ocp.idxbx;
    int j = 0;
    for (const auto* list : {&ocp.soft_state_bounds, &ocp.soft_constraints}) {
      const int base = dims.nbu[i] + (list == &ocp.soft_state_bounds ? 0 : dims.nbx[i]);
      for (const SoftConstraint& sc : *list) {
        if (dims.ns[i] == 0) break;
        s.idxs(j) = base + sc.index;
        s.Zl(j) = sc.Zl;
        s.Zu(j) = sc.Zu;
        s.zl(j) = sc.zl;
        s.zu(j) = sc.zu;
        ++j;
      }
    }
  }

  data_.resize(ocp);
  state_.trajectory.resize(ocp);
  const int ny_max = std::max(ocp.ny(), ocp.ny_terminal());
  ws_.x_next.setZero(nx);
  ws_.y.setZero(ny_max);
  ws_.Jx.setZero(ny_max, nx);
  ws_.Ju.setZero(ny_max, nu);
  ws_.WJ.setZero(ny_max, nx + nu);
  ws_.res.setZero(ny_max);
  ws_.g.setZero(ng);
  ws_.empty.resize(0);
  ws_.empty_Gu.resize(ng, 0);
  ws_.empty_Ju.resize(ocp.ny_terminal(), 0);
  selection_output_ = dynamic_cast<const SelectionOutput*>(ocp.output);
  selection_terminal_ = dynamic_cast<const SelectionOutput*>(ocp.terminal_output);
  // Index of each selected output in z = (x, u).
  const auto z_index = [nx](const SelectionOutput& sel) {
    const Eigen::VectorXi& ix = sel.state_index();
    const Eigen::VectorXi& iu = sel.input_index();
    Eigen::VectorXi z(ix.size() + iu.size());
    z << ix, iu.array() + nx;
    return z;
  };
  if (selection_output_) z_index_ = z_index(*selection_output_);
  if (selection_terminal_) terminal_z_index_ = z_index(*selection_terminal_);

  state_.stats = RtiStats{};
  state_.prepared = false;
  state_.have_qp_solution = false;
  ocp_ = &ocp;
  return {};
}

// Gauss-Newton blocks of stage i: H = Jᵀ W J, gradient Jᵀ W r with J = [Jx Ju], r = y − ỹ.
void RtiSolver::linearize_cost(int i) {
  const Ocp& ocp = *ocp_;
  const bool terminal = i == ocp.N;
  const int nx = ocp.nx(), nu = terminal ? 0 : ocp.nu();
  const OutputFunction& out = terminal ? *ocp.terminal_output : *ocp.output;
  const SelectionOutput* sel = terminal ? selection_terminal_ : selection_output_;
  const int ny = out.ny();
  const Eigen::MatrixXd& W = data_.W[i];
  OcpQpStage& s = qp_.stage[i];
  const OcpTrajectory& traj = state_.trajectory;
  const Eigen::VectorXd& x = traj.x[i];

  if (sel) {
    // y selects components of z = (x, u): H[z_k, z_l] += W(k, l), grad[z_k] += (W r)_k, with
    // z-indices precomputed in setup(); W is read column by column (its storage order).
    const Eigen::VectorXi& zi = terminal ? terminal_z_index_ : z_index_;
    auto r = ws_.res.head(ny);
    for (int k = 0; k < ny; ++k) {
      const int z = zi(k);
      r(k) = (z < nx ? x(z) : traj.u[i](z - nx)) - data_.yref[i](k);
    }
    s.Q.setZero();
    s.q.setZero();
    if (!terminal) {
      s.S.setZero();
      s.R.setZero();
      s.r.setZero();
    }
    // A diagonal W (the controllers' usual weights) contributes its diagonal only: one pass
    // over the entries (no branches) instead of a branch on each of the ny² entries. The same
    // additions in the same order as the general loop below; NaN or ∞ anywhere off the
    // diagonal takes the general loop.
    const bool diagonal = is_diagonal(W.data(), ny, static_cast<int>(W.rows()));
    auto wr = ws_.y.head(ny);
    if (diagonal)
      wr = W.diagonal().cwiseProduct(r);
    else
      wr.noalias() = W * r;
    for (int l = 0; diagonal && l < ny; ++l) {
      const int z = zi(l);
      const double w = W(l, l);
      if (w == 0.0) continue;
      if (z < nx) s.Q(z, z) += w;
      else s.R(z - nx, z - nx) += w;
    }
    for (int l = 0; !diagonal && l < ny; ++l) {
      const int zl = zi(l);
      const double* col = W.data() + std::ptrdiff_t(l) * W.rows();
      for (int k = 0; k < ny; ++k) {
        const double w = col[k];
        if (w == 0.0) continue;
        const int zk = zi(k);
        if (zk < nx) {
          if (zl < nx) s.Q(zk, zl) += w;
        } else if (zl < nx) {
          s.S(zk - nx, zl) += w;
        } else {
          s.R(zk - nx, zl - nx) += w;
        }
      }
    }
    for (int k = 0; k < ny; ++k) {
      const int z = zi(k);
      if (z < nx) s.q(z) += wr(k);
      else s.r(z - nx) += wr(k);
    }
    return;
  }

  // General output: dense products.
  auto y = ws_.y.head(ny);
  auto Jx = ws_.Jx.topRows(ny);
  auto Ju = ws_.Ju.topLeftCorner(ny, nu);
  if (terminal) {
    out.eval(x, ws_.empty, data_.p[i], y, Jx, ws_.empty_Ju);
  } else {
    out.eval(x, traj.u[i], data_.p[i], y, Jx, Ju);
  }
  auto r = ws_.res.head(ny);
  r = y - data_.yref[i];
  auto WJx = ws_.WJ.topLeftCorner(ny, nx);
  WJx.noalias() = W * Jx;
  s.Q.noalias() = Jx.transpose() * WJx;
  s.q.noalias() = WJx.transpose() * r;
  if (!terminal) {
    auto WJu = ws_.WJ.block(0, nx, ny, nu);
    WJu.noalias() = W * Ju;
    s.S.noalias() = WJu.transpose() * Jx;
    s.R.noalias() = Ju.transpose() * WJu;
    s.r.noalias() = WJu.transpose() * r;
  }
}

// Bounds and path constraints in the step: lb − v̄ ≤ Δv ≤ ub − v̄, lg − g ≤ Gx Δx + Gu Δu ≤ ug − g.
void RtiSolver::linearize_constraints(int i) {
  const Ocp& ocp = *ocp_;
  OcpQpStage& s = qp_.stage[i];
  const OcpQpDims& d = qp_.dims;
  const OcpTrajectory& traj = state_.trajectory;
  for (int k = 0; k < d.nbu[i]; ++k) {
    const double v = traj.u[i](ocp.idxbu(k));
    s.lbu(k) = ocp.lbu(k) - v;
    s.ubu(k) = ocp.ubu(k) - v;
  }
  for (int k = 0; k < d.nbx[i]; ++k) {
    const double v = traj.x[i](ocp.idxbx(k));
    s.lbx(k) = ocp.lbx(k) - v;
    s.ubx(k) = ocp.ubx(k) - v;
  }
  if (d.ng[i] > 0) {
    if (i == ocp.N) {
      ocp.constraint->eval(traj.x[i], ws_.empty, data_.p[i], ws_.g, s.C, ws_.empty_Gu);
    } else {
      ocp.constraint->eval(traj.x[i], traj.u[i], data_.p[i], ws_.g, s.C, s.D);
    }
    s.lg = ocp.lg - ws_.g;
    s.ug = ocp.ug - ws_.g;
  }
}

RtiStatus RtiSolver::prepare() {
  if (!ocp_) return RtiStatus::invalid;
  const Ocp& ocp = *ocp_;
  const OcpTrajectory& traj = state_.trajectory;
  const auto t0 = Clock::now();
  bool finite = true;
  for (int i = 0; i < ocp.N; ++i) {
    OcpQpStage& s = qp_.stage[i];
    const IntegratorStatus st =
        ocp.integrator->step_sensitivities(traj.x[i], traj.u[i], ocp.dt, ws_.x_next, s.A, s.B);
    finite = finite && st == IntegratorStatus::success;
    s.b = ws_.x_next - traj.x[i + 1];  // multiple-shooting gap
  }
  const auto t1 = Clock::now();
  for (int i = 0; i <= ocp.N; ++i) {
    linearize_cost(i);
    linearize_constraints(i);
  }
  // The x̄_0-free part of the QP solver's work: its layout, condensing, and with the warm start
  // the first factorization of every stage but the first.
  qp_solver().prepare(qp_, state_.qp_solution, warm_start());
  RtiStats& stats = state_.stats;
  stats.integration_us = std::chrono::duration<double, std::micro>(t1 - t0).count();
  stats.linearization_us = micros_since(t1);
  stats.linearization_finite = finite;
  state_.prepared = true;
  return RtiStatus::success;
}

RtiStatus RtiSolver::feedback(const Eigen::Ref<const Eigen::VectorXd>& x0) {
  if (!ocp_) return RtiStatus::invalid;
  if (x0.size() != ocp_->nx() || !x0.allFinite()) return RtiStatus::invalid;
  RtiState& st = state_;
  if (!st.prepared) return RtiStatus::not_prepared;
  st.prepared = false;
  auto t0 = Clock::now();
  qp_.x0 = x0 - st.trajectory.x[0];

  RtiStatus status = RtiStatus::fallback;
  RtiStats& stats = st.stats;
  stats.qp_iterations = 0;
  if (stats.linearization_finite) {
    const QpWarmStart warm = warm_start();
    if (observer_) {  // a tool's time, not the feedback phase's
      const auto o0 = Clock::now();
      observer_->on_qp(qp_, st.qp_solution, warm);
      t0 += Clock::now() - o0;
    }
    stats.qp_status = qp_solver().solve(qp_, st.qp_solution, warm);
    stats.qp_iterations = st.qp_solution.iterations;
    const double elapsed_us = stats.integration_us + stats.linearization_us + micros_since(t0);
    stats.overrun = st.force_overrun || (deadline_us_ > 0.0 && elapsed_us > deadline_us_);
    if (stats.qp_status == QpStatus::success && !stats.overrun) {
      for (int i = 0; i <= ocp_->N; ++i) st.trajectory.x[i] += st.qp_solution.x[i];
      for (int i = 0; i < ocp_->N; ++i) st.trajectory.u[i] += st.qp_solution.u[i];
      st.have_qp_solution = true;
      status = RtiStatus::success;
    }
  } else {
    stats.qp_status = QpStatus::invalid_data;
    stats.overrun = false;
  }
  st.force_overrun = false;
  if (status == RtiStatus::fallback) {
    ++stats.fallbacks;
    st.have_qp_solution = false;
  }
  stats.qp_us = micros_since(t0);
  stats.total_us = stats.integration_us + stats.linearization_us + stats.qp_us;
  stats.status = status;
  return status;
}

void RtiSolver::shift() {
  if (!ocp_) return;
  shift_left(state_.trajectory.x);
  shift_left(state_.trajectory.u);
  if (state_.have_qp_solution) {
    // Multipliers of the shifted problem for a primal-dual warm start (the last stage, whose
    // dims differ, keeps its own).
    OcpQpSolution& sol = state_.qp_solution;
    const int N = ocp_->N;
    for (int i = 0; i + 1 < N; ++i) {
      sol.pi[i].swap(sol.pi[i + 1]);
    }
    for (int i = 1; i + 1 < N; ++i) {
      sol.lam_l[i].swap(sol.lam_l[i + 1]);
      sol.lam_u[i].swap(sol.lam_u[i + 1]);
      sol.sl[i].swap(sol.sl[i + 1]);
      sol.su[i].swap(sol.su[i + 1]);
      sol.lam_sl[i].swap(sol.lam_sl[i + 1]);
      sol.lam_su[i].swap(sol.lam_su[i + 1]);
    }
  }
}

namespace {

// Same sizes, vector by vector: a copy of one into the other allocates nothing.
bool same_sizes(const std::vector<Eigen::VectorXd>& a, const std::vector<Eigen::VectorXd>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size()) return false;
  return true;
}

}  // namespace

bool RtiSolver::fits(const RtiState& state) const {
  const OcpTrajectory& t = state.trajectory;
  const OcpQpSolution& q = state.qp_solution;
  const OcpQpSolution& mine = state_.qp_solution;
  return ocp_ && same_sizes(t.x, state_.trajectory.x) && same_sizes(t.u, state_.trajectory.u) &&
         same_sizes(q.x, mine.x) && same_sizes(q.u, mine.u) && same_sizes(q.pi, mine.pi) &&
         same_sizes(q.lam_l, mine.lam_l) && same_sizes(q.lam_u, mine.lam_u) &&
         same_sizes(q.sl, mine.sl) && same_sizes(q.su, mine.su) &&
         same_sizes(q.lam_sl, mine.lam_sl) && same_sizes(q.lam_su, mine.lam_su) &&
         q.lam_x0.size() == mine.lam_x0.size();
}

bool RtiSolver::restore(const RtiState& state) {
  if (!fits(state)) return false;
  state_ = state;
  return true;
}

SqpResult RtiSolver::sqp(const Eigen::Ref<const Eigen::VectorXd>& x0, int max_iterations,
                         double tol) {
  SqpResult result;
  for (int it = 0; it < max_iterations; ++it) {
    prepare();
    const RtiStatus st = feedback(x0);
    result.iterations = it + 1;
    result.qp_status = state_.stats.qp_status;
    if (st != RtiStatus::success) return result;
    const OcpQpSolution& sol = state_.qp_solution;
    double step = 0.0;
    for (const auto& dx : sol.x) step = std::max(step, dx.lpNorm<Eigen::Infinity>());
    for (const auto& du : sol.u) step = std::max(step, du.lpNorm<Eigen::Infinity>());
    result.step_norm = step;
    if (step <= tol) {
      result.converged = true;
      return result;
    }
  }
  return result;
}

}  // namespace mixpilot
