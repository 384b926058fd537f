#include "core/qp/ocp_qp.hpp"

#include <cmath>
#include <limits>

#include "core/numerics/matrix_checks.hpp"

namespace mixpilot {

OcpQpDims::OcpQpDims(int horizon)
    : N(horizon),
      nx(horizon + 1, 0),
      nu(horizon + 1, 0),
      nbx(horizon + 1, 0),
      nbu(horizon + 1, 0),
      ng(horizon + 1, 0),
      ns(horizon + 1, 0) {}

OcpQpDims OcpQpDims::uniform(int N, int nx_, int nu_, int nbx_, int nbu_, int ng_, int ns_) {
  OcpQpDims d(N);
  for (int i = 0; i <= N; ++i) {
    d.nx[i] = nx_;
    d.nu[i] = i < N ? nu_ : 0;
    d.nbx[i] = i > 0 ? nbx_ : 0;
    d.nbu[i] = i < N ? nbu_ : 0;
    d.ng[i] = ng_;
    d.ns[i] = ns_;
  }
  return d;
}

bool OcpQpDims::valid() const {
  if (N < 0) return false;
  const std::size_t n = static_cast<std::size_t>(N) + 1;
  if (nx.size() != n || nu.size() != n || nbx.size() != n || nbu.size() != n || ng.size() != n ||
      ns.size() != n)
    return false;
  for (int i = 0; i <= N; ++i) {
    if (nx[i] < 0 || nu[i] < 0 || nbx[i] < 0 || nbu[i] < 0 || ng[i] < 0 || ns[i] < 0) return false;
    if (nbx[i] > nx[i] || nbu[i] > nu[i] || ns[i] > nc(i)) return false;
  }
  return true;
}

void OcpQp::resize(const OcpQpDims& d) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  dims = d;
  stage.assign(static_cast<std::size_t>(d.N) + 1, OcpQpStage{});
  x0 = Eigen::VectorXd::Zero(d.nx[0]);
  for (int i = 0; i <= d.N; ++i) {
    OcpQpStage& s = stage[i];
    const int nx = d.nx[i], nu = d.nu[i], nx1 = i < d.N ? d.nx[i + 1] : 0;
    s.A = Eigen::MatrixXd::Zero(nx1, nx);
    s.B = Eigen::MatrixXd::Zero(nx1, nu);
    s.b = Eigen::VectorXd::Zero(nx1);
    s.Q = Eigen::MatrixXd::Zero(nx, nx);
    s.S = Eigen::MatrixXd::Zero(nu, nx);
    s.R = Eigen::MatrixXd::Zero(nu, nu);
    s.q = Eigen::VectorXd::Zero(nx);
    s.r = Eigen::VectorXd::Zero(nu);
    s.idxbu = Eigen::VectorXi::LinSpaced(d.nbu[i], 0, d.nbu[i] - 1);
    s.lbu = Eigen::VectorXd::Constant(d.nbu[i], -inf);
    s.ubu = Eigen::VectorXd::Constant(d.nbu[i], inf);
    s.idxbx = Eigen::VectorXi::LinSpaced(d.nbx[i], 0, d.nbx[i] - 1);
    s.lbx = Eigen::VectorXd::Constant(d.nbx[i], -inf);
    s.ubx = Eigen::VectorXd::Constant(d.nbx[i], inf);
    s.C = Eigen::MatrixXd::Zero(d.ng[i], nx);
    s.D = Eigen::MatrixXd::Zero(d.ng[i], nu);
    s.lg = Eigen::VectorXd::Constant(d.ng[i], -inf);
    s.ug = Eigen::VectorXd::Constant(d.ng[i], inf);
    s.idxs = Eigen::VectorXi::LinSpaced(d.ns[i], 0, d.ns[i] - 1);
    s.Zl = Eigen::VectorXd::Zero(d.ns[i]);
    s.Zu = Eigen::VectorXd::Zero(d.ns[i]);
    s.zl = Eigen::VectorXd::Zero(d.ns[i]);
    s.zu = Eigen::VectorXd::Zero(d.ns[i]);
  }
}

double OcpQp::objective(const std::vector<Eigen::VectorXd>& x,
                        const std::vector<Eigen::VectorXd>& u,
                        const std::vector<Eigen::VectorXd>& sl,
                        const std::vector<Eigen::VectorXd>& su) const {
  double f = 0.0;
  for (int i = 0; i <= dims.N; ++i) {
    const OcpQpStage& s = stage[i];
    f += 0.5 * x[i].dot(s.Q.selfadjointView<Eigen::Lower>() * x[i]) + x[i].dot(s.q);
    f += 0.5 * u[i].dot(s.R.selfadjointView<Eigen::Lower>() * u[i]) + u[i].dot(s.r);
    f += u[i].dot(s.S * x[i]);
    f += 0.5 * sl[i].dot(s.Zl.cwiseProduct(sl[i])) + s.zl.dot(sl[i]);
    f += 0.5 * su[i].dot(s.Zu.cwiseProduct(su[i])) + s.zu.dot(su[i]);
  }
  return f;
}

