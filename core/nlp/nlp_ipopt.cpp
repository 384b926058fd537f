#include "core/nlp/nlp_ipopt.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

// Hessian choice. The default adds the constraint curvature Σ λ_j ∇²c_j, obtained by central
// differences of the sensitivities A, B (and Gx, Gu) along the ≤ nx + nu variables of each stage,
// to the Gauss-Newton cost blocks (exact for SelectionOutput). That is the Lagrangian Hessian to
// O(h²), so Ipopt takes Newton steps. Measured on SPEC §5.2's smooth step (Crazyflie, N = 400,
// 6800 variables, tol 1e-10, hover guess):
//   GN + FD curvature   31 iterations, ~2 s, converged (KKT error 1e-11)
//   Gauss-Newton only   1000 iterations, not converged (constraint violation 1.5e-2)
//   limited-memory      1000 iterations, not converged (dual infeasibility 1e-3)
// Without the dynamics curvature the multipliers of the 1.4 m step make the GN model poor (the
// quaternion weights are only 1e-3), and L-BFGS with 6 pairs cannot capture a 6800-variable
// Hessian to this accuracy. Both remain selectable.

namespace mixpilot {
namespace {

using Ipopt::Index;
using Ipopt::Number;

constexpr double kInf = ipopt_defaults::kInfBound;

bool is_finite_bound(double b) { return std::abs(b) < kInf; }  // false for ±inf and NaN
// Bounds as Ipopt takes them: ±kInf (and NaN) mean "no bound".
double lower_bound(double b) { return std::isnan(b) ? -kInf : std::clamp(b, -kInf, kInf); }
double upper_bound(double b) { return std::isnan(b) ? kInf : std::clamp(b, -kInf, kInf); }

// One row of stage k ≥ 1 after the dynamics rows; every stage has the same list.
struct StageRow {
  enum class Kind { hard_g, soft_g, soft_x };
  Kind kind = Kind::hard_g;
  int item = 0;        // index into g (hard_g, soft_g) or into idxbx (soft_x)
  bool lower = true;   // soft rows: the side this row relaxes
  int soft = 0;        // soft rows: index of the soft item in the stage's slack vectors
  int slack = 0;       // soft rows: index of the slack among the stage's slack variables
  double Z = 0.0;      // soft rows: ℓ2² weight
  double z = 0.0;      // soft rows: ℓ1 weight
  double lb = -kInf;   // row bounds
  double ub = kInf;
};

class OcpTnlp final : public Ipopt::TNLP {
 public:
  OcpTnlp(const Ocp& ocp, const OcpStageData& data, const Eigen::VectorXd& x0,
          const OcpTrajectory& guess, double curvature_step, bool curvature)
      : ocp_(ocp), data_(data), x0_(x0), guess_(guess), h_rel_(curvature_step),
        curvature_(curvature) {
    N_ = ocp.N;
    nx_ = ocp.nx();
    nu_ = ocp.nu();
    ng_ = ocp.ng();
    build_rows();
    nw_ = N_ * (nu_ + nx_);
    n_ = nw_ + N_ * ns_;
    m_ = N_ * (nx_ + int(rows_.size()));
    xs_.assign(N_ + 1, Eigen::VectorXd::Zero(nx_));
    us_.assign(N_, Eigen::VectorXd::Zero(nu_));
    xs_[0] = x0_;
    F_.assign(N_, Eigen::VectorXd::Zero(nx_));
    A_.assign(N_, Eigen::MatrixXd::Zero(nx_, nx_));
    B_.assign(N_, Eigen::MatrixXd::Zero(nx_, nu_));
    r_.resize(N_ + 1);
    Jx_.resize(N_ + 1);
    Ju_.resize(N_ + 1);
    for (int i = 0; i <= N_; ++i) {
      const int ny = i < N_ ? ocp.ny() : ocp.ny_terminal();
      r_[i] = Eigen::VectorXd::Zero(ny);
      Jx_[i] = Eigen::MatrixXd::Zero(ny, nx_);
      Ju_[i] = Eigen::MatrixXd::Zero(ny, i < N_ ? nu_ : 0);
    }
    g_.assign(N_ + 1, Eigen::VectorXd::Zero(ng_));
    Gx_.assign(N_ + 1, Eigen::MatrixXd::Zero(ng_, nx_));
    Gu_.resize(N_ + 1);
    for (int k = 0; k <= N_; ++k) Gu_[k] = Eigen::MatrixXd::Zero(ng_, k < N_ ? nu_ : 0);
    fd_F_.setZero(nx_);
    fd_A_.setZero(nx_, nx_);
    fd_B_.setZero(nx_, nu_);
    fd_g_.setZero(ng_);
    fd_Gx_.setZero(ng_, nx_);
    fd_Gu_.setZero(ng_, nu_);
  }

