// mixpilot-qpsets: solves every QP of the closed-loop QP sets (tests/benchmarks/qp_sets.hpp)
// once, as BM_QpSolve/closed_* does, and prints per set the QPs, their IPM iterations and how
// many failed. Made for instruction counts, which are repeatable on a loaded machine:
//   MIXPILOT_QP_SETS=/tmp/qpsets valgrind --tool=callgrind
//       --toggle-collect='mixpilot::bench::solve_set_once*' mixpilot-qpsets closed_mi_novice
// (one command line) gives the instructions of the whole set (÷ its QPs: per QP); the preparation (the
// x̄_0-free part) and the solve are the inclusive costs of prepare_qp and solve_qp.
// Arguments: set names (default: all).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include "tests/benchmarks/qp_sets.hpp"

namespace mixpilot::bench {

__attribute__((noinline)) void prepare_qp(QpSolver& solver, const OcpQp& qp,
                                          const OcpQpSolution& start, QpWarmStart warm) {
  solver.prepare(qp, start, warm);  // as the RTI's preparation phase
}
__attribute__((noinline)) QpStatus solve_qp(QpSolver& solver, const OcpQp& qp, OcpQpSolution& sol,
                                            QpWarmStart warm) {
  return solver.solve(qp, sol, warm);
}

struct SetResult {
  int qps = 0, failed = 0, iterations = 0, max_iterations = 0;
};

__attribute__((noinline)) SetResult solve_set_once(const QpSet& set, QpSolver& solver, OcpQp& qp,
                                                  OcpQpSolution& sol) {
  SetResult r;
  for (const ClosedLoopQp& c : set.qps) {
    qp = c.qp;
    sol = c.start;
    prepare_qp(solver, qp, sol, c.warm);
    if (solve_qp(solver, qp, sol, c.warm) != QpStatus::success) ++r.failed;
    ++r.qps;
    r.iterations += sol.iterations;
    r.max_iterations = std::max(r.max_iterations, sol.iterations);
  }
  return r;
}

}  // namespace mixpilot::bench

int main(int argc, char** argv) {
  using namespace mixpilot::bench;
  int status = 0;
  for (const QpSetSpec& spec : qp_set_specs()) {
    bool wanted = argc < 2;
    for (int i = 1; i < argc; ++i) wanted = wanted || std::strcmp(argv[i], spec.name) == 0;
    if (!wanted) continue;
    std::string error;
    const QpSet set = closed_loop_set(spec, 200, error);
    if (set.qps.empty()) {
      std::fprintf(stderr, "mixpilot-qpsets: %s: %s\n", spec.name, error.c_str());
      status = 1;
      continue;
    }
    const mixpilot::OcpQpDims& dims = set.qps.front().qp.dims;
    auto solver = make_qp_solver(set.rti, dims);
    mixpilot::OcpQp qp(dims);
    mixpilot::OcpQpSolution sol(dims);
    const SetResult r = solve_set_once(set, *solver, qp, sol);
    std::printf("%-32s qps %3d  iterations mean %.2f max %d  failed %d\n", spec.name, r.qps,
                double(r.iterations) / r.qps, r.max_iterations, r.failed);
    if (r.failed > 0) status = 1;
  }
  return status;
}
