// The QP solvers' solve() allocates nothing: every malloc/calloc/realloc of the process
// (Eigen's heap, std::vector growth, operator new, ...) is counted while solve() runs and must
// stay at zero; a Debug build also aborts at an Eigen allocation (no_malloc.hpp).
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "core/qp/qp_condensed_dense.hpp"
#include "core/qp/qp_dense_active_set.hpp"
#include "core/qp/qp_dense_ipm.hpp"
#include "core/qp/qp_riccati_ipm.hpp"
#include "core/qp/qp_riccati_ipm_pairs.hpp"
#include "no_malloc.hpp"
#include "qp_problems.hpp"
#include "qp_random.hpp"

namespace mixpilot {
namespace {

// The count the tests below rely on is live in this executable: a plain malloc, an Eigen
// vector and a std::vector are three allocations.
TEST(QpNoMalloc, TheCountSeesEveryAllocation) {
  if (!kAllocationsCounted) GTEST_SKIP() << "under the sanitizers malloc is theirs: nothing is counted";
  long n = 0;
  {
    AllocationCount counting;
    void* volatile p = std::malloc(32);
    std::free(p);
    Eigen::VectorXd v(64);
    v.setOnes();
    std::vector<int> w(3, 1);
    n = AllocationCount::count();
  }
  EXPECT_EQ(n, 3);
}

// A QP and two variants that must fail: NaN in the data, an indefinite Hessian.
struct QpCases {
  OcpQp qp, bad, indefinite;
};

QpCases random_cases(int N, int nx_min, int nx_max, int nu, unsigned seed) {
  testing_qp::RandomQpSpec spec;
  spec.N = N;
  spec.nx_min = nx_min;
  spec.nx_max = nx_max;
  spec.nu = nu;
  spec.ng_max = 2;
  spec.soft_fraction = 0.4;
  QpCases c{testing_qp::random_qp(spec, seed), {}, {}};
  c.bad = c.qp;
  c.bad.stage[3].A(0, 0) = std::numeric_limits<double>::quiet_NaN();
  c.indefinite = c.qp;
  for (auto& st : c.indefinite.stage) st.R *= -1.0;
  return c;
}

// Cold, primal and primal-dual warm starts (after a prepare(), where the solver has one, and
// after a prepare() given the warm start, as RTI's preparation phase does), invalid data and a
// failed factorization: none allocates.
void expect_solves_allocate_nothing(QpSolver& solver, const QpCases& c) {
  OcpQpSolution sol(c.qp.dims);
  QpStatus cold, primal, dual, prepared_dual, invalid, failed;
  {
    NoMalloc guard;
    cold = solver.solve(c.qp, sol);
    solver.prepare(c.qp);
    primal = solver.solve(c.qp, sol, QpWarmStart::primal);
    dual = solver.solve(c.qp, sol, QpWarmStart::primal_dual);
    solver.prepare(c.qp, sol, QpWarmStart::primal_dual);
    prepared_dual = solver.solve(c.qp, sol, QpWarmStart::primal_dual);
    invalid = solver.solve(c.bad, sol);
    failed = solver.solve(c.indefinite, sol);
    EXPECT_EQ(NoMalloc::count(), 0);
  }
  EXPECT_EQ(cold, QpStatus::success);
  EXPECT_EQ(primal, QpStatus::success);
  EXPECT_EQ(dual, QpStatus::success);
  EXPECT_EQ(prepared_dual, QpStatus::success);
  EXPECT_EQ(invalid, QpStatus::invalid_data);
  EXPECT_EQ(failed, QpStatus::factorization_failed);
}

// N = 21 (odd: QpRiccatiIpmPairs then has a lone last dynamic stage too), stage-varying nx.
const QpCases& riccati_cases() {
  static const QpCases c = random_cases(21, 6, 9, 3, 77);
  return c;
}

TEST(QpNoMalloc, SolveAllocatesNothing) {
  QpRiccatiIpm solver(riccati_cases().qp.dims);
  expect_solves_allocate_nothing(solver, riccati_cases());
}

TEST(QpNoMalloc, PairsPrepareAndSolveAllocateNothing) {
  for (const int levels : {1, 2}) {  // 2: nested, pairs of pairs
    QpRiccatiIpmPairs solver(riccati_cases().qp.dims, {}, levels);
    expect_solves_allocate_nothing(solver, riccati_cases());
  }
}

TEST(QpNoMalloc, CondensedDensePrepareAndSolveAllocateNothing) {
  const QpCases c = random_cases(12, 3, 6, 2, 78);  // stage-varying dims
  QpCondensedDense solver(c.qp.dims);
  expect_solves_allocate_nothing(solver, c);
}

TEST(QpNoMalloc, CondensedActiveSetPrepareAndSolveAllocateNothing) {
  // QpDenseActiveSet inside QpCondensedDense, warm starts, and the IPM fallback.
  const OcpQp qp = testing_qp::pendubot_qp();
  OcpQp moved = qp;
  moved.x0 += 0.02 * Eigen::VectorXd::Ones(qp.x0.size());
  OcpQp negative = qp;  // a negative ℓ1 weight: the active set hands over to the IPM
  negative.stage[3].zl[0] = -1.0;
  OcpQp indefinite = qp;
  for (auto& s : indefinite.stage) s.R *= -1e4;

  QpCondensedDense solver(qp.dims, QpSettings{}, CondensedQpMethod::active_set);
  QpDenseActiveSet dense(solver.condensed_qp().dims);
  OcpQpSolution sol(qp.dims), dsol(solver.condensed_qp().dims);
  QpStatus cold, warm, primal, fallback, failed, dcold, dwarm;
  {
    NoMalloc guard;
    cold = solver.solve(qp, sol);
    solver.prepare(moved);
    warm = solver.solve(moved, sol, QpWarmStart::primal_dual);
    primal = solver.solve(qp, sol, QpWarmStart::primal);
    fallback = solver.solve(negative, sol, QpWarmStart::primal_dual);
    failed = solver.solve(indefinite, sol);
    dcold = dense.solve(solver.condensed_qp(), dsol);
    dwarm = dense.solve(solver.condensed_qp(), dsol, QpWarmStart::primal_dual);
    EXPECT_EQ(NoMalloc::count(), 0);
  }
  EXPECT_EQ(cold, QpStatus::success);
  EXPECT_EQ(warm, QpStatus::success);
  EXPECT_EQ(primal, QpStatus::success);
  EXPECT_EQ(fallback, QpStatus::success);
  EXPECT_EQ(failed, QpStatus::factorization_failed);
  EXPECT_EQ(solver.ipm_fallbacks(), 2);
  EXPECT_EQ(dcold, QpStatus::factorization_failed);  // the indefinite QP, condensed last
  EXPECT_EQ(dwarm, QpStatus::factorization_failed);
}

TEST(QpNoMalloc, DenseIpmSolveAllocatesNothing) {
  testing_qp::RandomQpSpec spec;
  spec.N = 10;
  spec.nx_min = spec.nx_max = 4;
  spec.nu = 1;
  spec.ng_max = 2;
  spec.soft_fraction = 0.5;
  const OcpQp ocp = testing_qp::random_qp(spec, 79);
  QpCondensedDense condenser(ocp.dims);
  OcpQpSolution osol(ocp.dims);
  ASSERT_EQ(condenser.solve(ocp, osol), QpStatus::success);
  QpCases c{condenser.condensed_qp(), {}, {}};  // one stage, no states
  c.bad = c.qp;
  c.bad.stage[0].R(0, 0) = std::numeric_limits<double>::quiet_NaN();
  c.indefinite = c.qp;
  c.indefinite.stage[0].R *= -1.0;
  QpDenseIpm solver(c.qp.dims);
  expect_solves_allocate_nothing(solver, c);
}

}  // namespace
}  // namespace mixpilot