  // Results (valid after finalize_solution).
  bool finalized() const { return finalized_; }
  const Eigen::VectorXd& w() const { return w_final_; }
  double objective() const { return objective_; }
  int nsoft() const { return int(ocp_.soft_state_bounds.size() + ocp_.soft_constraints.size()); }
  const std::vector<StageRow>& rows() const { return rows_; }
  int x_var(int k) const { return stage_offset(k); }
  int u_var(int i) const { return stage_offset(i) + (i > 0 ? nx_ : 0); }
  int slack_var(int k, int s) const { return nw_ + (k - 1) * ns_ + s; }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = n_;
    m = m_;
    nnz_jac_g = 0;
    for_each_jacobian_entry(false, [&](int, int, double) { ++nnz_jac_g; });
    nnz_h_lag = 0;
    for_each_hessian_entry(false, nullptr, [&](int, int, double) { ++nnz_h_lag; });
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l,
                       Number* g_u) override {
    std::fill(x_l, x_l + n, -kInf);
    std::fill(x_u, x_u + n, kInf);
    for (int i = 0; i < N_; ++i)
      for (int j = 0; j < ocp_.idxbu.size(); ++j) {
        x_l[u_var(i) + ocp_.idxbu(j)] = lower_bound(ocp_.lbu(j));
        x_u[u_var(i) + ocp_.idxbu(j)] = upper_bound(ocp_.ubu(j));
      }
    std::vector<bool> soft_x(ocp_.idxbx.size(), false);
    for (const auto& s : ocp_.soft_state_bounds) soft_x[s.index] = true;
    for (int k = 1; k <= N_; ++k) {
      for (int j = 0; j < ocp_.idxbx.size(); ++j) {
        if (soft_x[j]) continue;
        x_l[x_var(k) + ocp_.idxbx(j)] = lower_bound(ocp_.lbx(j));
        x_u[x_var(k) + ocp_.idxbx(j)] = upper_bound(ocp_.ubx(j));
      }
      for (int s = 0; s < ns_; ++s) x_l[slack_var(k, s)] = 0.0;
    }
    for (int k = 1; k <= N_; ++k) {
      const int row0 = dyn_row(k - 1);
      std::fill(g_l + row0, g_l + row0 + nx_, 0.0);
      std::fill(g_u + row0, g_u + row0 + nx_, 0.0);
      for (int q = 0; q < int(rows_.size()); ++q) {
        g_l[row0 + nx_ + q] = lower_bound(rows_[q].lb);
        g_u[row0 + nx_ + q] = upper_bound(rows_[q].ub);
      }
    }
    (void)m;
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number*, Number*, Index,
                          bool init_lambda, Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    Eigen::Map<Eigen::VectorXd> w(x, n);
    w.setZero();
    for (int i = 0; i < N_; ++i) w.segment(u_var(i), nu_) = guess_.u[i];
    for (int k = 1; k <= N_; ++k) w.segment(x_var(k), nx_) = guess_.x[k];
    // Slacks start at the guess's violation (Ipopt pushes them into the interior).
    load(w.data(), true);
    if (!ensure_constraints()) return false;
    for (int k = 1; k <= N_; ++k) {
      for (const auto& row : rows_) {
        if (row.kind == StageRow::Kind::hard_g) continue;
        const double v = row.kind == StageRow::Kind::soft_g ? g_[k](row.item)
                                                            : xs_[k](ocp_.idxbx(row.item));
        w(slack_var(k, row.slack)) = std::max(0.0, row.lower ? row.lb - v : v - row.ub);
      }
    }
    return true;
  }

