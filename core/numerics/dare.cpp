#include "core/numerics/dare.hpp"

#include <algorithm>

#include <Eigen/Dense>

namespace mixpilot {

bool solve_dare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                const Eigen::MatrixXd& R, Eigen::MatrixXd& P, int max_iterations) {
  // Structure-preserving doubling: A_{k+1} = A_k (I + G_k H_k)⁻¹ A_k,
  // G_{k+1} = G_k + A_k (I + G_k H_k)⁻¹ G_k A_kᵀ, H_{k+1} = H_k + A_kᵀ H_k (I + G_k H_k)⁻¹ A_k,
  // from A_0 = A, G_0 = B R⁻¹ Bᵀ, H_0 = Q; H_k → P.
  const int n = int(A.rows());
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd Ak = A, Gk = B * R.ldlt().solve(B.transpose()), Hk = Q;
  for (int it = 0; it < max_iterations; ++it) {
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(I + Gk * Hk);
    const Eigen::MatrixXd W1 = lu.solve(Ak);       // (I + G H)⁻¹ A
    const Eigen::MatrixXd W2 = lu.solve(Gk);       // (I + G H)⁻¹ G
    const Eigen::MatrixXd Hn = Hk + Ak.transpose() * Hk * W1;
    Gk = Gk + Ak * W2 * Ak.transpose();
    Ak = Ak * W1;
    const double change = (Hn - Hk).lpNorm<Eigen::Infinity>();
    Hk = 0.5 * (Hn + Hn.transpose());
    if (!Hk.allFinite()) return false;
    if (change <= 1e-13 * std::max(1.0, Hk.lpNorm<Eigen::Infinity>())) {
      P = Hk;
      return true;
    }
  }
  return false;
}

}  // namespace mixpilot
