#pragma once
// Spherical obstacle clearance (SPEC §5.3). Obstacle j reads its centre o_j and clearance d_j
// (obstacle radius plus vehicle radius) from the stage parameters p[off + 4j .. off + 4j + 4]:
//   lcl:      g_j = ‖p − o_j‖₂  − d_j   ≥ 0   (least-conservative linearized form)
//   squared:  g_j = ‖p − o_j‖₂² − d_j²  ≥ 0   (the usual smooth baseline)
// Under one linearization per step, the lcl half-space contains the squared one (Proposition 1),
// so RTI is less conservative with lcl; converged, both describe the same feasible set.
// Use with lg = 0, ug = +∞ (≥ 1e20).
#include "core/nlp/ocp.hpp"

namespace mixpilot {

enum class ObstacleForm { lcl, squared };

class ObstacleConstraint final : public PathConstraint {
 public:
  static constexpr int kParamsPerObstacle = 4;  // centre (3), clearance

  // position_index: first of the three position components in x.
  ObstacleConstraint(int num_obstacles, ObstacleForm form, int position_index = 0,
                     int param_offset = 0)
      : num_(num_obstacles), form_(form), pos_(position_index), off_(param_offset) {}

  int ng() const override { return num_; }
  ObstacleForm form() const { return form_; }

  void eval(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& u,
            const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> g,
            Eigen::Ref<Eigen::MatrixXd> Gx, Eigen::Ref<Eigen::MatrixXd> Gu) const override;

 private:
  int num_;
  ObstacleForm form_;
  int pos_;
  int off_;
};

}  // namespace mixpilot