  bool eval_f(Index, const Number* x, bool new_x, Number& obj_value) override {
    load(x, new_x);
    if (!ensure_outputs()) return false;
    double f = 0.0;
    for (int i = 0; i <= N_; ++i) f += 0.5 * r_[i].dot(data_.W[i] * r_[i]);
    for (int k = 1; k <= N_; ++k)
      for (const auto& row : rows_) {
        if (row.kind == StageRow::Kind::hard_g) continue;
        const double s = x[slack_var(k, row.slack)];
        f += 0.5 * row.Z * s * s + row.z * s;
      }
    obj_value = f;
    return std::isfinite(f);
  }

  bool eval_grad_f(Index n, const Number* x, bool new_x, Number* grad_f) override {
    load(x, new_x);
    if (!ensure_outputs()) return false;
    Eigen::Map<Eigen::VectorXd> grad(grad_f, n);
    grad.setZero();
    for (int i = 0; i <= N_; ++i) {
      const Eigen::VectorXd Wr = data_.W[i] * r_[i];  // ny
      if (i > 0) grad.segment(x_var(i), nx_) += Jx_[i].transpose() * Wr;
      if (i < N_) grad.segment(u_var(i), nu_) += Ju_[i].transpose() * Wr;
    }
    for (int k = 1; k <= N_; ++k)
      for (const auto& row : rows_) {
        if (row.kind == StageRow::Kind::hard_g) continue;
        const int v = slack_var(k, row.slack);
        grad(v) = row.Z * x[v] + row.z;
      }
    return true;
  }

  bool eval_g(Index, const Number* x, bool new_x, Index, Number* g) override {
    load(x, new_x);
    if (!ensure_dynamics() || !ensure_constraints()) return false;
    for (int k = 1; k <= N_; ++k) {
      const int row0 = dyn_row(k - 1);
      Eigen::Map<Eigen::VectorXd>(g + row0, nx_) = F_[k - 1] - xs_[k];
      for (int q = 0; q < int(rows_.size()); ++q) {
        const StageRow& row = rows_[q];
        double v = row.kind == StageRow::Kind::soft_x ? xs_[k](ocp_.idxbx(row.item))
                                                      : g_[k](row.item);
        if (row.kind != StageRow::Kind::hard_g) {
          const double s = x[slack_var(k, row.slack)];
          v += row.lower ? s : -s;
        }
        g[row0 + nx_ + q] = v;
      }
    }
    return true;
  }

  bool eval_jac_g(Index, const Number* x, bool new_x, Index, Index nele_jac, Index* iRow,
                  Index* jCol, Number* values) override {
    int e = 0;
    if (values == nullptr) {
      for_each_jacobian_entry(false, [&](int r, int c, double) {
        iRow[e] = r;
        jCol[e] = c;
        ++e;
      });
    } else {
      load(x, new_x);
      if (!ensure_dynamics() || !ensure_constraints()) return false;
      for_each_jacobian_entry(true, [&](int, int, double v) { values[e++] = v; });
    }
    return e == nele_jac;
  }

  bool eval_h(Index, const Number* x, bool new_x, Number obj_factor, Index, const Number* lambda,
              bool, Index nele_hess, Index* iRow, Index* jCol, Number* values) override {
    int e = 0;
    if (values == nullptr) {
      for_each_hessian_entry(false, nullptr, [&](int r, int c, double) {
        iRow[e] = r;
        jCol[e] = c;
        ++e;
      });
      return e == nele_hess;
    }
    load(x, new_x);
    if (!ensure_outputs()) return false;
    HessianInput in{obj_factor, lambda, true};
    for_each_hessian_entry(true, &in, [&](int, int, double v) { values[e++] = v; });
    return in.ok && e == nele_hess;
  }

  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*,
                         const Number*, Index, const Number*, const Number*, Number obj_value,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    w_final_ = Eigen::Map<const Eigen::VectorXd>(x, n);
    objective_ = obj_value;
    finalized_ = true;
  }

 private:
  int stage_offset(int k) const { return k == 0 ? 0 : nu_ + (k - 1) * (nx_ + nu_); }
  int stage_size(int k) const { return (k > 0 ? nx_ : 0) + (k < N_ ? nu_ : 0); }
  int dyn_row(int i) const { return i * (nx_ + int(rows_.size())); }

