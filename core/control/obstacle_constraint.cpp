#include "core/control/obstacle_constraint.hpp"

namespace mixpilot {

void ObstacleConstraint::eval(const Eigen::Ref<const Eigen::VectorXd>& x,
                              const Eigen::Ref<const Eigen::VectorXd>& /*u*/,
                              const Eigen::Ref<const Eigen::VectorXd>& p,
                              Eigen::Ref<Eigen::VectorXd> g, Eigen::Ref<Eigen::MatrixXd> Gx,
                              Eigen::Ref<Eigen::MatrixXd> Gu) const {
  Gx.setZero();
  Gu.setZero();
  for (int j = 0; j < num_; ++j) {
    const int o = off_ + kParamsPerObstacle * j;
    const Eigen::Vector3d d = x.segment<3>(pos_) - p.segment<3>(o);
    const double clearance = p(o + 3);
    if (form_ == ObstacleForm::squared) {
      g(j) = d.squaredNorm() - clearance * clearance;
      Gx.row(j).segment<3>(pos_) = 2.0 * d.transpose();
    } else {
      const double n = d.norm();
      g(j) = n - clearance;
      // ∇‖d‖ = d/‖d‖; at the centre any unit vector is a subgradient: take +z.
      if (n > 1e-12) {
        Gx.row(j).segment<3>(pos_) = d.transpose() / n;
      } else {
        Gx(j, pos_ + 2) = 1.0;
      }
    }
  }
}

}  // namespace mixpilot
