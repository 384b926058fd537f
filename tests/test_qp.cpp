// OCP-QP solver (core/qp_riccati_ipm): agreement with a certified dense reference on random
// feasible OCP-QPs, KKT residuals of the returned solution checked independently of the solver,
// warm starts, and clear failure statuses without NaN output (SPEC §4).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <random>

#include <sstream>
#include <string>
#include <vector>

#include "core/qp/ocp_qp_io.hpp"
#include "core/qp/qp_condensed_dense.hpp"
#include "core/qp/qp_dense_active_set.hpp"
#include "core/qp/qp_dense_ipm.hpp"
#include "core/qp/detail/qp_kernels.hpp"
#include "core/qp/qp_riccati_ipm.hpp"
#include "core/qp/qp_riccati_ipm_pairs.hpp"
#include "qp_dense_reference.hpp"
#include "qp_problems.hpp"
#include "qp_random.hpp"

namespace mixpilot {
namespace {

using testing_qp::RandomQpSpec;

// KKT residuals of (x, u, s, π, λ) for the OCP-QP, from the problem data alone
// (conventions of core/qp/ocp_qp.hpp).
struct Kkt {
  double stat = 0, dyn = 0, primal = 0, dual = 0, comp = 0, x0 = 0;
  double max() const { return std::max({stat, dyn, primal, dual, comp, x0}); }
};

Kkt kkt_residuals(const OcpQp& qp, const OcpQpSolution& s) {
  const OcpQpDims& d = qp.dims;
  Kkt k;
  auto upd = [](double& r, double v) { r = std::max(r, std::abs(v)); };
  auto present = [](double b) { return std::isfinite(b) && std::abs(b) < 1e20; };
  k.x0 = (s.x[0] - qp.x0).lpNorm<Eigen::Infinity>();
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& st = qp.stage[i];
    const int nbu = d.nbu[i], nbx = d.nbx[i], nc = d.nc(i), ns = d.ns[i];
    Eigen::VectorXd gu = st.R * s.u[i] + st.S * s.x[i] + st.r;
    Eigen::VectorXd gx = st.Q * s.x[i] + st.S.transpose() * s.u[i] + st.q;
    if (i < d.N) {
      gu += st.B.transpose() * s.pi[i];
      gx += st.A.transpose() * s.pi[i];
      const Eigen::VectorXd r = st.A * s.x[i] + st.B * s.u[i] + st.b - s.x[i + 1];
      if (r.size()) upd(k.dyn, r.lpNorm<Eigen::Infinity>());
    }
    if (i > 0) gx -= s.pi[i - 1];
    const Eigen::VectorXd dl = s.lam_u[i] - s.lam_l[i];
    for (int j = 0; j < nbu; ++j) gu[st.idxbu[j]] += dl[j];
    for (int j = 0; j < nbx; ++j) gx[st.idxbx[j]] += dl[nbu + j];
    gu += st.D.transpose() * dl.tail(d.ng[i]);
    gx += st.C.transpose() * dl.tail(d.ng[i]);
    if (i == 0) gx -= s.lam_x0;
    for (Eigen::Index j = 0; j < gu.size(); ++j) upd(k.stat, gu[j]);
    for (Eigen::Index j = 0; j < gx.size(); ++j) upd(k.stat, gx[j]);
    // Constraint values, slacks and multipliers.
    Eigen::VectorXd dv(nc), lo(nc), hi(nc), sl = Eigen::VectorXd::Zero(nc),
        su = Eigen::VectorXd::Zero(nc);
    for (int j = 0; j < nbu; ++j) {
      dv[j] = s.u[i][st.idxbu[j]];
      lo[j] = st.lbu[j];
      hi[j] = st.ubu[j];
    }
    for (int j = 0; j < nbx; ++j) {
      dv[nbu + j] = s.x[i][st.idxbx[j]];
      lo[nbu + j] = st.lbx[j];
      hi[nbu + j] = st.ubx[j];
    }
    if (d.ng[i]) {
      dv.tail(d.ng[i]) = st.C * s.x[i] + st.D * s.u[i];
      lo.tail(d.ng[i]) = st.lg;
      hi.tail(d.ng[i]) = st.ug;
    }
    for (int j = 0; j < ns; ++j) {
      const int c = st.idxs[j];
      sl[c] = s.sl[i][j];
      su[c] = s.su[i][j];
      upd(k.stat, st.Zl[j] * s.sl[i][j] + st.zl[j] - s.lam_l[i][c] - s.lam_sl[i][j]);
      upd(k.stat, st.Zu[j] * s.su[i][j] + st.zu[j] - s.lam_u[i][c] - s.lam_su[i][j]);
      k.primal = std::max({k.primal, -s.sl[i][j], -s.su[i][j]});
      upd(k.comp, s.lam_sl[i][j] * s.sl[i][j]);
      upd(k.comp, s.lam_su[i][j] * s.su[i][j]);
      k.dual = std::max({k.dual, -s.lam_sl[i][j], -s.lam_su[i][j]});
    }
    for (int j = 0; j < nc; ++j) {
      k.dual = std::max({k.dual, -s.lam_l[i][j], -s.lam_u[i][j]});
      if (present(lo[j])) {
        const double g = dv[j] - lo[j] + sl[j];
        k.primal = std::max(k.primal, -g);
        upd(k.comp, s.lam_l[i][j] * g);
      } else {
        upd(k.dual, s.lam_l[i][j]);
      }
      if (present(hi[j])) {
        const double g = hi[j] - dv[j] + su[j];
        k.primal = std::max(k.primal, -g);
        upd(k.comp, s.lam_u[i][j] * g);
      } else {
        upd(k.dual, s.lam_u[i][j]);
      }
    }
  }
  return k;
}

bool all_finite(const OcpQpSolution& s) {
  auto ok = [](const std::vector<Eigen::VectorXd>& vs) {
    for (const auto& v : vs)
      if (!v.allFinite()) return false;
    return true;
  };
  return ok(s.x) && ok(s.u) && ok(s.pi) && ok(s.lam_l) && ok(s.lam_u) && ok(s.sl) && ok(s.su) &&
         ok(s.lam_sl) && ok(s.lam_su) && s.lam_x0.allFinite() && std::isfinite(s.objective);
}

// NaN in the data and an index out of range: invalid_data, and no NaN in the output.
void expect_invalid_data_rejected(QpSolver& solver, const OcpQp& qp) {
  OcpQpSolution sol(qp.dims);
  OcpQp bad = qp;
  bad.stage[0].D(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solver.solve(bad, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
  bad = qp;
  bad.stage[0].idxbu[0] = qp.dims.nu[0];
  EXPECT_EQ(solver.solve(bad, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
}

// Inconsistent hard bounds on input 0 of `stage` (lb = 1 > ub = −1): the solve stops with
// min_step or max_iterations and a finite iterate.
void expect_inconsistent_bounds_fail_cleanly(QpSolver& solver, const OcpQp& qp, int stage) {
  OcpQp infeasible = qp;
  infeasible.stage[stage].lbu[0] = 1.0;
  infeasible.stage[stage].ubu[0] = -1.0;
  OcpQpSolution sol(qp.dims);
  const QpStatus st = solver.solve(infeasible, sol);
  EXPECT_TRUE(st == QpStatus::min_step || st == QpStatus::max_iterations) << to_string(st);
  EXPECT_EQ(sol.status, st);
  EXPECT_TRUE(all_finite(sol));
}

QpRiccatiIpmSettings tight() {
  QpRiccatiIpmSettings s;
  // An order of magnitude below the 1e-8 required of the KKT residuals.
  s.tol_stat = 1e-9;
  s.tol_eq = 1e-9;
  s.tol_ineq = 1e-9;
  s.tol_comp = 1e-11;
  return s;
}

struct Case {
  RandomQpSpec spec;
  unsigned seed;
};
void PrintTo(const Case& c, std::ostream* os) {
  *os << "N=" << c.spec.N << " nx=" << c.spec.nx_min << ".." << c.spec.nx_max << " nu=" << c.spec.nu
      << " ng<=" << c.spec.ng_max << " soft=" << c.spec.soft_fraction << " seed=" << c.seed;
}

// gtest parameter names of the random cases: N…_nx…_nu…_seed….
std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  const RandomQpSpec& s = info.param.spec;
  std::ostringstream name;
  name << "N" << s.N << "_nx" << s.nx_max << "_nu" << s.nu << "_seed" << info.param.seed;
  return name.str();
}

class RandomQp : public ::testing::TestWithParam<Case> {};

// tight() with the complementarity the primal comparison needs: on a degenerate pair (t and λ
// → 0 together) the primal error is O(√μ), and tol_comp 1e-11 left 3.5e-7 on one N = 60 case
// once the steps stopped overshooting μ. (1e-14 is too low for the pure ℓ1 cases: μ then
// collapses before stationarity converges and the factorization breaks down.)
QpRiccatiIpmSettings reference_tight() {
  QpRiccatiIpmSettings s = tight();
  s.tol_comp = 1e-13;
  return s;
}

// Solves qp at reference_tight() tolerances and checks it against the certified dense
// reference: primal solution and objective to 1e-7 (relative), independent KKT residuals to
// 1e-8; returns the solution.
template <class Solver = QpRiccatiIpm>
OcpQpSolution expect_matches_reference(const OcpQp& qp,
                                       const QpSettings& settings = reference_tight()) {
  Solver solver(qp.dims, settings);
  OcpQpSolution sol(qp.dims);
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::success)
      << "iterations " << sol.iterations << " res " << sol.res_stat << " " << sol.res_eq << " "
      << sol.res_ineq << " " << sol.res_comp;
  EXPECT_LE(sol.iterations, 40);

  const testing_qp::DenseQp D = testing_qp::densify(qp);
  const Eigen::VectorXd z = testing_qp::to_dense(D, qp.dims, sol);
  testing_qp::DenseSolution ref = testing_qp::dense_reference(qp);
  // The reference's own textbook IPM diverges on ℓ1 weights ~1e4 (its cold start has the flaw
  // fixed in the solver); its active-set certification then starts from the solver's active set,
  // which it verifies (or corrects) independently.
  if (!ref.certified) ref = testing_qp::dense_reference(qp, &z);
  EXPECT_TRUE(ref.certified) << "dense reference failed to certify its optimum";
  if (!ref.certified) return sol;

  const double zs = std::max(1.0, ref.z.lpNorm<Eigen::Infinity>());
  EXPECT_LE((z - ref.z).lpNorm<Eigen::Infinity>() / zs, 1e-7);
  EXPECT_LE(std::abs(sol.objective - ref.objective) / std::max(1.0, std::abs(ref.objective)), 1e-7);
  EXPECT_NEAR(sol.objective, qp.objective(sol.x, sol.u, sol.sl, sol.su),
              1e-10 * std::max(1.0, std::abs(sol.objective)));

  const Kkt k = kkt_residuals(qp, sol);
  EXPECT_LE(k.stat, 1e-8);
  EXPECT_LE(k.dyn, 1e-8);
  EXPECT_LE(k.primal, 1e-8);
  EXPECT_LE(k.dual, 1e-8);
  EXPECT_LE(k.comp, 1e-8);
  EXPECT_EQ(k.x0, 0.0);
  return sol;
}

TEST_P(RandomQp, MatchesCertifiedDenseReference) {
  const Case& c = GetParam();
  const OcpQp qp = testing_qp::random_qp(c.spec, c.seed);
  const OcpQpSolution sol = expect_matches_reference(qp);
  // The test exercises what it claims: some constraints are active at the optimum.
  int active = 0;
  for (int i = 0; i <= qp.dims.N; ++i)
    active += (sol.lam_l[i].array() > 1e-6).count() + (sol.lam_u[i].array() > 1e-6).count();
  EXPECT_GT(active, 0);
}

RandomQpSpec spec(int N, int nx_min, int nx_max, int nu, int ng_max, double soft,
                  bool all_bounds = false) {
  RandomQpSpec s;
  s.all_bounds = all_bounds;
  s.N = N;
  s.nx_min = nx_min;
  s.nx_max = nx_max;
  s.nu = nu;
  s.ng_max = ng_max;
  s.soft_fraction = soft;
  return s;
}

const Case kRandomCases[] = {
    Case{spec(1, 2, 2, 1, 1, 0.5), 1},    Case{spec(1, 16, 16, 4, 2, 0.3, true), 2},
    Case{spec(2, 3, 3, 2, 0, 0.0), 3},    Case{spec(5, 4, 4, 1, 1, 0.4), 4},
    Case{spec(10, 6, 6, 3, 2, 0.3), 5},   Case{spec(10, 2, 8, 2, 1, 0.3), 6},
    Case{spec(20, 16, 16, 4, 1, 0.2), 7}, Case{spec(30, 4, 4, 2, 1, 0.3), 8},
    Case{spec(40, 8, 8, 3, 2, 0.3), 9},   Case{spec(60, 3, 5, 1, 1, 0.3), 10},
    Case{spec(60, 6, 6, 2, 0, 0.5), 11},  Case{spec(15, 12, 16, 4, 2, 0.5), 12},
    Case{spec(25, 5, 5, 4, 3, 1.0), 13},  Case{spec(60, 4, 4, 2, 1, 0.0), 14}};

INSTANTIATE_TEST_SUITE_P(Sizes, RandomQp, ::testing::ValuesIn(kRandomCases), case_name);

// The same cases through partial condensing (core/qp_riccati_ipm_pairs): odd and even N, N = 1
// and 2 (nothing or one pair to condense), stage-varying nx, soft and general constraints on the
// eliminated stages; the expanded solution, multipliers included, is checked as above.
// Pairs condensed `Levels` times (blocks of 2^Levels stages).
template <int Levels>
struct PairsSolver : QpRiccatiIpmPairs {
  PairsSolver(const OcpQpDims& dims, const QpSettings& settings)
      : QpRiccatiIpmPairs(dims, settings, Levels) {}
};

class PairsRandomQp : public ::testing::TestWithParam<Case> {};

TEST_P(PairsRandomQp, MatchesCertifiedDenseReference) {
  const Case& c = GetParam();
  const OcpQp qp = testing_qp::random_qp(c.spec, c.seed);
  expect_matches_reference<PairsSolver<1>>(qp);
  expect_matches_reference<PairsSolver<2>>(qp);
  expect_matches_reference<PairsSolver<3>>(qp);
}

INSTANTIATE_TEST_SUITE_P(Sizes, PairsRandomQp, ::testing::ValuesIn(kRandomCases), case_name);

// Pure ℓ1 soft constraints (Zl = Zu = 0: the exact penalty of SPEC §5.3), half the bound sides
// absent: a soft side without a bound has a slack decoupled from everything (cost z·s, s ≥ 0
// only). Weights ~1 leave some slacks positive; weights ~1e4 (SPEC §5.3's 1.45e4) are the
// exact-penalty regime in which the RTI obstacle QP failed with min_step on its first iteration.
struct L1Case {
  int N, nx, nu, ng;
  double l1_scale;
  unsigned seed;
};
void PrintTo(const L1Case& c, std::ostream* os) {
  *os << "N=" << c.N << " nx=" << c.nx << " nu=" << c.nu << " ng=" << c.ng
      << " l1_scale=" << c.l1_scale << " seed=" << c.seed;
}
class PureL1SoftQp : public ::testing::TestWithParam<L1Case> {};

TEST_P(PureL1SoftQp, MatchesCertifiedDenseReference) {
  const L1Case& c = GetParam();
  RandomQpSpec s = spec(c.N, c.nx, c.nx, c.nu, c.ng, 1.0);
  s.pure_l1 = true;
  s.l1_scale = c.l1_scale;
  s.absent_side = 0.5;
  const OcpQp qp = testing_qp::random_qp(s, c.seed);
  // The problem is what the test claims: pure ℓ1 soft constraints, some of them one-sided.
  int soft = 0, one_sided = 0;
  for (int i = 0; i <= qp.dims.N; ++i) {
    const OcpQpStage& st = qp.stage[i];
    const int nbu = qp.dims.nbu[i], nbx = qp.dims.nbx[i];
    for (int j = 0; j < qp.dims.ns[i]; ++j) {
      ASSERT_EQ(st.Zl[j], 0.0);
      ASSERT_EQ(st.Zu[j], 0.0);
      const int k = st.idxs[j];
      const double lo = k < nbu ? st.lbu[k] : k < nbu + nbx ? st.lbx[k - nbu] : st.lg[k - nbu - nbx];
      const double hi = k < nbu ? st.ubu[k] : k < nbu + nbx ? st.ubx[k - nbu] : st.ug[k - nbu - nbx];
      ++soft;
      one_sided += std::isinf(lo) != std::isinf(hi);
    }
  }
  ASSERT_GT(soft, 0);
  ASSERT_GT(one_sided, 0);
  const OcpQpSolution sol = expect_matches_reference(qp);
  if (c.l1_scale <= 1.0) {  // small weights: some slacks in use
    double smax = 0;
    for (int i = 0; i <= qp.dims.N; ++i)
      smax = std::max({smax, sol.sl[i].size() ? sol.sl[i].maxCoeff() : 0.0,
                       sol.su[i].size() ? sol.su[i].maxCoeff() : 0.0});
    EXPECT_GT(smax, 1e-3);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, PureL1SoftQp,
    ::testing::Values(L1Case{10, 4, 2, 2, 1.0, 71}, L1Case{10, 4, 2, 2, 1.45e4, 72},
                      L1Case{30, 6, 2, 2, 1.0, 73}, L1Case{30, 6, 2, 2, 1.45e4, 74},
                      L1Case{50, 12, 4, 1, 1.45e4, 75}, L1Case{5, 3, 1, 3, 10.0, 76}),
    [](const ::testing::TestParamInfo<L1Case>& info) {
      const L1Case& c = info.param;
      std::ostringstream name;
      name << "N" << c.N << "_nx" << c.nx << "_z" << (c.l1_scale > 100 ? "large" : "small")
           << "_seed" << c.seed;
      return name.str();
    });

TEST(QpRiccatiIpm, UnconstrainedIsOneNewtonStep) {
  RandomQpSpec s = spec(8, 5, 5, 2, 0, 0.0);
  OcpQp qp = testing_qp::random_qp(s, 21);
  OcpQpDims d = qp.dims;
  std::fill(d.nbx.begin(), d.nbx.end(), 0);
  std::fill(d.nbu.begin(), d.nbu.end(), 0);
  std::fill(d.ns.begin(), d.ns.end(), 0);
  OcpQp un(d);
  un.x0 = qp.x0;
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& a = qp.stage[i];
    OcpQpStage& b = un.stage[i];
    b.A = a.A, b.B = a.B, b.b = a.b, b.Q = a.Q, b.S = a.S, b.R = a.R, b.q = a.q, b.r = a.r;
  }
  const testing_qp::DenseSolution ref = testing_qp::dense_reference(un);
  ASSERT_TRUE(ref.certified);
  QpRiccatiIpm solver(d, tight());
  OcpQpSolution sol(d);
  ASSERT_EQ(solver.solve(un, sol), QpStatus::success);
  EXPECT_EQ(sol.iterations, 1);
  const Eigen::VectorXd z = testing_qp::to_dense(testing_qp::densify(un), d, sol);
  EXPECT_LE((z - ref.z).lpNorm<Eigen::Infinity>(), 1e-9 * std::max(1.0, ref.z.lpNorm<Eigen::Infinity>()));
  EXPECT_LE(kkt_residuals(un, sol).max(), 1e-9);
}

TEST(QpRiccatiIpm, WarmStartReproducesColdSolutionInFewerIterations) {
  const OcpQp qp = testing_qp::random_qp(spec(30, 6, 6, 2, 1, 0.3), 31);
  QpRiccatiIpm solver(qp.dims, tight());
  OcpQpSolution cold(qp.dims);
  ASSERT_EQ(solver.solve(qp, cold), QpStatus::success);
  // Re-solve a slightly perturbed problem (new x0, as in the RTI feedback phase).
  OcpQp qp2 = qp;
  qp2.x0 += 1e-3 * Eigen::VectorXd::Ones(qp.x0.size());
  OcpQpSolution c2(qp.dims);
  ASSERT_EQ(solver.solve(qp2, c2), QpStatus::success);
  for (QpWarmStart mode : {QpWarmStart::primal, QpWarmStart::primal_dual}) {
    OcpQpSolution w = cold;
    ASSERT_EQ(solver.solve(qp2, w, mode), QpStatus::success);
    double dx = 0;
    for (int i = 0; i <= qp.dims.N; ++i) dx = std::max(dx, (w.x[i] - c2.x[i]).lpNorm<Eigen::Infinity>());
    EXPECT_LE(dx, 1e-7);
    if (mode == QpWarmStart::primal_dual) {
      EXPECT_LT(w.iterations, c2.iterations);
    }
  }
}

TEST(QpRiccatiIpm, DimsMayDifferPerStage) {
  // Stage-varying nx (as in a multi-phase problem), nu_N = 0, bounds only on 1..N.
  const OcpQp qp = testing_qp::random_qp(spec(12, 2, 7, 3, 1, 0.3), 41);
  bool varies = false;
  for (int i = 1; i <= qp.dims.N; ++i) varies |= qp.dims.nx[i] != qp.dims.nx[0];
  ASSERT_TRUE(varies);
  const testing_qp::DenseSolution ref = testing_qp::dense_reference(qp);
  ASSERT_TRUE(ref.certified);
  QpRiccatiIpm solver(qp.dims, tight());
  OcpQpSolution sol(qp.dims);
  ASSERT_EQ(solver.solve(qp, sol), QpStatus::success);
  const Eigen::VectorXd z = testing_qp::to_dense(testing_qp::densify(qp), qp.dims, sol);
  EXPECT_LE((z - ref.z).lpNorm<Eigen::Infinity>() / std::max(1.0, ref.z.lpNorm<Eigen::Infinity>()), 1e-7);
}

// The controllers' QPs used by mixpilot-bench (tests/qp_problems.hpp): solved at tight
// tolerances, certified against the dense KKT system, with active constraints.
class ControllerQp : public ::testing::TestWithParam<int> {};

TEST_P(ControllerQp, MatchesCertifiedDenseReference) {
  const OcpQp qp = GetParam() == 0   ? testing_qp::mixed_initiative_qp()
                   : GetParam() == 1 ? testing_qp::crazyflie_qp()
                                     : testing_qp::pendubot_qp();
  QpRiccatiIpm solver(qp.dims, tight());
  OcpQpSolution sol(qp.dims);
  ASSERT_EQ(solver.solve(qp, sol), QpStatus::success);
  const Kkt k = kkt_residuals(qp, sol);
  EXPECT_LE(k.max(), 1e-8);
  const testing_qp::DenseQp D = testing_qp::densify(qp);
  const Eigen::VectorXd z = testing_qp::to_dense(D, qp.dims, sol);
  const testing_qp::DenseSolution ref = testing_qp::dense_reference(qp, &z);
  ASSERT_TRUE(ref.certified);
  EXPECT_LE((z - ref.z).lpNorm<Eigen::Infinity>() / std::max(1.0, ref.z.lpNorm<Eigen::Infinity>()), 1e-7);
  EXPECT_LE(std::abs(sol.objective - ref.objective) / std::max(1.0, std::abs(ref.objective)), 1e-7);
  int active = 0;
  for (int i = 0; i <= qp.dims.N; ++i)
    active += (sol.lam_l[i].array() > 1e-6).count() + (sol.lam_u[i].array() > 1e-6).count();
  EXPECT_GT(active, 0);
  // At the benchmark tolerances too (what mixpilot-bench measures).
  QpRiccatiIpmSettings bench;
  bench.tol_comp = 1e-8;
  bench.tol_stat = 1e-6;
  QpRiccatiIpm fast(qp.dims, bench);
  OcpQpSolution s2(qp.dims);
  ASSERT_EQ(fast.solve(qp, s2), QpStatus::success);
  EXPECT_LE(std::abs(s2.objective - ref.objective) / std::max(1.0, std::abs(ref.objective)), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Bench, ControllerQp, ::testing::Values(0, 1, 2),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return std::string(info.param == 0   ? "mi"
                                              : info.param == 1 ? "crazyflie"
                                                                : "pendubot");
                         });

TEST(QpDump, RoundTripIsExact) {
  const OcpQp qp = testing_qp::random_qp(spec(7, 3, 6, 2, 2, 0.5), 61);
  QpRiccatiIpmSettings st = tight();
  st.max_iterations = 33;
  std::stringstream ss;
  write_ocp_qp_json(ss, qp, st, "roundtrip");
  std::string line;
  std::getline(ss, line);
  OcpQp back;
  QpRiccatiIpmSettings st2;
  std::string name, err;
  ASSERT_TRUE(read_ocp_qp_json(line, back, st2, name, err)) << err;
  EXPECT_EQ(name, "roundtrip");
  EXPECT_EQ(st2.max_iterations, 33);
  EXPECT_EQ(st2.tol_comp, st.tol_comp);
  ASSERT_EQ(back.dims.nx, qp.dims.nx);
  ASSERT_EQ(back.dims.ns, qp.dims.ns);
  EXPECT_EQ(back.x0, qp.x0);
  for (int i = 0; i <= qp.dims.N; ++i) {
    const OcpQpStage &a = qp.stage[i], &b = back.stage[i];
    EXPECT_TRUE(a.A == b.A && a.B == b.B && a.b == b.b && a.Q == b.Q && a.S == b.S && a.R == b.R &&
                a.q == b.q && a.r == b.r && a.C == b.C && a.D == b.D)
        << i;
    EXPECT_TRUE(a.idxbu == b.idxbu && a.idxbx == b.idxbx && a.idxs == b.idxs) << i;
    EXPECT_TRUE(a.lbu == b.lbu && a.ubu == b.ubu && a.lbx == b.lbx && a.ubx == b.ubx &&
                a.lg == b.lg && a.ug == b.ug)
        << i;  // ±inf survive as ±1e30 → ±inf
    EXPECT_TRUE(a.Zl == b.Zl && a.Zu == b.Zu && a.zl == b.zl && a.zu == b.zu) << i;
  }
  QpRiccatiIpm s1(qp.dims, st), s2(back.dims, st2);
  OcpQpSolution r1(qp.dims), r2(back.dims);
  ASSERT_EQ(s1.solve(qp, r1), QpStatus::success);
  ASSERT_EQ(s2.solve(back, r2), QpStatus::success);
  EXPECT_EQ(r1.iterations, r2.iterations);
  EXPECT_EQ(r1.objective, r2.objective);

  EXPECT_FALSE(read_ocp_qp_json("{\"format\":\"other\"}", back, st2, name, err));
  EXPECT_FALSE(read_ocp_qp_json(line.substr(0, line.size() / 2), back, st2, name, err));
  EXPECT_FALSE(err.empty());

  // A closed-loop record: the warm start goes with the QP, and the warm solve from the read
  // record repeats the original one exactly.
  std::stringstream ws;
  write_ocp_qp_json(ws, qp, st, "warm", &r1, QpWarmStart::primal_dual);
  std::getline(ws, line);
  OcpQpSolution start;
  QpWarmStart warm = QpWarmStart::cold;
  ASSERT_TRUE(read_ocp_qp_json(line, back, st2, name, err, &start, &warm)) << err;
  EXPECT_EQ(warm, QpWarmStart::primal_dual);
  for (int i = 0; i <= qp.dims.N; ++i) {
    EXPECT_TRUE(start.x[i] == r1.x[i] && start.u[i] == r1.u[i] && start.lam_l[i] == r1.lam_l[i] &&
                start.lam_u[i] == r1.lam_u[i] && start.sl[i] == r1.sl[i] &&
                start.su[i] == r1.su[i] && start.lam_sl[i] == r1.lam_sl[i] &&
                start.lam_su[i] == r1.lam_su[i])
        << i;
    if (i < qp.dims.N) {
      EXPECT_TRUE(start.pi[i] == r1.pi[i]) << i;
    }
  }
  OcpQpSolution w1 = r1, w2 = start;
  ASSERT_EQ(s1.solve(qp, w1, QpWarmStart::primal_dual), QpStatus::success);
  ASSERT_EQ(s2.solve(back, w2, QpWarmStart::primal_dual), QpStatus::success);
  EXPECT_EQ(w1.iterations, w2.iterations);
  EXPECT_EQ(w1.objective, w2.objective);
  // Without a start member a warm record is refused; a cold record reads as cold.
  const std::string no_start = line.substr(0, line.find(",\"start\"")) +
                               line.substr(line.find(",\"x0\""));
  EXPECT_FALSE(read_ocp_qp_json(no_start, back, st2, name, err, &start, &warm));
  EXPECT_NE(err.find("start"), std::string::npos) << err;
  std::stringstream cs;
  write_ocp_qp_json(cs, qp, st, "cold", &r1, QpWarmStart::cold);
  std::getline(cs, line);
  ASSERT_TRUE(read_ocp_qp_json(line, back, st2, name, err, &start, &warm)) << err;
  EXPECT_EQ(warm, QpWarmStart::cold);
}

// --- Condensing + dense IPM (core/qp_condensed_dense): the same contract on short horizons. ---

// The condensed QP's stationarity is measured in U-space; the states x = ΓU + ξ carry its error
// amplified by ‖Γ‖ (up to ~N for these A ≈ 0.8 I), so for the same 1e-7 on the primal solution
// the dense variant needs stationarity one order tighter.
QpSettings dense_tight() {
  QpSettings s = tight();
  s.tol_stat = 1e-10;
  return s;
}

class DenseRandomQp : public ::testing::TestWithParam<Case> {};

TEST_P(DenseRandomQp, MatchesCertifiedDenseReference) {
  const Case& c = GetParam();
  RandomQpSpec s = c.spec;
  if (c.seed % 2 == 0) {  // every other case pure ℓ1 with SPEC §5.3-sized weights, one-sided
    s.pure_l1 = true;
    s.l1_scale = 1.45e4;
    s.absent_side = 0.5;
  }
  const OcpQp qp = testing_qp::random_qp(s, c.seed);
  const OcpQpSolution sol = expect_matches_reference<QpCondensedDense>(qp, dense_tight());
  // Multipliers are complete (π and λ_x0 from the backward pass; the KKT check above uses
  // them) and agree with the Riccati IPM's.
  QpRiccatiIpm riccati(qp.dims, tight());
  OcpQpSolution r(qp.dims);
  ASSERT_EQ(riccati.solve(qp, r), QpStatus::success);
  double dpi = 0, dlam = 0, scale = 1;
  for (int i = 0; i <= qp.dims.N; ++i) {
    if (i < qp.dims.N) dpi = std::max(dpi, (sol.pi[i] - r.pi[i]).lpNorm<Eigen::Infinity>());
    dlam = std::max({dlam, (sol.lam_l[i] - r.lam_l[i]).lpNorm<Eigen::Infinity>(),
                     (sol.lam_u[i] - r.lam_u[i]).lpNorm<Eigen::Infinity>()});
    scale = std::max({scale, r.lam_l[i].lpNorm<Eigen::Infinity>(),
                      r.lam_u[i].lpNorm<Eigen::Infinity>()});
  }
  // Multipliers of a QP with a unique (LICQ) solution are unique; 1e-6 relative leaves room for
  // the 1e-11 complementarity tolerance over weakly active constraints.
  EXPECT_LE(dpi / scale, 1e-6);
  EXPECT_LE(dlam / scale, 1e-6);
  EXPECT_LE((sol.lam_x0 - r.lam_x0).lpNorm<Eigen::Infinity>() / scale, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, DenseRandomQp,
    ::testing::Values(Case{spec(1, 2, 2, 1, 1, 0.5), 101}, Case{spec(3, 3, 3, 2, 2, 0.5), 102},
                      Case{spec(5, 4, 4, 1, 1, 0.4), 103}, Case{spec(10, 4, 4, 1, 2, 0.5), 104},
                      Case{spec(10, 6, 6, 2, 2, 0.3, true), 105}, Case{spec(12, 2, 6, 2, 1, 0.3), 106},
                      Case{spec(20, 6, 6, 2, 1, 0.3), 109}, Case{spec(20, 5, 5, 1, 2, 1.0), 108}),
    case_name);

TEST(QpCondensedDense, PendubotQpAndPrepareSplit) {
  // The Pendubot QP (SPEC §5.1): the result equals the Riccati IPM's, and prepare() (before x0 is
  // known) + solve() with a new x0 equals a plain solve() of that QP.
  OcpQp qp = testing_qp::pendubot_qp();
  const OcpQpSolution sol = expect_matches_reference<QpCondensedDense>(qp, dense_tight());
  QpCondensedDense dense(qp.dims, tight());
  OcpQp qp2 = qp;
  qp2.x0 += 0.05 * Eigen::VectorXd::Ones(qp.x0.size());
  OcpQpSolution a(qp.dims), b(qp.dims);
  dense.prepare(qp);  // x0 of qp, not qp2: prepare must not depend on it
  ASSERT_EQ(dense.solve(qp2, a), QpStatus::success);
  ASSERT_EQ(dense.solve(qp2, b), QpStatus::success);
  double dx = 0;
  for (int i = 0; i <= qp.dims.N; ++i) dx = std::max(dx, (a.x[i] - b.x[i]).lpNorm<Eigen::Infinity>());
  EXPECT_LE(dx, 1e-12);
  EXPECT_GT((a.x[1] - sol.x[1]).lpNorm<Eigen::Infinity>(), 1e-3);  // x0 did change the solution
}

TEST(QpCondensedDense, WarmStartReproducesColdSolutionInFewerIterations) {
  const OcpQp qp = testing_qp::random_qp(spec(10, 4, 4, 2, 1, 0.3), 131);
  QpCondensedDense solver(qp.dims, tight());
  OcpQpSolution cold(qp.dims);
  ASSERT_EQ(solver.solve(qp, cold), QpStatus::success);
  OcpQp qp2 = qp;
  qp2.x0 += 1e-3 * Eigen::VectorXd::Ones(qp.x0.size());
  OcpQpSolution c2(qp.dims);
  ASSERT_EQ(solver.solve(qp2, c2), QpStatus::success);
  OcpQpSolution w = cold;
  ASSERT_EQ(solver.solve(qp2, w, QpWarmStart::primal_dual), QpStatus::success);
  double dx = 0;
  for (int i = 0; i <= qp.dims.N; ++i) dx = std::max(dx, (w.x[i] - c2.x[i]).lpNorm<Eigen::Infinity>());
  EXPECT_LE(dx, 1e-7);
  EXPECT_LT(w.iterations, c2.iterations);
}

TEST(QpCondensedDense, FailureStatusesWithoutNan) {
  OcpQpDims d = OcpQpDims::uniform(5, 3, 2, 1, 2);
  OcpQp qp(d);
  qp.x0.setOnes();
  for (int i = 0; i <= 5; ++i) {
    qp.stage[i].Q = Eigen::MatrixXd::Identity(3, 3);
    if (i < 5) {
      qp.stage[i].R = -Eigen::MatrixXd::Identity(2, 2);  // indefinite on the inputs
      qp.stage[i].r.setOnes();  // u = 0 is not stationary
      qp.stage[i].A = Eigen::MatrixXd::Identity(3, 3);
      qp.stage[i].B = Eigen::MatrixXd::Zero(3, 2);
    }
  }
  QpCondensedDense solver(d);
  OcpQpSolution sol(d);
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::factorization_failed);
  EXPECT_TRUE(all_finite(sol));
  OcpQp bad = qp;
  bad.stage[0].Q(0, 0) = std::numeric_limits<double>::quiet_NaN();  // reaches only f and λ_x0
  EXPECT_EQ(solver.solve(bad, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
  bad = qp;
  bad.stage[2].idxbu[0] = 9;
  EXPECT_EQ(solver.solve(bad, sol), QpStatus::invalid_data);
  QpCondensedDense other(OcpQpDims::uniform(4, 3, 2));
  EXPECT_EQ(other.solve(qp, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
}

// --- Failure modes: a clear status, never a crash, never NaN in the outputs. ---

OcpQp small_qp() {
  RandomQpSpec s = spec(6, 3, 3, 2, 1, 0.0);
  s.all_bounds = true;
  s.absent_side = 0.0;
  return testing_qp::random_qp(s, 51);
}

// --- Dense IPM (core/qp_dense_ipm) on condensed QPs: the Riccati IPM's algorithm at N = 0. ---

// The condensed (one-stage, state-free) QP of qp, as QpCondensedDense poses it.
OcpQp condensed(const OcpQp& qp) {
  QpCondensedDense dense(qp.dims);
  OcpQpSolution sol(qp.dims);
  dense.solve(qp, sol);  // condenses and embeds x0
  return dense.condensed_qp();
}

class DenseIpmQp : public ::testing::TestWithParam<Case> {};

TEST_P(DenseIpmQp, MatchesCertifiedDenseReferenceAndRiccatiIpm) {
  const Case& c = GetParam();
  RandomQpSpec s = c.spec;
  if (c.seed % 2 == 0) {  // pure ℓ1, SPEC §5.3-sized weights, one-sided
    s.pure_l1 = true;
    s.l1_scale = 1.45e4;
    s.absent_side = 0.5;
  }
  const OcpQp qp = condensed(testing_qp::random_qp(s, c.seed));
  ASSERT_EQ(qp.dims.N, 0);
  ASSERT_EQ(qp.dims.nx[0], 0);
  const OcpQpSolution sol = expect_matches_reference<QpDenseIpm>(qp);
  // Same solution as the Riccati IPM on the one-stage QP.
  QpRiccatiIpm riccati(qp.dims, tight());
  OcpQpSolution r(qp.dims);
  ASSERT_EQ(riccati.solve(qp, r), QpStatus::success);
  EXPECT_LE((sol.u[0] - r.u[0]).lpNorm<Eigen::Infinity>(), 1e-8);
  // Warm start from the solution of a perturbed QP: same solution, fewer iterations.
  OcpQp qp2 = qp;
  qp2.stage[0].r += 1e-3 * Eigen::VectorXd::Ones(qp.dims.nu[0]);
  QpDenseIpm solver(qp.dims, tight());
  OcpQpSolution cold(qp.dims), warm = sol;
  ASSERT_EQ(solver.solve(qp2, cold), QpStatus::success);
  ASSERT_EQ(solver.solve(qp2, warm, QpWarmStart::primal_dual), QpStatus::success);
  EXPECT_LE((warm.u[0] - cold.u[0]).lpNorm<Eigen::Infinity>(), 1e-7);
  EXPECT_LT(warm.iterations, cold.iterations);
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, DenseIpmQp,
    ::testing::Values(Case{spec(3, 3, 3, 2, 2, 0.5), 201}, Case{spec(10, 4, 4, 1, 2, 0.5), 202},
                      Case{spec(10, 6, 6, 2, 2, 0.3, true), 203},
                      Case{spec(12, 2, 6, 2, 1, 0.3), 204}),
    case_name);

TEST(QpDenseIpm, PendubotCondensedQp) {
  const OcpQp qp = condensed(testing_qp::pendubot_qp());
  const OcpQpSolution sol = expect_matches_reference<QpDenseIpm>(qp);
  int active = 0;
  active += (sol.lam_l[0].array() > 1e-6).count() + (sol.lam_u[0].array() > 1e-6).count();
  EXPECT_GT(active, 0);
}

TEST(QpDenseIpm, FailureStatusesWithoutNan) {
  // Only one-stage, state-free dims are accepted.
  QpDenseIpm staged;
  EXPECT_FALSE(staged.setup(OcpQpDims::uniform(3, 2, 1)));
  OcpQpDims d1(0);
  d1.nx[0] = 2;
  d1.nu[0] = 1;
  EXPECT_FALSE(staged.setup(d1));
  const OcpQp qp = condensed(small_qp());
  OcpQpSolution sol(qp.dims);
  EXPECT_EQ(staged.solve(qp, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));

  QpDenseIpm solver(qp.dims);
  ASSERT_EQ(solver.solve(qp, sol), QpStatus::success);
  OcpQp indefinite = qp;  // negative curvature beyond any barrier weight of the cold start
  indefinite.stage[0].R = -1e4 * Eigen::MatrixXd::Identity(qp.dims.nu[0], qp.dims.nu[0]);
  EXPECT_EQ(solver.solve(indefinite, sol), QpStatus::factorization_failed);
  EXPECT_TRUE(all_finite(sol));
  expect_invalid_data_rejected(solver, qp);
  expect_inconsistent_bounds_fail_cleanly(solver, qp, 0);
  QpSettings few;
  few.max_iterations = 1;
  QpDenseIpm limited(qp.dims, few);
  EXPECT_EQ(limited.solve(qp, sol), QpStatus::max_iterations);
  EXPECT_TRUE(all_finite(sol));
}


// --- Dense active set (core/qp_dense_active_set) on condensed QPs, and inside QpCondensedDense. ---

// QpCondensedDense with the active-set method, constructible like the other solvers.
class CondensedActiveSet final : public QpSolver {
 public:
  explicit CondensedActiveSet(const OcpQpDims& dims, const QpSettings& settings = {})
      : inner_(dims, settings, CondensedQpMethod::active_set) {}
  bool setup(const OcpQpDims& dims, const QpSettings& settings) override {
    return inner_.setup(dims, settings);
  }
  void prepare(const OcpQp& qp) override { inner_.prepare(qp); }
  QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                 QpWarmStart warm = QpWarmStart::cold) override {
    return inner_.solve(qp, sol, warm);
  }
  QpSettings& settings() override { return inner_.settings(); }
  const QpSettings& settings() const override { return inner_.settings(); }
  const OcpQpDims& dims() const override { return inner_.dims(); }
  const QpCondensedDense& inner() const { return inner_; }

 private:
  QpCondensedDense inner_;
};

// The random OCP-QP of case c (pure ℓ1, one-sided, for even seeds) with x0 shifted by dx0.
OcpQp random_case(const Case& c, double dx0 = 0.0) {
  RandomQpSpec s = c.spec;
  if (c.seed % 2 == 0) {
    s.pure_l1 = true;
    s.l1_scale = 1.45e4;
    s.absent_side = 0.5;
  }
  OcpQp qp = testing_qp::random_qp(s, c.seed);
  qp.x0 += dx0 * Eigen::VectorXd::Ones(qp.x0.size());
  return qp;
}

class DenseActiveSetQp : public ::testing::TestWithParam<Case> {};

// Hard input bounds and soft (ℓ2², ℓ1 or both) general rows, the structure of the Pendubot QP,
// where the active set converges from a cold start too. (Hard general rows can make it cycle
// from a cold start: see HardGeneralRowsFailCleanly; QpCondensedDense then uses the IPM.)
TEST_P(DenseActiveSetQp, MatchesCertifiedDenseReferenceColdAndWarm) {
  const Case& c = GetParam();
  // Cold: the exact KKT point of the condensed QP, the IPM's solution.
  const OcpQp qp = condensed(random_case(c));
  const OcpQpSolution sol = expect_matches_reference<QpDenseActiveSet>(qp, tight());
  QpDenseIpm ipm(qp.dims, tight());
  OcpQpSolution r(qp.dims);
  ASSERT_EQ(ipm.solve(qp, r), QpStatus::success);
  EXPECT_LE((sol.u[0] - r.u[0]).lpNorm<Eigen::Infinity>(), 1e-7);
  // Warm from that solution on the QP of a changed x0 (the closed-loop case): the same
  // solution as a cold solve, certified, in fewer iterations.
  const OcpQp qp2 = condensed(random_case(c, 0.05));
  const OcpQpSolution cold2 = expect_matches_reference<QpDenseActiveSet>(qp2, tight());
  QpDenseActiveSet solver(qp2.dims, tight());
  OcpQpSolution warm = sol;
  ASSERT_EQ(solver.solve(qp2, warm, QpWarmStart::primal_dual), QpStatus::success);
  EXPECT_LE((warm.u[0] - cold2.u[0]).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LE(warm.iterations, cold2.iterations);
  const Kkt k = kkt_residuals(qp2, warm);
  EXPECT_LE(k.max(), 1e-8);
  // Warm from its own solution: one iteration confirms the active set.
  ASSERT_EQ(solver.solve(qp2, warm, QpWarmStart::primal_dual), QpStatus::success);
  EXPECT_EQ(warm.iterations, 1);
  OcpQpSolution primal = sol;
  ASSERT_EQ(solver.solve(qp2, primal, QpWarmStart::primal), QpStatus::success);
  EXPECT_LE((primal.u[0] - cold2.u[0]).lpNorm<Eigen::Infinity>(), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, DenseActiveSetQp,
    ::testing::Values(Case{spec(1, 2, 2, 1, 1, 1.0), 301}, Case{spec(3, 3, 3, 2, 2, 1.0), 303},
                      Case{spec(5, 4, 4, 1, 1, 1.0), 305}, Case{spec(10, 4, 4, 1, 2, 1.0), 307},
                      Case{spec(10, 6, 6, 2, 2, 1.0, true), 309},
                      Case{spec(12, 2, 6, 2, 1, 1.0), 311}, Case{spec(10, 4, 4, 1, 2, 1.0), 313},
                      Case{spec(20, 5, 5, 1, 2, 1.0), 315}, Case{spec(10, 4, 4, 1, 2, 0.5), 304}),
    case_name);

class CondensedActiveSetQp : public ::testing::TestWithParam<Case> {};

TEST_P(CondensedActiveSetQp, MatchesCertifiedDenseReferenceColdAndWarm) {
  const Case& c = GetParam();
  const OcpQp qp = random_case(c);
  const OcpQpSolution sol = expect_matches_reference<CondensedActiveSet>(qp, dense_tight());
  // Warm start with a changed x0 through the OCP-QP solution (as RtiSolver does).
  const OcpQp qp2 = random_case(c, 0.05);
  const OcpQpSolution cold2 = expect_matches_reference<CondensedActiveSet>(qp2, dense_tight());
  CondensedActiveSet solver(qp2.dims, dense_tight());
  OcpQpSolution warm = sol;
  solver.prepare(qp2);
  ASSERT_EQ(solver.solve(qp2, warm, QpWarmStart::primal_dual), QpStatus::success);
  double dx = 0;
  for (int i = 0; i <= qp2.dims.N; ++i)
    dx = std::max(dx, (warm.x[i] - cold2.x[i]).lpNorm<Eigen::Infinity>());
  EXPECT_LE(dx, 1e-8);
  EXPECT_LE(kkt_residuals(qp2, warm).max(), 1e-8);
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, CondensedActiveSetQp,
    ::testing::Values(Case{spec(3, 3, 3, 2, 2, 0.5), 311}, Case{spec(10, 4, 4, 1, 2, 0.5), 312},
                      Case{spec(10, 6, 6, 2, 2, 0.3, true), 313},
                      Case{spec(20, 5, 5, 1, 2, 1.0), 314}),
    case_name);

TEST(QpDenseActiveSet, HardGeneralRowsFailCleanly) {
  // Random QPs with hard state rows, cold: either the certified solution or a failure status
  // with a finite iterate (the caller's cue to fall back to the IPM).
  int solved = 0;
  for (unsigned seed = 321; seed < 329; ++seed) {
    const OcpQp qp = condensed(random_case(Case{spec(10, 4, 4, 2, 2, 0.3), seed}));
    QpDenseActiveSet solver(qp.dims, tight());
    OcpQpSolution sol(qp.dims);
    const QpStatus st = solver.solve(qp, sol);
    EXPECT_TRUE(all_finite(sol));
    if (st != QpStatus::success) {
      EXPECT_TRUE(st == QpStatus::max_iterations || st == QpStatus::min_step) << to_string(st);
      continue;
    }
    ++solved;
    EXPECT_LE(kkt_residuals(qp, sol).max(), 1e-8) << "seed " << seed;
    QpDenseIpm ipm(qp.dims, tight());
    OcpQpSolution r(qp.dims);
    ASSERT_EQ(ipm.solve(qp, r), QpStatus::success);
    EXPECT_LE((sol.u[0] - r.u[0]).lpNorm<Eigen::Infinity>(), 1e-7) << "seed " << seed;
  }
  RecordProperty("solved", solved);
  // The comparison above ran: 6 of the 8 seeds are solved (the method is deterministic; a
  // change that solves fewer is a regression, and failing them all would check nothing).
  EXPECT_GE(solved, 6);
}

TEST(QpDenseActiveSet, PendubotQpColdAndWarmWithChangedX0) {
  const OcpQp ocp = testing_qp::pendubot_qp();
  const OcpQp qp = condensed(ocp);
  const OcpQpSolution sol = expect_matches_reference<QpDenseActiveSet>(qp, tight());
  int active = 0;
  active += (sol.lam_l[0].array() > 1e-6).count() + (sol.lam_u[0].array() > 1e-6).count();
  EXPECT_GT(active, 0);
  OcpQp ocp2 = ocp;
  ocp2.x0 += 0.02 * Eigen::VectorXd::Ones(ocp.x0.size());
  const OcpQp qp2 = condensed(ocp2);
  const OcpQpSolution cold2 = expect_matches_reference<QpDenseActiveSet>(qp2, tight());
  QpDenseActiveSet solver(qp2.dims, tight());
  OcpQpSolution warm = sol;
  ASSERT_EQ(solver.solve(qp2, warm, QpWarmStart::primal_dual), QpStatus::success);
  EXPECT_LE((warm.u[0] - cold2.u[0]).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LE(warm.iterations, 2);
  EXPECT_LE(kkt_residuals(qp2, warm).max(), 1e-8);
  // And through QpCondensedDense on the OCP-QP.
  expect_matches_reference<CondensedActiveSet>(ocp2, dense_tight());
}

TEST(QpDenseActiveSet, FailureStatusesWithoutNan) {
  QpDenseActiveSet staged;
  EXPECT_FALSE(staged.setup(OcpQpDims::uniform(3, 2, 1)));
  const OcpQp qp = condensed(testing_qp::pendubot_qp());
  OcpQpSolution sol(qp.dims);
  EXPECT_EQ(staged.solve(qp, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));

  QpDenseActiveSet solver(qp.dims);
  ASSERT_EQ(solver.solve(qp, sol), QpStatus::success);
  ASSERT_GT(sol.iterations, 1);  // some constraint is active
  OcpQp indefinite = qp;
  indefinite.stage[0].R = -Eigen::MatrixXd::Identity(qp.dims.nu[0], qp.dims.nu[0]);
  EXPECT_EQ(solver.solve(indefinite, sol), QpStatus::factorization_failed);
  EXPECT_TRUE(all_finite(sol));
  expect_invalid_data_rejected(solver, qp);
  // Inconsistent hard bounds on an input: both sides end in hold on one variable.
  expect_inconsistent_bounds_fail_cleanly(solver, qp, 0);
  QpSettings few;
  few.max_iterations = 1;
  QpDenseActiveSet limited(qp.dims, few);
  EXPECT_EQ(limited.solve(qp, sol), QpStatus::max_iterations);
  EXPECT_TRUE(all_finite(sol));
  // Negative slack weights are not supported.
  OcpQp negative = qp;
  negative.stage[0].zl[0] = -1.0;
  EXPECT_EQ(solver.solve(negative, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
}

TEST(QpCondensedDense, ActiveSetFallsBackToTheIpm) {
  // A negative ℓ1 weight (unsupported by the active set) and an iteration limit of the active
  // set's size: the IPM solves the QP, to the same solution as the IPM variant.
  OcpQp qp = testing_qp::pendubot_qp();
  qp.stage[3].zl[0] = -1.0;
  QpCondensedDense ipm(qp.dims, tight());
  OcpQpSolution r(qp.dims);
  ASSERT_EQ(ipm.solve(qp, r), QpStatus::success);
  CondensedActiveSet solver(qp.dims, tight());
  OcpQpSolution sol(qp.dims);
  ASSERT_EQ(solver.solve(qp, sol, QpWarmStart::cold), QpStatus::success);
  EXPECT_EQ(solver.inner().ipm_fallbacks(), 1);
  EXPECT_LE((sol.u[0] - r.u[0]).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_TRUE(all_finite(sol));
  QpCondensedDense failing(qp.dims, QpSettings{}, CondensedQpMethod::active_set);
  OcpQp indefinite = qp;
  for (auto& st : indefinite.stage) st.R *= -1e4;
  EXPECT_EQ(failing.solve(indefinite, sol), QpStatus::factorization_failed);
  EXPECT_EQ(failing.ipm_fallbacks(), 1);
  EXPECT_TRUE(all_finite(sol));
}

// The benchmark QPs through partial condensing: the same solution as the plain Riccati IPM,
// and a primal-dual warm start with a changed x0 as in the RTI feedback phase.
// RTI's preparation phase (QpSolver::prepare with the warm start) factorizes the first Newton
// system of stages N..1 before x0 is known: prepared on the QP with the previous x0, then solved
// with the new one, the solve is the plain warm solve's bit for bit (stage 0 is initialized and
// factorized again with the new x0), for the stage-wise solver and behind pair condensing (whose
// first block's constraints do involve x0).
TEST_P(ControllerQp, PreparedWarmStartSolvesAsThePlainWarmStart) {
  const OcpQp qp = GetParam() == 0   ? testing_qp::mixed_initiative_qp()
                   : GetParam() == 1 ? testing_qp::crazyflie_qp()
                                     : testing_qp::pendubot_qp();
  QpRiccatiIpm plain(qp.dims, tight()), prepared(qp.dims, tight());
  QpRiccatiIpmPairs pairs_plain(qp.dims, tight()), pairs_prepared(qp.dims, tight());
  OcpQpSolution start(qp.dims);
  ASSERT_EQ(plain.solve(qp, start), QpStatus::success);
  OcpQp moved = qp;
  moved.x0 += 1e-2 * Eigen::VectorXd::Ones(qp.x0.size());
  for (auto [a, b] : {std::pair<QpSolver*, QpSolver*>{&plain, &prepared},
                      std::pair<QpSolver*, QpSolver*>{&pairs_plain, &pairs_prepared}}) {
    OcpQpSolution sa = start, sb = start;
    ASSERT_EQ(a->solve(moved, sa, QpWarmStart::primal_dual), QpStatus::success);
    OcpQp stale = moved;
    stale.x0 = qp.x0;  // the preparation does not know x0 yet
    b->prepare(stale, sb, QpWarmStart::primal_dual);
    stale.x0 = moved.x0;
    ASSERT_EQ(b->solve(stale, sb, QpWarmStart::primal_dual), QpStatus::success);
    EXPECT_EQ(sa.iterations, sb.iterations);
    EXPECT_GT(sa.iterations, 0);
    for (int i = 0; i <= qp.dims.N; ++i) {
      ASSERT_EQ(sa.x[i], sb.x[i]) << i;
      ASSERT_EQ(sa.u[i], sb.u[i]) << i;
      ASSERT_EQ(sa.lam_l[i], sb.lam_l[i]) << i;
    }
    EXPECT_LE(kkt_residuals(moved, sb).max(), 1e-8);
  }
}

TEST_P(ControllerQp, PairsMatchThePlainSolverColdAndWarm) {
  const OcpQp qp = GetParam() == 0   ? testing_qp::mixed_initiative_qp()
                   : GetParam() == 1 ? testing_qp::crazyflie_qp()
                                     : testing_qp::pendubot_qp();
  QpRiccatiIpm plain(qp.dims, tight());
  QpRiccatiIpmPairs pairs(qp.dims, tight());
  OcpQpSolution a(qp.dims), b(qp.dims);
  ASSERT_EQ(plain.solve(qp, a), QpStatus::success);
  ASSERT_EQ(pairs.solve(qp, b), QpStatus::success);
  EXPECT_LE(kkt_residuals(qp, b).max(), 1e-8);
  auto max_diff = [&](const OcpQpSolution& p, const OcpQpSolution& q) {  // relative, as above
    double d = 0, scale = 1.0;
    for (int i = 0; i <= qp.dims.N; ++i) {
      d = std::max({d, (p.x[i] - q.x[i]).lpNorm<Eigen::Infinity>(),
                    (p.u[i] - q.u[i]).lpNorm<Eigen::Infinity>()});
      scale = std::max({scale, p.x[i].lpNorm<Eigen::Infinity>(), p.u[i].lpNorm<Eigen::Infinity>()});
    }
    return d / scale;
  };
  EXPECT_LE(max_diff(a, b), 1e-7);
  EXPECT_NEAR(a.objective, b.objective, 1e-9 * std::max(1.0, std::abs(a.objective)));
  OcpQp qp2 = qp;
  qp2.x0 += 1e-3 * Eigen::VectorXd::Ones(qp.x0.size());
  ASSERT_EQ(plain.solve(qp2, a), QpStatus::success);
  pairs.prepare(qp2);
  OcpQpSolution w = b;
  ASSERT_EQ(pairs.solve(qp2, w, QpWarmStart::primal_dual), QpStatus::success);
  EXPECT_LE(max_diff(a, w), 1e-7);
  EXPECT_LE(kkt_residuals(qp2, w).max(), 1e-8);
  EXPECT_LT(w.iterations, b.iterations);
}

// The condensing's gemm kernel against Eigen on every tile shape: rows 1..13 (one and two
// vectors, full and masked), columns 1..9 (4-column blocks and tails), k = 0..16, leading
// dimensions larger than the operands, accumulating and overwriting; rows below m untouched.
TEST(QpKernels, GemmNnMatchesEigen) {
  std::srand(11);
  for (int m = 1; m <= 13; ++m)
    for (int n = 1; n <= 9; ++n)
      for (int k : {0, 1, 5, 16})
        for (bool overwrite : {false, true}) {
          const Eigen::MatrixXd A = Eigen::MatrixXd::Random(m + 3, k);
          const Eigen::MatrixXd B = Eigen::MatrixXd::Random(k + 2, n);
          Eigen::MatrixXd C = Eigen::MatrixXd::Random(m + 1, n);
          const Eigen::MatrixXd C0 = C;
          Eigen::MatrixXd expected = A.topRows(m) * B.topRows(k);
          if (!overwrite) expected += C0.topRows(m);
          kernels::gemm_nn(m, n, k, A.data(), int(A.rows()), B.data(), int(B.rows()), C.data(),
                           int(C.rows()), overwrite);
          EXPECT_LE((C.topRows(m) - expected).cwiseAbs().maxCoeff(), 1e-14 * (k + 1))
              << m << "x" << n << "x" << k;
          EXPECT_EQ(C.row(m), C0.row(m));
        }
}

// The matrix-vector kernels against Eigen: rows 0..13 (4-row vectors and masked tails),
// columns 0..9 (4-column blocks and their tails), a larger leading dimension; y accumulates, and
// the entries of y past the result are untouched.
TEST(QpKernels, GemvMatchesEigen) {
  std::srand(17);
  for (int m = 0; m <= 13; ++m)
    for (int n = 0; n <= 9; ++n) {
      const Eigen::MatrixXd A = Eigen::MatrixXd::Random(m + 3, n);
      const Eigen::VectorXd xn = Eigen::VectorXd::Random(n), xt = Eigen::VectorXd::Random(m);
      Eigen::VectorXd yn = Eigen::VectorXd::Random(m + 2), yt = Eigen::VectorXd::Random(n + 2);
      const Eigen::VectorXd yn0 = yn, yt0 = yt;
      kernels::gemv_n(m, n, A.data(), int(A.rows()), xn.data(), yn.data());
      kernels::gemv_t(m, n, A.data(), int(A.rows()), xt.data(), yt.data());
      const Eigen::VectorXd en = yn0.head(m) + A.topRows(m) * xn;
      const Eigen::VectorXd et = yt0.head(n) + A.topRows(m).transpose() * xt;
      if (m > 0) {
        EXPECT_LE((yn.head(m) - en).cwiseAbs().maxCoeff(), 1e-14 * (n + 1)) << m << "x" << n;
      }
      if (n > 0) {
        EXPECT_LE((yt.head(n) - et).cwiseAbs().maxCoeff(), 1e-14 * (m + 1)) << m << "x" << n;
      }
      EXPECT_EQ(yn.tail(2), yn0.tail(2)) << m << "x" << n;
      EXPECT_EQ(yt.tail(2), yt0.tail(2)) << m << "x" << n;
    }
}

// The transposing copy against Eigen: every shape up to 9 x 9 (4 x 4 blocks, row and column
// tails), larger leading dimensions; the destination's rows and columns outside Aᵀ untouched.
TEST(QpKernels, TransposeMatchesEigen) {
  std::srand(13);
  for (int m = 0; m <= 9; ++m)
    for (int n = 0; n <= 9; ++n) {
      const Eigen::MatrixXd A = Eigen::MatrixXd::Random(m + 2, n);
      Eigen::MatrixXd B = Eigen::MatrixXd::Random(n + 3, m + 1);
      const Eigen::MatrixXd B0 = B;
      kernels::transpose(m, n, A.data(), int(A.rows()), B.data(), int(B.rows()));
      EXPECT_EQ(B.topLeftCorner(n, m), A.topRows(m).transpose()) << m << "x" << n;
      EXPECT_EQ(B.bottomRows(3), B0.bottomRows(3));
      EXPECT_EQ(B.col(m), B0.col(m));
    }
}

// The fraction-to-boundary search against its definition (the smallest −z_k/dz_k over dz_k < 0,
// capped at alpha; the first index attaining it), for every length up to 13 (the vector blocks
// and every tail): random signs, repeated ratios (ties: the first wins), NaN components (never
// block), nothing blocking, and the cap.
TEST(QpKernels, MaxStepMatchesItsDefinition) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int blocked = 0, capped = 0;
  for (int m = 0; m <= 13; ++m)
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<double> z(static_cast<std::size_t>(m)), dz(static_cast<std::size_t>(m));
      for (int k = 0; k < m; ++k) {
        z[k] = 0.1 + unit(rng);
        dz[k] = unit(rng) < 0.5 ? -4.0 * unit(rng) : unit(rng);
        if (trial % 5 == 1 && k > 0) z[k] = z[k - 1], dz[k] = dz[k - 1];  // ties
        if (trial % 7 == 2 && unit(rng) < 0.3) (unit(rng) < 0.5 ? z[k] : dz[k]) = nan;
        if (trial % 11 == 3) dz[k] = std::abs(dz[k]);  // nothing blocks
      }
      const double cap = trial % 3 == 0 ? 1.0 : 1e3;
      double expected = cap;
      int expected_block = -1;
      for (int k = 0; k < m; ++k)
        if (dz[k] < 0.0 && -z[k] / dz[k] < expected) expected = -z[k] / dz[k], expected_block = k;
      int block = -2;
      const double a = kernels::max_step(m, z.data(), dz.data(), cap, &block);
      EXPECT_EQ(a, expected) << m << " / " << trial;
      EXPECT_EQ(block, expected_block) << m << " / " << trial;
      blocked += expected_block >= 0;
      capped += expected_block < 0;
    }
  EXPECT_GT(blocked, 500);  // both outcomes were exercised
  EXPECT_GT(capped, 500);
}

// Each condensed pair block against the formulas of core/qp/qp_riccati_ipm_pairs.hpp, evaluated
// with Eigen: for dense Hessians with cross terms S, and for the controllers' structure (Q
// diagonal, S = 0: Q1 A0 as a row scaling, no S1 products); Q exactly symmetric.
TEST(QpRiccatiIpmPairs, CondensedBlocksMatchTheirDefinition) {
  for (const auto& [nx_max, structured] :  // blocks of 4 states and their tails
       {std::pair{6, false}, std::pair{6, true}, std::pair{13, false}, std::pair{13, true}}) {
    SCOPED_TRACE(structured ? "diagonal Q, S = 0" : "dense Q, S");
    SCOPED_TRACE("nx up to " + std::to_string(nx_max));
    OcpQp qp = testing_qp::random_qp(spec(9, 3, nx_max, 2, 2, 0.3), 61);
    if (structured)
      for (OcpQpStage& s : qp.stage) {
        s.Q = Eigen::MatrixXd(s.Q.diagonal().asDiagonal());
        s.S.setZero();
      }
    QpRiccatiIpmPairs pairs(qp.dims);
    pairs.prepare(qp);
    const OcpQp& c = pairs.condensed();
    for (int j = 0; 2 * j + 1 < qp.dims.N; ++j) {
      SCOPED_TRACE("pair " + std::to_string(j));
      const OcpQpStage &s0 = qp.stage[2 * j], &s1 = qp.stage[2 * j + 1], &t = c.stage[j];
      const int nu0 = qp.dims.nu[2 * j], nu1 = qp.dims.nu[2 * j + 1];
      const int ng0 = qp.dims.ng[2 * j], nbx1 = qp.dims.nbx[2 * j + 1];
      const Eigen::VectorXd g1 = s1.Q * s0.b + s1.q;
      Eigen::MatrixXd B(s1.A.rows(), nu0 + nu1), S(nu0 + nu1, s0.Q.cols()), R(nu0 + nu1, nu0 + nu1);
      B << s1.A * s0.B, s1.B;
      S << s0.S + s0.B.transpose() * s1.Q * s0.A, s1.S * s0.A;
      R << s0.R + s0.B.transpose() * s1.Q * s0.B, (s1.S * s0.B).transpose(), s1.S * s0.B, s1.R;
      Eigen::VectorXd r(nu0 + nu1);
      r << s0.r + s0.B.transpose() * g1, s1.r + s1.S * s0.b;
      const auto near = [](const auto& a, const auto& b) {
        return (a - b).cwiseAbs().maxCoeff() <= 1e-12 * (1.0 + b.cwiseAbs().maxCoeff());
      };
      EXPECT_TRUE(near(t.A, s1.A * s0.A));
      EXPECT_TRUE(near(t.B, B));
      EXPECT_TRUE(near(t.b, s1.A * s0.b + s1.b));
      EXPECT_TRUE(near(t.Q, s0.Q + s0.A.transpose() * s1.Q * s0.A));
      EXPECT_EQ(t.Q, t.Q.transpose());
      EXPECT_TRUE(near(t.S, S));
      EXPECT_TRUE(near(t.R, R));
      EXPECT_TRUE(near(t.q, s0.q + s0.A.transpose() * g1));
      EXPECT_TRUE(near(t.r, r));
      for (int k = 0; k < nbx1; ++k) {  // x_{k+1}'s bounds as rows of [A0 B0]
        const int idx = s1.idxbx[k];
        EXPECT_EQ(t.C.row(ng0 + k), s0.A.row(idx));
        EXPECT_EQ(t.D.row(ng0 + k).head(nu0), s0.B.row(idx));
        EXPECT_EQ(t.D.row(ng0 + k).tail(nu1).cwiseAbs().sum(), 0.0);
      }
      const int r0 = ng0 + nbx1, ng1 = qp.dims.ng[2 * j + 1];
      if (ng1 > 0) {
        EXPECT_TRUE(near(t.C.middleRows(r0, ng1), s1.C * s0.A));
        EXPECT_TRUE(near(t.D.middleRows(r0, ng1).leftCols(nu0), s1.C * s0.B));
        EXPECT_EQ(t.D.middleRows(r0, ng1).rightCols(nu1), s1.D);
      }
    }
  }
}

TEST(QpRiccatiIpmPairs, FailureStatusesWithoutNan) {
  const OcpQp qp = testing_qp::random_qp(spec(9, 4, 4, 2, 1, 0.3), 51);
  QpRiccatiIpmPairs solver(qp.dims);
  OcpQpSolution sol(qp.dims);
  OcpQp nan = qp;
  nan.stage[3].Q(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solver.solve(nan, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
  OcpQp indefinite = qp;
  for (auto& s : indefinite.stage) s.R *= -1.0;
  EXPECT_EQ(solver.solve(indefinite, sol), QpStatus::factorization_failed);
  EXPECT_TRUE(all_finite(sol));
  expect_inconsistent_bounds_fail_cleanly(solver, qp, 3);  // an eliminated (odd) stage's input
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::success);
  QpRiccatiIpmPairs other(OcpQpDims::uniform(4, 3, 2));
  EXPECT_EQ(other.solve(qp, sol), QpStatus::invalid_data);
}

TEST(QpRiccatiIpmFailure, InfeasibleHardConstraints) {
  OcpQp qp = small_qp();
  // All input bounds hard and tight around 0; a state bound on x_N far outside the reachable
  // set: x_N = A…x0 + Σ… with |u| ≤ 1e-3 cannot reach it.
  OcpQpDims d = OcpQpDims::uniform(6, 3, 2, 1, 2, 0, 0);
  OcpQp in(d);
  in.x0 = qp.x0;
  for (int i = 0; i <= 6; ++i) {
    OcpQpStage& s = in.stage[i];
    s.Q = Eigen::MatrixXd::Identity(3, 3);
    if (i < 6) {
      s.R = Eigen::MatrixXd::Identity(2, 2);
      s.A = 0.9 * Eigen::MatrixXd::Identity(3, 3);
      s.B = Eigen::MatrixXd::Ones(3, 2);
      s.lbu.setConstant(-1e-3);
      s.ubu.setConstant(1e-3);
    }
    if (i > 0) {
      s.lbx[0] = i == 6 ? 100.0 : -1e3;
      s.ubx[0] = 1e3;
    }
  }
  QpRiccatiIpm solver(d);
  OcpQpSolution sol(d);
  const QpStatus st = solver.solve(in, sol);
  EXPECT_TRUE(st == QpStatus::min_step || st == QpStatus::max_iterations) << to_string(st);
  EXPECT_EQ(sol.status, st);
  EXPECT_TRUE(all_finite(sol));
}

TEST(QpRiccatiIpmFailure, InconsistentBoundsAreInfeasible) {
  OcpQp qp = small_qp();
  qp.stage[2].lbu.setConstant(1.0);
  qp.stage[2].ubu.setConstant(-1.0);
  QpRiccatiIpm solver(qp.dims);
  OcpQpSolution sol(qp.dims);
  const QpStatus st = solver.solve(qp, sol);
  EXPECT_NE(st, QpStatus::success);
  EXPECT_NE(st, QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
}

TEST(QpRiccatiIpmFailure, SingularHessianOnUnboundedInput) {
  // R = 0 and S = 0 with the input unbounded: the QP has no unique minimizer (unbounded if
  // r ≠ 0); the uu Riccati block is singular.
  OcpQpDims d = OcpQpDims::uniform(5, 3, 2);
  OcpQp qp(d);
  qp.x0.setOnes();
  for (int i = 0; i <= 5; ++i) {
    qp.stage[i].Q = Eigen::MatrixXd::Identity(3, 3);
    if (i < 5) {
      qp.stage[i].A = Eigen::MatrixXd::Identity(3, 3);
      qp.stage[i].B = Eigen::MatrixXd::Zero(3, 2);
      qp.stage[i].r.setOnes();
    }
  }
  QpRiccatiIpm solver(d);
  OcpQpSolution sol(d);
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::factorization_failed);
  EXPECT_TRUE(all_finite(sol));
}

TEST(QpRiccatiIpmFailure, IndefiniteHessian) {
  // A negative curvature direction of an unconstrained state: the QP is unbounded below.
  OcpQpDims d = OcpQpDims::uniform(5, 3, 2, 1, 2);
  OcpQp qp(d);
  qp.x0.setOnes();
  for (int i = 0; i <= 5; ++i) {
    qp.stage[i].Q = Eigen::MatrixXd::Identity(3, 3);
    if (i == 3) qp.stage[i].Q(2, 2) = -2.0;
    if (i < 5) {
      qp.stage[i].R = Eigen::MatrixXd::Identity(2, 2);
      qp.stage[i].A = Eigen::MatrixXd::Identity(3, 3);
      qp.stage[i].B = Eigen::MatrixXd::Ones(3, 2);
      qp.stage[i].lbu.setConstant(-1.0);
      qp.stage[i].ubu.setConstant(1.0);
    }
    if (i > 0) {
      qp.stage[i].lbx.setConstant(-1.0);  // bounds state 0 only
      qp.stage[i].ubx.setConstant(1.0);
    }
  }
  QpRiccatiIpm solver(d);
  OcpQpSolution sol(d);
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::factorization_failed);
  EXPECT_TRUE(all_finite(sol));
}

TEST(QpRiccatiIpmFailure, SemidefiniteStateCostIsFine) {
  // Q = 0 everywhere (cost on inputs only) is singular but the QP is well posed: the square-root
  // Riccati must handle a singular cost-to-go P.
  OcpQp qp = small_qp();
  for (auto& s : qp.stage) {
    s.Q.setZero();
    s.S.setZero();
  }
  const testing_qp::DenseSolution ref = testing_qp::dense_reference(qp);
  ASSERT_TRUE(ref.certified);
  QpRiccatiIpm solver(qp.dims, tight());
  OcpQpSolution sol(qp.dims);
  ASSERT_EQ(solver.solve(qp, sol), QpStatus::success);
  EXPECT_LE(std::abs(sol.objective - ref.objective) / std::max(1.0, std::abs(ref.objective)), 1e-7);
}

// A state without curvature in the cost-to-go (the mixed-initiative cost at λ = 0 leaves φ, θ
// and Ω unweighted at the terminal stage) and a warm start whose multipliers π do not vanish
// there: the stationarity residual then has a component along P's null space that the Newton
// direction must remove (Δπ = P Δx + g needs all of g), or the solve stalls at that residual.
TEST(QpRiccatiIpmFailure, SemidefiniteStateCostWarmStartedFromOtherMultipliers) {
  RandomQpSpec s = spec(6, 3, 3, 2, 0, 0.0);
  s.all_bounds = true;
  s.absent_side = 0.0;
  const OcpQp pd = testing_qp::random_qp(s, 51);
  OcpQp qp = pd;
  for (int i = 0; i <= qp.dims.N; ++i) {  // state 0 free of cost everywhere
    qp.stage[i].Q.row(0).setZero();
    qp.stage[i].Q.col(0).setZero();
    qp.stage[i].q(0) = 0.0;
    if (i < qp.dims.N) qp.stage[i].S.col(0).setZero();
    for (int k = 0; k < qp.stage[i].idxbx.size(); ++k)  // and unbounded: no barrier curvature
      if (qp.stage[i].idxbx(k) == 0) qp.stage[i].lbx(k) = -1e30, qp.stage[i].ubx(k) = 1e30;
  }
  const testing_qp::DenseSolution ref = testing_qp::dense_reference(qp);
  ASSERT_TRUE(ref.certified);
  const testing_qp::DenseQp D = testing_qp::densify(qp);
  for (const bool pairs : {false, true}) {
    SCOPED_TRACE(pairs ? "pairs" : "plain");
    std::unique_ptr<QpSolver> solver;
    if (pairs) solver = std::make_unique<QpRiccatiIpmPairs>(qp.dims, tight());
    else solver = std::make_unique<QpRiccatiIpm>(qp.dims, tight());
    OcpQpSolution warm(qp.dims);
    if (pairs) solver->prepare(pd);
    ASSERT_EQ(solver->solve(pd, warm), QpStatus::success);
    for (auto& pi : warm.pi) pi(0) += 1.0;  // multipliers of another problem
    if (pairs) solver->prepare(qp);
    ASSERT_EQ(solver->solve(qp, warm, QpWarmStart::primal_dual), QpStatus::success)
        << "iterations " << warm.iterations << " stationarity " << warm.res_stat;
    const Eigen::VectorXd z = testing_qp::to_dense(D, qp.dims, warm);
    EXPECT_LE((z - ref.z).lpNorm<Eigen::Infinity>() / std::max(1.0, ref.z.lpNorm<Eigen::Infinity>()),
              1e-6);
  }
}

TEST(QpRiccatiIpmFailure, NanOrInfInData) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int which = 0; which < 6; ++which) {
    OcpQp qp = small_qp();
    switch (which) {
      case 0: qp.stage[2].A(1, 1) = nan; break;
      case 1: qp.stage[0].R(0, 0) = inf; break;
      case 2: qp.x0[0] = nan; break;
      case 3: qp.stage[4].q[2] = -inf; break;
      case 4: qp.stage[1].lbu[0] = nan; break;
      case 5: qp.stage[3].C(0, 0) = nan; break;
    }
    QpRiccatiIpm solver(qp.dims);
    OcpQpSolution sol(qp.dims);
    // A NaN-polluted warm start must not leak either.
    sol.x[1].setConstant(nan);
    EXPECT_EQ(solver.solve(qp, sol, QpWarmStart::primal), QpStatus::invalid_data) << which;
    EXPECT_TRUE(all_finite(sol)) << which;
  }
}

TEST(QpRiccatiIpmFailure, MaxIterationsReportedWithFiniteIterate) {
  const OcpQp qp = small_qp();
  QpRiccatiIpmSettings s;
  s.max_iterations = 2;
  QpRiccatiIpm solver(qp.dims, s);
  OcpQpSolution sol(qp.dims);
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::max_iterations);
  EXPECT_EQ(sol.iterations, 2);
  EXPECT_TRUE(all_finite(sol));
}

TEST(QpRiccatiIpmFailure, InvalidDimsOrMismatchedProblem) {
  OcpQpDims bad = OcpQpDims::uniform(3, 2, 1, 0, 1);
  bad.nbx[1] = 5;  // more bounds than states
  QpRiccatiIpm solver;
  EXPECT_FALSE(solver.setup(bad));
  const OcpQp qp = small_qp();
  OcpQpSolution sol(qp.dims);
  EXPECT_EQ(solver.solve(qp, sol), QpStatus::invalid_data);
  QpRiccatiIpm other(OcpQpDims::uniform(4, 3, 2));
  EXPECT_EQ(other.solve(qp, sol), QpStatus::invalid_data);
  OcpQp badidx = qp;
  badidx.stage[1].idxbu[0] = 7;
  QpRiccatiIpm ok(qp.dims);
  EXPECT_EQ(ok.solve(badidx, sol), QpStatus::invalid_data);
  EXPECT_TRUE(all_finite(sol));
}

}  // namespace
}  // namespace mixpilot