  void build_rows() {
    std::vector<int> soft_g(ng_, -1);
    const int nsbx = int(ocp_.soft_state_bounds.size());
    for (int q = 0; q < int(ocp_.soft_constraints.size()); ++q)
      soft_g[ocp_.soft_constraints[q].index] = q;
    for (int j = 0; j < ng_; ++j)
      if (soft_g[j] < 0) {
        StageRow row;
        row.kind = StageRow::Kind::hard_g;
        row.item = j;
        row.lb = ocp_.lg(j);
        row.ub = ocp_.ug(j);
        rows_.push_back(row);
      }
    ns_ = 0;
    auto add_soft = [&](StageRow::Kind kind, const SoftConstraint& s, int soft, double lb,
                        double ub) {
      StageRow row;
      row.kind = kind;
      row.item = s.index;
      row.soft = soft;
      if (is_finite_bound(lb)) {
        row.lower = true;
        row.slack = ns_++;
        row.Z = s.Zl;
        row.z = s.zl;
        row.lb = lb;
        row.ub = kInf;
        rows_.push_back(row);
      }
      if (is_finite_bound(ub)) {
        row.lower = false;
        row.slack = ns_++;
        row.Z = s.Zu;
        row.z = s.zu;
        row.lb = -kInf;
        row.ub = ub;
        rows_.push_back(row);
      }
    };
    for (int q = 0; q < nsbx; ++q) {
      const auto& s = ocp_.soft_state_bounds[q];
      add_soft(StageRow::Kind::soft_x, s, q, ocp_.lbx(s.index), ocp_.ubx(s.index));
    }
    for (int q = 0; q < int(ocp_.soft_constraints.size()); ++q) {
      const auto& s = ocp_.soft_constraints[q];
      add_soft(StageRow::Kind::soft_g, s, nsbx + q, ocp_.lg(s.index), ocp_.ug(s.index));
    }
  }

  // Copies the stage variables out of x when it changed; invalidates the evaluations.
  void load(const Number* x, bool new_x) {
    if (!new_x && loaded_) return;
    loaded_ = true;
    have_dynamics_ = have_outputs_ = have_constraints_ = false;
    for (int i = 0; i < N_; ++i) us_[i] = Eigen::Map<const Eigen::VectorXd>(x + u_var(i), nu_);
    for (int k = 1; k <= N_; ++k)
      xs_[k] = Eigen::Map<const Eigen::VectorXd>(x + x_var(k), nx_);
  }

  bool ensure_dynamics() {
    if (have_dynamics_) return true;
    for (int i = 0; i < N_; ++i)
      if (ocp_.integrator->step_sensitivities(xs_[i], us_[i], ocp_.dt, F_[i], A_[i], B_[i]) !=
          IntegratorStatus::success)
        return false;
    have_dynamics_ = true;
    return true;
  }

  bool ensure_outputs() {
    if (have_outputs_) return true;
    for (int i = 0; i <= N_; ++i) {
      const OutputFunction* out = i < N_ ? ocp_.output : ocp_.terminal_output;
      out->eval(xs_[i], i < N_ ? us_[i] : empty_, data_.p[i], r_[i], Jx_[i], Ju_[i]);
      r_[i] -= data_.yref[i];
      if (!r_[i].allFinite()) return false;
    }
    have_outputs_ = true;
    return true;
  }

  bool ensure_constraints() {
    if (have_constraints_ || ng_ == 0) return true;
    for (int k = 1; k <= N_; ++k) {
      ocp_.constraint->eval(xs_[k], k < N_ ? us_[k] : empty_, data_.p[k], g_[k], Gx_[k], Gu_[k]);
      if (!g_[k].allFinite()) return false;
    }
    have_constraints_ = true;
    return true;
  }

