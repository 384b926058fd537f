#pragma once
// Random OCP-QPs that are feasible by construction: a random input sequence is simulated from a
// random x0, and every hard bound and general constraint brackets that trajectory with a random
// margin (some sides absent). Linear cost terms are large compared with the margins, so many
// constraints are active at the optimum; soft constraints get slack weights small enough to be
// violated sometimes.
#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

#include "core/qp/ocp_qp.hpp"

namespace mixpilot::testing_qp {

struct RandomQpSpec {
  int N = 10;
  int nx_min = 4, nx_max = 4;  // per-stage nx drawn in [nx_min, nx_max]
  int nu = 2;
  int ng_max = 1;              // general constraints per stage in [0, ng_max]
  double soft_fraction = 0.3;  // fraction of constraints softened
  double absent_side = 0.15;   // probability that one side of a bound is absent
  double gradient_scale = 5.0;
  bool all_bounds = false;     // every input bounded and min(nx, 4) states bounded on 1..N
  bool pure_l1 = false;        // every soft constraint pure ℓ1 (Zl = Zu = 0), as in SPEC §5.3
  double l1_scale = 1.0;       // ℓ1 weights drawn in l1_scale · [0.1, 2.1]
};

inline OcpQp random_qp(const RandomQpSpec& spec, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  auto randint = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  const int N = spec.N;
  OcpQpDims d(N);
  for (int i = 0; i <= N; ++i) {
    d.nx[i] = randint(spec.nx_min, spec.nx_max);
    d.nu[i] = i < N ? spec.nu : 0;
    d.nbu[i] = spec.all_bounds ? d.nu[i] : randint(0, d.nu[i]);
    d.nbx[i] = i == 0 ? 0 : spec.all_bounds ? std::min(d.nx[i], 4) : randint(0, std::min(d.nx[i], 4));
    d.ng[i] = randint(0, spec.ng_max);
    const int nc = d.nbu[i] + d.nbx[i] + d.ng[i];
    d.ns[i] = static_cast<int>(spec.soft_fraction * nc + U01(rng) * 0.999);
    d.ns[i] = std::min(d.ns[i], nc);
  }
  OcpQp qp(d);
  std::vector<Eigen::VectorXd> xs(N + 1), us(N + 1);
  qp.x0 = Eigen::VectorXd::NullaryExpr(d.nx[0], [&] { return U(rng); });
  xs[0] = qp.x0;
  auto rand_mat = [&](int r, int c) { return Eigen::MatrixXd::NullaryExpr(r, c, [&] { return U(rng); }); };
  for (int i = 0; i <= N; ++i) {
    OcpQpStage& s = qp.stage[i];
    const int nx = d.nx[i], nu = d.nu[i], nv = nx + nu;
    // [R S; Sᵀ Q] in (u, x) order = GᵀG + 0.1 I: symmetric positive definite.
    const Eigen::MatrixXd G = rand_mat(nv, nv);
    const Eigen::MatrixXd H = G.transpose() * G + 0.1 * Eigen::MatrixXd::Identity(nv, nv);
    s.R = H.topLeftCorner(nu, nu);
    s.S = H.topRightCorner(nu, nx);
    s.Q = H.bottomRightCorner(nx, nx);
    s.r = spec.gradient_scale * Eigen::VectorXd::NullaryExpr(nu, [&] { return U(rng); });
    s.q = spec.gradient_scale * Eigen::VectorXd::NullaryExpr(nx, [&] { return U(rng); });
    us[i] = Eigen::VectorXd::NullaryExpr(nu, [&] { return 0.5 * U(rng); });
    if (i < N) {
      const int nx1 = d.nx[i + 1];
      s.A = 0.8 * Eigen::MatrixXd::Identity(nx1, nx) + rand_mat(nx1, nx) * (0.3 / std::sqrt(nx));
      s.B = rand_mat(nx1, nu);
      s.b = 0.1 * Eigen::VectorXd::NullaryExpr(nx1, [&] { return U(rng); });
      xs[i + 1] = s.A * xs[i] + s.B * us[i] + s.b;
    }
  }
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto margin = [&] { return 0.02 + 0.3 * U01(rng); };
  for (int i = 0; i <= N; ++i) {
    OcpQpStage& s = qp.stage[i];
    const int nx = d.nx[i], nu = d.nu[i];
    auto pick = [&](int n, int k) {
      std::vector<int> idx(n);
      std::iota(idx.begin(), idx.end(), 0);
      std::shuffle(idx.begin(), idx.end(), rng);
      std::vector<int> sel(idx.begin(), idx.begin() + k);
      std::sort(sel.begin(), sel.end());
      return sel;
    };
    const auto bu = pick(nu, d.nbu[i]);
    for (int k = 0; k < d.nbu[i]; ++k) {
      s.idxbu[k] = bu[k];
      s.lbu[k] = U01(rng) < spec.absent_side ? -inf : us[i][bu[k]] - margin();
      s.ubu[k] = U01(rng) < spec.absent_side ? inf : us[i][bu[k]] + margin();
    }
    const auto bx = pick(nx, d.nbx[i]);
    for (int k = 0; k < d.nbx[i]; ++k) {
      s.idxbx[k] = bx[k];
      s.lbx[k] = U01(rng) < spec.absent_side ? -inf : xs[i][bx[k]] - margin();
      s.ubx[k] = U01(rng) < spec.absent_side ? inf : xs[i][bx[k]] + margin();
    }
    if (d.ng[i] > 0) {
      s.C = rand_mat(d.ng[i], nx);
      s.D = rand_mat(d.ng[i], nu);
      const Eigen::VectorXd g = s.C * xs[i] + s.D * us[i];
      for (int k = 0; k < d.ng[i]; ++k) {
        s.lg[k] = U01(rng) < spec.absent_side ? -inf : g[k] - margin();
        s.ug[k] = U01(rng) < spec.absent_side ? inf : g[k] + margin();
      }
    }
    const auto soft = pick(d.nc(i), d.ns[i]);
    for (int j = 0; j < d.ns[i]; ++j) {
      s.idxs[j] = soft[j];
      // Pure ℓ1, pure ℓ2² and mixed penalties.
      const int kind = spec.pure_l1 ? (randint(0, 2), 0) : randint(0, 2);
      s.Zl[j] = kind == 0 ? 0.0 : 0.5 + 5.0 * U01(rng);
      s.Zu[j] = kind == 0 ? 0.0 : 0.5 + 5.0 * U01(rng);
      s.zl[j] = kind == 1 ? 0.0 : spec.l1_scale * (0.1 + 2.0 * U01(rng));
      s.zu[j] = kind == 1 ? 0.0 : spec.l1_scale * (0.1 + 2.0 * U01(rng));
    }
  }
  return qp;
}

}  // namespace mixpilot::testing_qp
