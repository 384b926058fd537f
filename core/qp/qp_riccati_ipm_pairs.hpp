#pragma once
// Partial condensing with block size 2 (HPIPM's ocp_qp_part_cond, Axehill 2015) in front of the
// Riccati IPM: stages (k, k+1) become one stage of the OCP-QP of core/qp/ocp_qp.hpp with state x_k
// and input (u_k, u_{k+1}); x_{k+1} = A_k x_k + B_k u_k + b_k is eliminated. Same problem, same
// solution, half the stages: the Riccati recursion's sequential chains (pivots, vector passes)
// halve while its flops drop (nx = 16, nu = 4: 8.3k → 5.7k FMA per original stage), at the price
// of condensing once per QP (in prepare(), which needs no x0) and of the intermediate stage's
// box bounds becoming general rows.
//
// Block j of stage pair (k, k+1) (k + 1 < N); a last dynamic stage without a partner (odd N) and
// the terminal stage are copied unchanged:
//   x_{k+2} = A1 A0 x + [A1 B0, B1] u + A1 b0 + b1
//   Q = Q0 + A0ᵀQ1A0,  S = [S0 + B0ᵀQ1A0; S1A0],  R = [R0 + B0ᵀQ1B0, (S1B0)ᵀ; S1B0, R1]
//   q = q0 + A0ᵀ(Q1b0 + q1),  r = [r0 + B0ᵀ(Q1b0 + q1); r1 + S1b0]
//   constraints d = [bu_k; bu_{k+1}; bx_k; g_k; bx_{k+1} as rows of A0, B0; C1 x_{k+1} + D1 u_{k+1}]
//   slacks [s_k; s_{k+1}], constant ½b0ᵀQ1b0 + q1ᵀb0 added to the objective
// (0 = stage k, 1 = stage k+1). The solution is expanded back: x_{k+1} from the dynamics, the
// multipliers split, and π_k from the stationarity in x_{k+1}:
//   π_k = Q1 x_{k+1} + S1ᵀu_{k+1} + q1 + A1ᵀπ_{k+1} − ∇_x d_{k+1}ᵀ(λ_l − λ_u)_{k+1}.
//
// `levels` > 1 condenses the condensed QP again (pairs of pairs: blocks of 2^levels stages),
// by a nested QpRiccatiIpmPairs.
//
// setup() sizes everything; prepare(), solve() allocate nothing, never throw or print.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_riccati_ipm.hpp"
#include "core/qp/qp_solver.hpp"

namespace mixpilot {

// The condensed dims of `dims`: one stage per pair (k, k+1) with k + 1 < N, then the lone stages.
OcpQpDims ocp_qp_pair_dims(const OcpQpDims& dims);

class QpRiccatiIpmPairs : public QpSolver {
 public:
  using Settings = QpRiccatiIpmSettings;

  explicit QpRiccatiIpmPairs(int levels = qp_defaults::kPairLevels) { set_levels(levels); }
  explicit QpRiccatiIpmPairs(const OcpQpDims& dims, const Settings& settings = {},
                             int levels = qp_defaults::kPairLevels) {
    set_levels(levels);
    setup(dims, settings);
  }

  // How many times pairs are condensed (≥ 1); takes effect at the next setup().
  void set_levels(int levels) { levels_ = levels < 1 ? 1 : levels; }
  bool setup(const OcpQpDims& dims, const Settings& settings = {}) override;
  // Condenses qp (everything but x0); the next solve() of the same qp reuses it.
  void prepare(const OcpQp& qp) override;
  // ... and hands the restricted warm start to the inner solver's preparation.
  void prepare(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) override;
  QpStatus solve(const OcpQp& qp, OcpQpSolution& sol,
                 QpWarmStart warm = QpWarmStart::cold) override;

  Settings& settings() override { return settings_; }
  const Settings& settings() const override { return settings_; }
  const OcpQpDims& dims() const override { return dims_; }

  const OcpQp& condensed() const { return qpc_; }  // the last condensed QP

 private:
  bool condense(const OcpQp& qp);  // every block into qpc_; false for invalid data
  void condense_pair(const OcpQp& qp, int j);
  void expand(const OcpQp& qp, OcpQpSolution& sol) const;
  void restrict_warm_start(const OcpQpSolution& sol);
  void set_inner_settings();  // settings_ without the data check (done on the original QP)

  int levels_ = qp_defaults::kPairLevels;  // ≥ 1
  Settings settings_{};
  OcpQpDims dims_;
  bool ready_ = false;
  bool prepared_ = false;
  bool restricted_ = false;  // solc_ holds the warm start given to prepare()
  std::vector<int> first_;  // per block: its first original stage
  std::vector<int> count_;  // per block: 1 or 2 stages
  OcpQp qpc_;               // the condensed QP (x0 copied at each solve)
  OcpQpSolution solc_;      // its solution (and warm start)
  std::unique_ptr<QpSolver> inner_;  // QpRiccatiIpm, or QpRiccatiIpmPairs(levels − 1)
  // Condensing workspace, sized for the largest stage.
  Eigen::MatrixXd Q1A0_;  // nx1 x nx0
  Eigen::MatrixXd Q1B0_;  // nx1 x nu0 (same leading dimension as Q1A0_)
  Eigen::MatrixXd BA0t_;  // (nu0 + nx0) x nx1: [B0ᵀ; A0ᵀ]
  Eigen::VectorXd g1_;    // nx1: Q1 b0 + q1 (first the diagonal of a diagonal Q1)
  Eigen::VectorXd x1_;    // nx1: scratch of the expansion
  std::vector<double> constant_;  // per block: ½b0ᵀQ1b0 + q1ᵀb0
};

}  // namespace mixpilot