  // Calls f(row, col, value) for every structural nonzero of ∂c/∂w, in a fixed order.
  template <class Fn>
  void for_each_jacobian_entry(bool values, Fn&& f) const {
    for (int k = 1; k <= N_; ++k) {
      const int i = k - 1, row0 = dyn_row(i);
      // F(x_i, u_i) − x_{i+1}: [A_i B_i −I] (x_0 is fixed, so no A_0 block).
      for (int r = 0; r < nx_; ++r) {
        if (i > 0)
          for (int c = 0; c < nx_; ++c) f(row0 + r, x_var(i) + c, values ? A_[i](r, c) : 0.0);
        for (int c = 0; c < nu_; ++c) f(row0 + r, u_var(i) + c, values ? B_[i](r, c) : 0.0);
        f(row0 + r, x_var(k) + r, -1.0);
      }
      for (int q = 0; q < int(rows_.size()); ++q) {
        const StageRow& row = rows_[q];
        const int rr = row0 + nx_ + q;
        if (row.kind == StageRow::Kind::soft_x) {
          f(rr, x_var(k) + ocp_.idxbx(row.item), 1.0);
        } else {
          for (int c = 0; c < nx_; ++c) f(rr, x_var(k) + c, values ? Gx_[k](row.item, c) : 0.0);
          if (k < N_)
            for (int c = 0; c < nu_; ++c)
              f(rr, u_var(k) + c, values ? Gu_[k](row.item, c) : 0.0);
        }
        if (row.kind != StageRow::Kind::hard_g)
          f(rr, slack_var(k, row.slack), row.lower ? 1.0 : -1.0);
      }
    }
  }

  struct HessianInput {
    double obj_factor;
    const Number* lambda;
    bool ok;
  };

  // Calls f(row, col, value) for the lower triangle: a dense block per stage (its x_k, u_k),
  // then the slack diagonal.
  template <class Fn>
  void for_each_hessian_entry(bool values, HessianInput* in, Fn&& f) {
    Eigen::MatrixXd H;
    for (int k = 0; k <= N_; ++k) {
      const int off = stage_offset(k), nz = stage_size(k);
      if (values) {
        stage_hessian(k, *in, H);
        if (!H.allFinite()) in->ok = false;
      }
      for (int c = 0; c < nz; ++c)
        for (int r = c; r < nz; ++r) f(off + r, off + c, values ? H(r, c) : 0.0);
    }
    for (int k = 1; k <= N_; ++k)
      for (const auto& row : rows_)
        if (row.kind != StageRow::Kind::hard_g)
          f(slack_var(k, row.slack), slack_var(k, row.slack),
            values ? in->obj_factor * row.Z : 0.0);
  }

  // H (nz x nz) = obj_factor J_yᵀ W J_y + the curvature of the constraints of stage k, with
  // J_y = [Jx Ju] restricted to the stage's variables (u_0 only at k = 0, x_N only at k = N).
  void stage_hessian(int k, HessianInput& in, Eigen::MatrixXd& H) {
    const int nz = stage_size(k);
    Eigen::MatrixXd J(r_[k].size(), nz);  // ny x nz
    if (k == 0) {
      J = Ju_[0];
    } else if (k == N_) {
      J = Jx_[N_];
    } else {
      J << Jx_[k], Ju_[k];
    }
    H = in.obj_factor * (J.transpose() * data_.W[k] * J);
    if (!curvature_) return;
    // Multipliers: λ of the dynamics rows of interval k; μ_j = Σ λ over the rows of g_j at k.
    Eigen::VectorXd lam_dyn = Eigen::VectorXd::Zero(nx_);
    if (k < N_) lam_dyn = Eigen::Map<const Eigen::VectorXd>(in.lambda + dyn_row(k), nx_);
    Eigen::VectorXd mu = Eigen::VectorXd::Zero(ng_);
    if (k > 0)
      for (int q = 0; q < int(rows_.size()); ++q)
        if (rows_[q].kind != StageRow::Kind::soft_x)
          mu(rows_[q].item) += in.lambda[dyn_row(k - 1) + nx_ + q];
    const bool dyn = lam_dyn.any(), con = mu.any();
    if (!dyn && !con) return;
    // Central differences of ψ(z) = ∇_z (λᵀF + μᵀg) along each stage variable z_c.
    Eigen::VectorXd x = xs_[k], u = k < N_ ? us_[k] : empty_;
    Eigen::MatrixXd C(nz, nz);  // nz x nz
    Eigen::VectorXd plus(nz), minus(nz);
    for (int c = 0; c < nz; ++c) {
      const bool is_x = k > 0 && c < nx_;
      double& zc = is_x ? x(c) : u(c - (k > 0 ? nx_ : 0));
      const double z0 = zc, h = h_rel_ * std::max(1.0, std::abs(z0));
      zc = z0 + h;
      const bool ok1 = curvature_gradient(k, x, u, lam_dyn, mu, dyn, con, plus);
      zc = z0 - h;
      const bool ok2 = curvature_gradient(k, x, u, lam_dyn, mu, dyn, con, minus);
      zc = z0;
      if (!ok1 || !ok2) {
        in.ok = false;
        return;
      }
      C.col(c) = (plus - minus) / (2.0 * h);
    }
    H += 0.5 * (C + C.transpose());
  }

