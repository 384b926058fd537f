#pragma once
// The ERK4 state predictor of SPEC §5.2, for any model with fixed-size State and Input: the
// measured state is integrated over the round-trip time with the commands already sent, so the
// controller starts from the state its next command will meet.
//
// Clock. Command m acts over [m·s, (m+1)·s) substeps of h on the controller's clock σ (the time
// a command is sent); before command 0 the vehicle rests. A measurement taken n substeps before
// σ = t_k (the time command k goes out) is x(σ = t_k − n·h); predict() returns x(σ = t_k).
// The horizon n is fixed (the simulated delay of core/modes/tracking_mode.hpp) or given per
// step (an estimated round-trip time, core/control/rtt_estimator.hpp).
//
// setup() allocates; the rest does not.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/numerics/integrator_erk4.hpp"

namespace mixpilot {

template <class Model>
class DelayPredictor {
 public:
  using State = typename Model::State;
  using Input = typename Model::Input;

  // What predict() reads of the commands sent so far (a snapshot of a flight copies it).
  struct Sent {
    std::vector<Input> ring;  // the last commands, indexed k mod size
    long k = 0;               // commands sent so far
  };

  // `rtt_substeps`: the horizon of predict(measured, predicted); `max_substeps` (at least that)
  // the longest horizon ever asked for.
  void setup(const Model& model, int substeps_per_period, double h, int rtt_substeps,
             int max_substeps = 0) {
    erk4_ = IntegratorErk4<Model>(model);
    s_ = std::max(1, substeps_per_period);
    h_ = h;
    n_r_ = std::max(0, rtt_substeps);
    n_max_ = std::max(n_r_, max_substeps);
    sent_.ring.assign(std::size_t((n_max_ + s_ - 1) / s_ + 1), Input::Zero());
    sent_.k = 0;
  }
  // Forgets the sent commands (the next command is k = 0).
  void reset() { sent_.k = 0; }
  // Command u_k was sent (once per period, after predict()).
  void record_sent(const Input& u) {
    sent_.ring[std::size_t(sent_.k % long(sent_.ring.size()))] = u;
    ++sent_.k;
  }
  // x(σ = t_k) from the measurement x(σ = t_k − τ_r), τ_r = rtt_substeps·h.
  void predict(const State& measured, State& predicted) const { predict(measured, predicted, n_r_); }
  // The same over n substeps (clamped to [0, max_substeps]), integrating from max(t_k − n·h, 0)
  // with the command in effect on each substep.
  void predict(const State& measured, State& predicted, int n) const {
    const long end = sent_.k * s_;
    State x = measured, xn;
    const std::vector<Input>& ring = sent_.ring;
    for (long j = std::max(0L, end - long(std::clamp(n, 0, n_max_))); j < end; ++j) {
      const long m = j / s_;  // the command in effect on this substep (m < k)
      erk4_.template step<double>(x, ring[std::size_t(m % long(ring.size()))], h_, xn);
      x = xn;
    }
    predicted = x;
  }
  int rtt_substeps() const { return n_r_; }
  int max_substeps() const { return n_max_; }
  double substep() const { return h_; }
  long commands_sent() const { return sent_.k; }

  // The commands sent, and back: restore() takes those that fit(), of a predictor set up
  // alike (false, changing nothing, for any other). Allocates nothing.
  const Sent& sent() const { return sent_; }
  bool fits(const Sent& sent) const { return sent.ring.size() == sent_.ring.size(); }
  bool restore(const Sent& sent) {
    if (!fits(sent)) return false;
    sent_ = sent;
    return true;
  }

 private:
  IntegratorErk4<Model> erk4_{};
  int s_ = 1;      // substeps per control period
  double h_ = 0;   // substep [s]
  int n_r_ = 0;    // the fixed horizon, substeps
  int n_max_ = 0;  // the longest horizon, substeps
  Sent sent_;
};

}  // namespace mixpilot
