#pragma once
// The optimal control problem of SPEC §4, independent of the solver (RTI, SQP, Ipopt):
//
//   min  Σ_{i<N} ½‖y(x_i,u_i,p_i) − ỹ_i‖²_{W_i} + ½‖y_N(x_N,p_N) − ỹ_N‖²_{W_N} + slack penalties
//   s.t. x_0 = x̄_0,  x_{i+1} = F(x_i, u_i)                     (one ERK4 step of Δt)
//        lbu ≤ u_i[idxbu] ≤ ubu                    (i = 0..N−1)
//        lbx ≤ x_i[idxbx] ≤ ubx                    (i = 1..N)
//        lg  ≤ g(x_i, u_i, p_i) ≤ ug               (i = 1..N; u is empty at i = N)
//
// Path constraints start at stage 1: with x_0 fixed, a constraint on x_0 alone is a constant.
// Any state bound or path constraint can be made soft: slacks s_l, s_u ≥ 0 relax its lower and
// upper side, with cost ½ Z s² + z s per side (ℓ2² and exact ℓ1 penalties).
//
// What is fixed for the lifetime of a solver lives in Ocp; what changes every step (references,
// weights, parameters) lives in OcpStageData, owned by the caller or the solver.
#include <vector>

#include <Eigen/Core>

#include "core/numerics/integrator.hpp"

namespace mixpilot {

// A least-squares output y(x, u, p) (ny) with its Jacobians.
class OutputFunction {
 public:
  virtual ~OutputFunction() = default;
  virtual int ny() const = 0;

  // y (ny); Jx (ny x nx) = ∂y/∂x; Ju (ny x nu) = ∂y/∂u. At the terminal stage u has size 0.
  virtual void eval(const Eigen::Ref<const Eigen::VectorXd>& x,
                    const Eigen::Ref<const Eigen::VectorXd>& u,
                    const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> y,
                    Eigen::Ref<Eigen::MatrixXd> Jx, Eigen::Ref<Eigen::MatrixXd> Ju) const = 0;
};

// y = (x[state_index], u[input_index]): every output in SPEC §5 is such a selection, so the
// Gauss-Newton blocks are a scatter of W (O(ny²) per stage, no products).
class SelectionOutput final : public OutputFunction {
 public:
  SelectionOutput() = default;
  SelectionOutput(Eigen::VectorXi state_index, Eigen::VectorXi input_index)
      : state_index_(std::move(state_index)), input_index_(std::move(input_index)) {}

  int ny() const override { return int(state_index_.size() + input_index_.size()); }
  const Eigen::VectorXi& state_index() const { return state_index_; }  // ny_x
  const Eigen::VectorXi& input_index() const { return input_index_; }  // ny_u

  void eval(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& u,
            const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> y,
            Eigen::Ref<Eigen::MatrixXd> Jx, Eigen::Ref<Eigen::MatrixXd> Ju) const override;

 private:
  Eigen::VectorXi state_index_;
  Eigen::VectorXi input_index_;
};

// A vector of path constraints g(x, u, p) (ng) with its Jacobians.
class PathConstraint {
 public:
  virtual ~PathConstraint() = default;
  virtual int ng() const = 0;

  // g (ng); Gx (ng x nx); Gu (ng x nu). At the terminal stage u has size 0 (and so has Gu).
  virtual void eval(const Eigen::Ref<const Eigen::VectorXd>& x,
                    const Eigen::Ref<const Eigen::VectorXd>& u,
                    const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> g,
                    Eigen::Ref<Eigen::MatrixXd> Gx, Eigen::Ref<Eigen::MatrixXd> Gu) const = 0;
};

// Softening of one state bound or path constraint (index into idxbx or into g).
struct SoftConstraint {
  int index = 0;
  double Zl = 0.0;  // ℓ2² weight of the lower-side slack
  double Zu = 0.0;  // ℓ2² weight of the upper-side slack
  double zl = 0.0;  // ℓ1 weight of the lower-side slack
  double zu = 0.0;  // ℓ1 weight of the upper-side slack
};

struct Ocp {
  const Integrator* integrator = nullptr;  // F and its sensitivities; fixes nx, nu
  int N = 0;                               // shooting intervals
  double dt = 0.0;                         // interval length [s]
  int np = 0;                              // parameters per stage

  const OutputFunction* output = nullptr;           // y(x, u, p), stages 0..N−1
  const OutputFunction* terminal_output = nullptr;  // y_N(x, p), stage N (called with empty u)

  Eigen::VectorXi idxbu;  // nbu: bounded input components
  Eigen::VectorXd lbu;    // nbu
  Eigen::VectorXd ubu;    // nbu
  Eigen::VectorXi idxbx;  // nbx: bounded state components (stages 1..N)
  Eigen::VectorXd lbx;    // nbx
  Eigen::VectorXd ubx;    // nbx

  const PathConstraint* constraint = nullptr;  // g(x, u, p), stages 1..N; may be null
  Eigen::VectorXd lg;                          // ng
  Eigen::VectorXd ug;                          // ng

  std::vector<SoftConstraint> soft_state_bounds;  // indices into idxbx
  std::vector<SoftConstraint> soft_constraints;   // indices into g

  int nx() const { return integrator ? integrator->nx() : 0; }
  int nu() const { return integrator ? integrator->nu() : 0; }
  int ny() const { return output ? output->ny() : 0; }
  int ny_terminal() const { return terminal_output ? terminal_output->ny() : 0; }
  int ng() const { return constraint ? constraint->ng() : 0; }

  // Empty when the description is complete and consistent; otherwise what is wrong.
  const char* check() const;
};

// Per-stage data that changes from one control step to the next.
struct OcpStageData {
  std::vector<Eigen::VectorXd> yref;  // N+1: ỹ_i (ny; ny_N at i = N)
  std::vector<Eigen::MatrixXd> W;     // N+1: W_i (ny x ny; ny_N x ny_N at i = N), symmetric ≥ 0
  std::vector<Eigen::VectorXd> p;     // N+1: p_i (np)

  OcpStageData() = default;
  explicit OcpStageData(const Ocp& ocp) { resize(ocp); }
  void resize(const Ocp& ocp);  // zero references and weights, zero parameters
};

// Trajectories x_0..x_N (nx each) and u_0..u_{N−1} (nu each).
struct OcpTrajectory {
  std::vector<Eigen::VectorXd> x;  // N+1 x nx
  std::vector<Eigen::VectorXd> u;  // N x nu

  OcpTrajectory() = default;
  explicit OcpTrajectory(const Ocp& ocp) { resize(ocp); }
  void resize(const Ocp& ocp);
};

}  // namespace mixpilot