  // out (nz) = ∇_z (λᵀF(x, u) + μᵀg(x, u, p_k)) over the stage's variables.
  bool curvature_gradient(int k, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                          const Eigen::VectorXd& lam, const Eigen::VectorXd& mu, bool dyn,
                          bool con, Eigen::VectorXd& out) {
    out.setZero();
    const int ox = k > 0 ? nx_ : 0;  // where u starts in z
    if (dyn) {
      if (ocp_.integrator->step_sensitivities(x, u, ocp_.dt, fd_F_, fd_A_, fd_B_) !=
          IntegratorStatus::success)
        return false;
      if (k > 0) out.head(nx_) += fd_A_.transpose() * lam;
      out.segment(ox, nu_) += fd_B_.transpose() * lam;
    }
    if (con) {
      fd_Gu_.resize(ng_, k < N_ ? nu_ : 0);
      ocp_.constraint->eval(x, u, data_.p[k], fd_g_, fd_Gx_, fd_Gu_);
      out.head(nx_) += fd_Gx_.transpose() * mu;
      if (k < N_) out.segment(nx_, nu_) += fd_Gu_.transpose() * mu;
    }
    return out.allFinite();
  }

  const Ocp& ocp_;
  const OcpStageData& data_;
  const Eigen::VectorXd& x0_;
  const OcpTrajectory& guess_;
  double h_rel_;
  bool curvature_;

  int N_ = 0, nx_ = 0, nu_ = 0, ng_ = 0;
  int ns_ = 0;  // slack variables per stage
  int nw_ = 0, n_ = 0, m_ = 0;
  std::vector<StageRow> rows_;

  bool loaded_ = false;
  bool have_dynamics_ = false, have_outputs_ = false, have_constraints_ = false;
  Eigen::VectorXd empty_;
  std::vector<Eigen::VectorXd> xs_;  // N+1 x nx (xs_[0] = x̄_0)
  std::vector<Eigen::VectorXd> us_;  // N x nu
  std::vector<Eigen::VectorXd> F_;   // N x nx: F(x_i, u_i)
  std::vector<Eigen::MatrixXd> A_;   // N: nx x nx
  std::vector<Eigen::MatrixXd> B_;   // N: nx x nu
  std::vector<Eigen::VectorXd> r_;   // N+1: y_i − ỹ_i (ny; ny_N)
  std::vector<Eigen::MatrixXd> Jx_;  // N+1: ny x nx
  std::vector<Eigen::MatrixXd> Ju_;  // N+1: ny x nu (ny_N x 0 at N)
  std::vector<Eigen::VectorXd> g_;   // N+1 x ng (stage 0 unused)
  std::vector<Eigen::MatrixXd> Gx_;  // N+1: ng x nx
  std::vector<Eigen::MatrixXd> Gu_;  // N+1: ng x nu (ng x 0 at N)

  // Finite-difference scratch.
  Eigen::VectorXd fd_F_;   // nx
  Eigen::MatrixXd fd_A_;   // nx x nx
  Eigen::MatrixXd fd_B_;   // nx x nu
  Eigen::VectorXd fd_g_;   // ng
  Eigen::MatrixXd fd_Gx_;  // ng x nx
  Eigen::MatrixXd fd_Gu_;  // ng x nu (ng x 0 at N)

  bool finalized_ = false;
  Eigen::VectorXd w_final_;  // n
  double objective_ = 0.0;
};

