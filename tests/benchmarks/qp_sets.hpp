#pragma once
// Closed-loop QP sets (mixpilot-bench, mixpilot-qpsets): the QPs the NMPC of a shipped scenario
// solved in a flight, each with the warm start the loop solved it from (RtiQpObserver), taken
// evenly over the flight. Flying is deterministic, so a set is the same on every run of the
// same build; MIXPILOT_QP_SETS=DIR keeps them in DIR/<set>.qps (a raw binary cache, not a
// format: the build that wrote it reads it) so that two builds can be timed on identical QPs,
// and MIXPILOT_DUMP_QP=FILE appends them to FILE as JSON lines with their warm starts
// (docs/qp-dump-format.md) for other solvers. MIXPILOT_QP_SET_SOLVER=riccati_ipm (or
// riccati_ipm_pairs) solves the sets with that variant instead of the loop's, to compare them.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/nlp/rti.hpp"
#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_solver.hpp"

namespace mixpilot::bench {

struct QpSetSpec {
  const char* name;      // closed_<...>: the benchmark's suffix and the cache file's name
  const char* scenario;  // under scenarios/
  const char* pilot;     // mixed initiative: the pilot; else null
};
// novice and reckless on mi_helix, obstacles_thrown_balls, crazyflie tracking (smooth step).
const std::vector<QpSetSpec>& qp_set_specs();

struct ClosedLoopQp {
  OcpQp qp;              // x0 embedded
  OcpQpSolution start;   // the warm start (read when warm is not cold)
  QpWarmStart warm = QpWarmStart::cold;
  std::int64_t solve = 0;  // which solve of the flight (0-based)
};

struct QpSet {
  std::string name;
  RtiSettings rti;  // the solver the loop used: kind, pair levels, IPM settings
  std::vector<ClosedLoopQp> qps;
};

// Up to `count` QPs of the flight, every (solves / count)-th, from the cache when
// MIXPILOT_QP_SETS names one (else flown; then written there). Empty with the reason on failure.
QpSet closed_loop_set(const QpSetSpec& spec, int count, std::string& error);
// The same, kept for the process: each set is made once however many benchmarks use it.
const QpSet& cached_closed_loop_set(const QpSetSpec& spec, int count);

// A QP solver of the kind the loop used, set up for dims.
std::unique_ptr<QpSolver> make_qp_solver(const RtiSettings& rti, const OcpQpDims& dims);

// Median, 90th percentile and maximum of v (sorted in place); zeros for an empty v.
struct Percentiles {
  double median = 0, p90 = 0, worst = 0;
};
Percentiles percentiles(std::vector<double>& v);

}  // namespace mixpilot::bench
