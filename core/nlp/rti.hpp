#pragma once
// Real-time iteration NMPC (SPEC §4, thesis Algorithm 1) on an Ocp, with the Riccati IPM or
// condensing + a dense IPM as QP solver (RtiSettings::qp_solver). The QP is posed in the step
// (Δx, Δu) around the current trajectory (x̄, ū):
//
//   min Σ ½ [Δx;Δu]ᵀ [JxᵀWJx JxᵀWJu; JuᵀWJx JuᵀWJu] [Δx;Δu] + (JᵀW r)ᵀ[Δx;Δu]   (Gauss-Newton)
//   s.t. Δx_0 = x̄_0 − x_0,  Δx_{i+1} = A_i Δx_i + B_i Δu_i + (F(x_i,u_i) − x_{i+1}),
//        bounds and linearized path constraints shifted by the current values,
//
// with r = y(x_i,u_i,p_i) − ỹ_i. Phases, as in acados:
//   prepare()       integrate with sensitivities and build every QP block; needs no x̄_0;
//   feedback(x̄_0)   embed x̄_0, solve one QP, take the full step, expose u_0;
//   shift()         move the trajectory one stage for the next warm start (last stage doubled).
// sqp() iterates prepare/feedback to convergence (tests and "fully converged" baselines).
//
// Failure policy (SPEC §4, thesis ch. 7.5.4): if the linearization is not finite or the QP
// fails, the trajectory is left as it was (already shifted by the previous step) and its u_0 —
// the previous solution's next input — is applied; the event is reported in the statistics.
// control() never holds NaN.
//
// setup() sizes everything; prepare(), feedback() and shift() allocate nothing.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/nlp/ocp.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_condensed_dense.hpp"
#include "core/qp/qp_riccati_ipm.hpp"
#include "core/qp/qp_riccati_ipm_pairs.hpp"
#include "core/qp/qp_solver.hpp"
#include "core/numerics/types.hpp"

namespace mixpilot {

struct RtiSettings {
  QpRiccatiIpmSettings qp{};
  // Primal-dual warm start of the QP from the previous (shifted) QP solution.
  bool qp_warm_start = rti_defaults::kQpWarmStart;
  // QP solver variant; condensed_* condense the Hessian in prepare() (no x̄_0 needed).
  QpSolverKind qp_solver = rti_defaults::kQpSolver;
  // riccati_ipm_pairs: how many times stage pairs are condensed (blocks of 2^levels stages).
  int qp_pair_levels = rti_defaults::kQpPairLevels;
};

enum class RtiStatus {
  success,
  fallback,      // QP failed or linearization not finite: previous solution's input applied
  not_prepared,  // feedback() without a prepare() since the last feedback
  invalid,       // setup() failed, or x̄_0 has the wrong size or is not finite
};

const char* to_string(RtiStatus status);

// Statistics of the last control step (prepare + feedback).
struct RtiStats {
  RtiStatus status = RtiStatus::not_prepared;
  QpStatus qp_status = QpStatus::invalid_data;
  int qp_iterations = 0;
  bool linearization_finite = true;
  double integration_us = 0.0;    // ERK4 with sensitivities, all stages
  double linearization_us = 0.0;  // Gauss-Newton blocks, bounds, path constraints
  double qp_us = 0.0;             // QP solve
  double total_us = 0.0;          // prepare + feedback
  std::int64_t fallbacks = 0;     // running count since setup()
  // The solve overran its deadline (or was told to): its step was discarded and the previous
  // solution's next input applied (status fallback, SPEC §4).
  bool overrun = false;
};

struct SqpResult {
  bool converged = false;
  int iterations = 0;
  double step_norm = 0.0;  // ‖(Δx, Δu)‖∞ of the last step
  QpStatus qp_status = QpStatus::invalid_data;
};

// What the next control step reads of the previous ones: the state of an RTI solver, as a
// plain value (a snapshot of a flight copies it, core/modes/mode.hpp). The QP data, the QP
// solvers' workspaces and the preparation buffers are not in it: prepare() rebuilds them from
// the trajectory and the stage data, which every owner sets whole before each prepare() (its
// constant parts at setup). Copying it into a state of the same OCP allocates nothing.
struct RtiState {
  OcpTrajectory trajectory;   // the linearization point, shifted: the next step's warm start
  OcpQpSolution qp_solution;  // the last QP's iterates and multipliers, shifted: its warm start
  RtiStats stats{};           // the last step's (fallbacks counted since setup())
  bool prepared = false;      // prepare() ran since the last feedback()
  bool have_qp_solution = false;  // qp_solution holds a solution to warm-start from
  bool force_overrun = false;     // the next feedback() is an overrun (force_overrun_next())
};

// Sees every QP the feedback phase solves, with the warm start it is solved from: what the
// closed-loop QP sets of mixpilot-bench are made of (docs/qp-dump-format.md). Called on the
// control thread right before the solve, so an observer that copies (allocates) is for tools,
// never for a paced flight.
class RtiQpObserver {
 public:
  virtual ~RtiQpObserver() = default;
  // qp with x0 embedded; start the solution the solve starts from (read only when warm is not
  // cold).
  virtual void on_qp(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) = 0;
};

// Buffers of the preparation phase.
struct RtiWorkspace {
  Eigen::VectorXd x_next;  // nx: F(x_i, u_i)
  Eigen::VectorXd y;       // max(ny, ny_N): output value
  Eigen::MatrixXd Jx;      // max(ny, ny_N) x nx
  Eigen::MatrixXd Ju;      // max(ny, ny_N) x nu
  Eigen::MatrixXd WJ;      // max(ny, ny_N) x (nx + nu): W [Jx Ju]
  Eigen::VectorXd res;     // max(ny, ny_N): y − ỹ
  Eigen::VectorXd g;       // ng: path constraint value
  Eigen::VectorXd empty;   // size 0: the input at the terminal stage
  Eigen::MatrixXd empty_Gu;  // ng x 0
  Eigen::MatrixXd empty_Ju;  // ny_N x 0
};

class RtiSolver {
 public:
  using Settings = RtiSettings;