IpoptOcpStatus map_status(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
      return IpoptOcpStatus::solved;
    case Ipopt::Solved_To_Acceptable_Level:
      return IpoptOcpStatus::acceptable;
    case Ipopt::Maximum_Iterations_Exceeded:
      return IpoptOcpStatus::max_iterations;
    case Ipopt::Infeasible_Problem_Detected:
      return IpoptOcpStatus::infeasible;
    default:
      return IpoptOcpStatus::failed;
  }
}

const char* describe(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded: return "solve succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "solved to acceptable level";
    case Ipopt::Infeasible_Problem_Detected: return "infeasible problem detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "search direction becomes too small";
    case Ipopt::Diverging_Iterates: return "diverging iterates";
    case Ipopt::User_Requested_Stop: return "user requested stop";
    case Ipopt::Feasible_Point_Found: return "feasible point found";
    case Ipopt::Maximum_Iterations_Exceeded: return "maximum iterations exceeded";
    case Ipopt::Restoration_Failed: return "restoration failed";
    case Ipopt::Error_In_Step_Computation: return "error in step computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "maximum CPU time exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "not enough degrees of freedom";
    case Ipopt::Invalid_Problem_Definition: return "invalid problem definition";
    case Ipopt::Invalid_Option: return "invalid option";
    case Ipopt::Invalid_Number_Detected: return "invalid number detected (NaN or Inf)";
    case Ipopt::Unrecoverable_Exception: return "unrecoverable exception";
    case Ipopt::NonIpopt_Exception_Thrown: return "non-Ipopt exception thrown";
    case Ipopt::Insufficient_Memory: return "insufficient memory";
    case Ipopt::Internal_Error: return "internal error";
  }
  return "unknown Ipopt status";
}

const char* check_input(const Ocp& ocp, const OcpStageData& data, const Eigen::VectorXd& x0,
                        const OcpTrajectory& guess) {
  if (const char* why = ocp.check(); why[0] != '\0') return why;
  const int N = ocp.N, nx = ocp.nx(), nu = ocp.nu();
  if (int(data.yref.size()) != N + 1 || int(data.W.size()) != N + 1 ||
      int(data.p.size()) != N + 1)
    return "stage data must have N+1 entries";
  for (int i = 0; i <= N; ++i) {
    const int ny = i < N ? ocp.ny() : ocp.ny_terminal();
    if (data.yref[i].size() != ny || data.W[i].rows() != ny || data.W[i].cols() != ny)
      return "a reference or weight has the wrong size";
    if (data.p[i].size() != ocp.np) return "a parameter vector has the wrong size";
  }
  if (x0.size() != nx || !x0.allFinite()) return "x0 has the wrong size or is not finite";
  if (int(guess.x.size()) != N + 1 || int(guess.u.size()) != N)
    return "the guess must have N+1 states and N inputs";
  for (int k = 1; k <= N; ++k)
    if (guess.x[k].size() != nx || !guess.x[k].allFinite())
      return "a guess state has the wrong size or is not finite";
  for (const auto& u : guess.u)
    if (u.size() != nu || !u.allFinite()) return "a guess input has the wrong size or is not finite";
  return "";
}

}  // namespace

const char* to_string(IpoptOcpStatus status) {
  switch (status) {
    case IpoptOcpStatus::solved: return "solved";
    case IpoptOcpStatus::acceptable: return "acceptable";
    case IpoptOcpStatus::max_iterations: return "max_iterations";
    case IpoptOcpStatus::infeasible: return "infeasible";
    case IpoptOcpStatus::failed: return "failed";
    case IpoptOcpStatus::invalid_input: return "invalid_input";
  }
  return "unknown";
}

struct IpoptOcpSolver::Impl {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app;
};

IpoptOcpSolver::IpoptOcpSolver(const Settings& settings)
    : settings_(settings), impl_(std::make_unique<Impl>()) {}

IpoptOcpSolver::~IpoptOcpSolver() = default;

