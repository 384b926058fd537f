#pragma once
// The discrete algebraic Riccati equation, one solver for every LQR of the project.
#include <Eigen/Core>

namespace mixpilot {

// Solves AᵀPA − P − AᵀPB (BᵀPB + R)⁻¹ BᵀPA + Q = 0 by the structure-preserving doubling
// algorithm (quadratic convergence). Returns false when it does not converge.
bool solve_dare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                const Eigen::MatrixXd& R, Eigen::MatrixXd& P, int max_iterations = 100);

}  // namespace mixpilot