  RtiSolver() = default;

  // Sizes everything for ocp (which must outlive the solver). Fails with the reason when
  // ocp.check() reports a problem or the QP solver cannot be sized; then every other call
  // returns RtiStatus::invalid.
  SetupResult setup(const Ocp& ocp, const Settings& settings = {});

  const Settings& settings() const { return settings_; }

  // References, weights and parameters per stage: set them before prepare().
  OcpStageData& data() { return data_; }
  const OcpStageData& data() const { return data_; }
  // The linearization point: initialize it (e.g. hover) before the first prepare().
  OcpTrajectory& trajectory() { return state_.trajectory; }
  const OcpTrajectory& trajectory() const { return state_.trajectory; }

  RtiStatus prepare();
  RtiStatus feedback(const Eigen::Ref<const Eigen::VectorXd>& x0);
  void shift();

  // SPEC §4: a control step whose prepare + feedback time exceeds `deadline_us` (0: none, the
  // default, for runs not paced by a clock) is discarded after its QP, as when the QP fails.
  void set_deadline_us(double deadline_us) { deadline_us_ = deadline_us; }
  // The next feedback() is an overrun whatever its time: a replay reproduces a recorded one.
  void force_overrun_next() { state_.force_overrun = true; }

  // Every QP of a feedback phase goes to `observer` (null: none, the default) before it is
  // solved. The observer outlives the solver or is reset to null first.
  void set_qp_observer(RtiQpObserver* observer) { observer_ = observer; }

  // Iterates prepare/feedback from the current trajectory until ‖(Δx, Δu)‖∞ ≤ tol.
  SqpResult sqp(const Eigen::Ref<const Eigen::VectorXd>& x0, int max_iterations, double tol);

  const Eigen::VectorXd& control() const { return state_.trajectory.u[0]; }  // u_0 (nu)
  const RtiStats& stats() const { return state_.stats; }
  const OcpQp& qp() const { return qp_; }
  const OcpQpSolution& qp_solution() const { return state_.qp_solution; }
  const Ocp* ocp() const { return ocp_; }

  // The solver's state (RtiState), and back: restore() continues from a state that fits(),
  // one of a solver set up for the same OCP (false, changing nothing, for any other).
  // Allocates nothing.
  const RtiState& state() const { return state_; }
  bool fits(const RtiState& state) const;
  bool restore(const RtiState& state);

 private:
  // How the next QP starts: from the previous (shifted) solution when there is one.
  QpWarmStart warm_start() const {
    return settings_.qp_warm_start && state_.have_qp_solution ? QpWarmStart::primal_dual
                                                              : QpWarmStart::cold;
  }
  void linearize_cost(int i);
  void linearize_constraints(int i);

  const Ocp* ocp_ = nullptr;
  Settings settings_{};
  OcpStageData data_;
  RtiState state_;
  OcpQp qp_;
  QpSolver& qp_solver() {
    switch (settings_.qp_solver) {
      case QpSolverKind::riccati_ipm: return qp_riccati_;
      case QpSolverKind::riccati_ipm_pairs: return qp_pairs_;
      default: return qp_dense_;
    }
  }
  QpRiccatiIpm qp_riccati_;    // set up when settings.qp_solver == riccati_ipm
  QpRiccatiIpmPairs qp_pairs_;  // set up when settings.qp_solver == riccati_ipm_pairs
  QpCondensedDense qp_dense_;  // set up when settings.qp_solver is condensed_*
  RtiWorkspace ws_;
  const SelectionOutput* selection_output_ = nullptr;    // fast Gauss-Newton path, or null
  const SelectionOutput* selection_terminal_ = nullptr;  // likewise for the terminal output
  Eigen::VectorXi z_index_;           // ny: index in z = (x, u) of each selected output
  Eigen::VectorXi terminal_z_index_;  // ny_N
  double deadline_us_ = 0.0;
  RtiQpObserver* observer_ = nullptr;
};

}  // namespace mixpilot