IpoptOcpResult IpoptOcpSolver::solve(const Ocp& ocp, const OcpStageData& data,
                                     const Eigen::VectorXd& x0, OcpTrajectory& guess_and_result) {
  IpoptOcpResult result;
  const char* why = check_input(ocp, data, x0, guess_and_result);
  if (why[0] != '\0') {
    result.status = IpoptOcpStatus::invalid_input;
    result.message = why;
    return result;
  }
  const auto start = std::chrono::steady_clock::now();
  try {
    if (Ipopt::IsNull(impl_->app)) impl_->app = IpoptApplicationFactory();
    Ipopt::IpoptApplication& app = *impl_->app;
    Ipopt::SmartPtr<Ipopt::OptionsList> opt = app.Options();
    opt->SetIntegerValue("print_level", std::clamp(settings_.print_level, 0, 12));
    opt->SetStringValue("sb", "yes");  // no banner
    opt->SetNumericValue("tol", settings_.tolerance);
    opt->SetIntegerValue("max_iter", std::max(0, settings_.max_iterations));
    // Converge to `tol` or report failure: no early exit at Ipopt's "acceptable" level.
    opt->SetIntegerValue("acceptable_iter", 0);
    // Keep bounds exact: Ipopt's default relaxes them by 1e-8 and projects the result back,
    // which leaves a dynamics residual of ~1e-7 wherever an input bound is active.
    opt->SetNumericValue("bound_relax_factor", 0.0);
    opt->SetNumericValue("nlp_lower_bound_inf", -kInf);
    opt->SetNumericValue("nlp_upper_bound_inf", kInf);
    opt->SetStringValue("hessian_approximation",
                        settings_.hessian == IpoptHessian::limited_memory ? "limited-memory"
                                                                          : "exact");
    if (app.Initialize("") != Ipopt::Solve_Succeeded) {
      result.message = "Ipopt initialization failed";
      return result;
    }
    const bool curvature = settings_.hessian == IpoptHessian::gauss_newton_fd_curvature;
    Ipopt::SmartPtr<OcpTnlp> nlp =
        new OcpTnlp(ocp, data, x0, guess_and_result, settings_.curvature_step, curvature);
    const Ipopt::ApplicationReturnStatus s = app.OptimizeTNLP(Ipopt::GetRawPtr(nlp));
    result.ipopt_return_code = int(s);
    result.status = map_status(s);
    result.message = describe(s);
    if (Ipopt::IsValid(app.Statistics())) {
      result.iterations = app.Statistics()->IterationCount();
      double dual_inf = 0, constr_viol = 0, compl_ = 0, kkt = 0;
      app.Statistics()->Infeasibilities(dual_inf, constr_viol, compl_, kkt);
      result.dual_infeasibility = dual_inf;
      result.constraint_violation = constr_viol;
    }
    if (nlp->finalized() && nlp->w().allFinite()) {
      const int N = ocp.N, nx = ocp.nx(), nu = ocp.nu();
      const Eigen::VectorXd& w = nlp->w();
      guess_and_result.x[0] = x0;
      for (int i = 0; i < N; ++i) guess_and_result.u[i] = w.segment(nlp->u_var(i), nu);
      for (int k = 1; k <= N; ++k) guess_and_result.x[k] = w.segment(nlp->x_var(k), nx);
      result.objective = nlp->objective();
      const int ns = nlp->nsoft();
      slack_lower_.assign(N + 1, Eigen::VectorXd::Zero(ns));
      slack_upper_.assign(N + 1, Eigen::VectorXd::Zero(ns));
      for (int k = 1; k <= N; ++k)
        for (const auto& row : nlp->rows()) {
          if (row.kind == StageRow::Kind::hard_g) continue;
          (row.lower ? slack_lower_ : slack_upper_)[k](row.soft) = w(nlp->slack_var(k, row.slack));
        }
      Eigen::VectorXd xn(nx);
      double res = 0.0;
      for (int i = 0; i < N; ++i) {
        ocp.integrator->step(guess_and_result.x[i], guess_and_result.u[i], ocp.dt, xn);
        res = std::max(res, (xn - guess_and_result.x[i + 1]).lpNorm<Eigen::Infinity>());
      }
      result.dynamics_residual = res;
    } else if (result.status == IpoptOcpStatus::solved) {
      result.status = IpoptOcpStatus::failed;
      result.message = "Ipopt returned no finite solution";
    }
  } catch (const std::exception&) {
    result.status = IpoptOcpStatus::failed;
    result.message = "exception inside Ipopt";
  } catch (...) {
    result.status = IpoptOcpStatus::failed;
    result.message = "exception inside Ipopt";
  }
  result.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace mixpilot