const char* to_string(QpStatus status) {
  switch (status) {
    case QpStatus::success: return "success";
    case QpStatus::max_iterations: return "max_iterations";
    case QpStatus::min_step: return "min_step";
    case QpStatus::nan_detected: return "nan_detected";
    case QpStatus::factorization_failed: return "factorization_failed";
    case QpStatus::invalid_data: return "invalid_data";
  }
  return "unknown";
}

void OcpQpSolution::resize(const OcpQpDims& d) {
  const std::size_t n = static_cast<std::size_t>(d.N) + 1;
  x.resize(n);
  u.resize(n);
  pi.resize(static_cast<std::size_t>(d.N));
  lam_l.resize(n);
  lam_u.resize(n);
  sl.resize(n);
  su.resize(n);
  lam_sl.resize(n);
  lam_su.resize(n);
  for (int i = 0; i <= d.N; ++i) {
    x[i] = Eigen::VectorXd::Zero(d.nx[i]);
    u[i] = Eigen::VectorXd::Zero(d.nu[i]);
    if (i < d.N) pi[i] = Eigen::VectorXd::Zero(d.nx[i + 1]);
    lam_l[i] = Eigen::VectorXd::Zero(d.nc(i));
    lam_u[i] = Eigen::VectorXd::Zero(d.nc(i));
    sl[i] = Eigen::VectorXd::Zero(d.ns[i]);
    su[i] = Eigen::VectorXd::Zero(d.ns[i]);
    lam_sl[i] = Eigen::VectorXd::Zero(d.ns[i]);
    lam_su[i] = Eigen::VectorXd::Zero(d.ns[i]);
  }
  lam_x0 = Eigen::VectorXd::Zero(d.nx[0]);
  status = QpStatus::invalid_data;
  iterations = 0;
  objective = res_stat = res_eq = res_ineq = res_comp = 0.0;
}


namespace {
// Bounds: NaN is invalid; ±inf or |b| ≥ inf_bound means the side is absent.
bool bound_ok(const Eigen::VectorXd& b) {
  for (Eigen::Index k = 0; k < b.size(); ++k)
    if (std::isnan(b[k])) return false;
  return true;
}
}  // namespace

bool ocp_qp_indices_valid(const OcpQp& qp) {
  const OcpQpDims& d = qp.dims;
  if (qp.stage.size() != static_cast<std::size_t>(d.N) + 1) return false;
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    for (int k = 0; k < d.nbu[i]; ++k)
      if (s.idxbu[k] < 0 || s.idxbu[k] >= d.nu[i]) return false;
    for (int k = 0; k < d.nbx[i]; ++k)
      if (s.idxbx[k] < 0 || s.idxbx[k] >= d.nx[i]) return false;
    for (int j = 0; j < d.ns[i]; ++j)
      if (s.idxs[j] < 0 || s.idxs[j] >= d.nc(i)) return false;
  }
  return true;
}

bool ocp_qp_dims_equal(const OcpQpDims& a, const OcpQpDims& b) {
  return a.N == b.N && a.nx == b.nx && a.nu == b.nu && a.nbx == b.nbx && a.nbu == b.nbu &&
         a.ng == b.ng && a.ns == b.ns;
}

bool ocp_qp_valid_for(const OcpQp& qp, const OcpQpDims& dims, bool check_data) {
  return ocp_qp_dims_equal(qp.dims, dims) && ocp_qp_indices_valid(qp) &&
         (!check_data || ocp_qp_data_finite(qp));
}

QpStatus OcpQpSolution::set_invalid_data() {
  for (auto* vs : {&x, &u, &pi, &lam_l, &lam_u, &sl, &su, &lam_sl, &lam_su})
    for (auto& v : *vs) v.setZero();
  lam_x0.setZero();
  iterations = 0;
  objective = res_stat = res_eq = res_ineq = res_comp = 0.0;
  status = QpStatus::invalid_data;
  return status;
}

bool ocp_qp_data_finite(const OcpQp& qp) {
  if (!all_finite(qp.x0)) return false;
  for (int i = 0; i <= qp.dims.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    if (!(all_finite(s.A) && all_finite(s.B) && all_finite(s.b) && all_finite(s.Q) &&
          all_finite(s.S) && all_finite(s.R) && all_finite(s.q) && all_finite(s.r) &&
          all_finite(s.C) && all_finite(s.D) && all_finite(s.Zl) && all_finite(s.Zu) &&
          all_finite(s.zl) && all_finite(s.zu)))
      return false;
    if (!(bound_ok(s.lbu) && bound_ok(s.ubu) && bound_ok(s.lbx) && bound_ok(s.ubx) &&
          bound_ok(s.lg) && bound_ok(s.ug)))
      return false;
  }
  return true;
}

}  // namespace mixpilot
