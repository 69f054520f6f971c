// The smallest eigenpairs of a sparse symmetric positive semi-definite matrix, without a dense
// decomposition: what ProblemBuilder::NullSpace needs (the null space of the Jacobi-scaled reduced
// normal matrix and the 16 smallest eigenvalues beside it), at the cost of a sparse Cholesky
// factorisation and a few dozen solves instead of O(n^3) with every eigenvector.
//
// Method (calib/README.md, "Observation cofactors and covariance"):
// - the largest eigenvalue by Lanczos with full re-orthogonalisation (the reports divide by it):
//   to 1e-12 when it stands apart; within a tight cluster of largest eigenvalues the Ritz value
//   lands on one of them (a path Laplacian of 400 nodes: 1e-7 below the largest);
// - the smallest ones by shift-invert block subspace iteration: X <- orth((M + mu I)^-1 X) with
//   M + mu I factorised once (sparse LLT, AMD ordering), mu = 1e-10 x the largest eigenvalue (a
//   positive semi-definite M whose rounding makes a null eigenvalue slightly negative still
//   factorises; 1e4 above the LLT's backward error at n = 10^4), then Rayleigh-Ritz with M itself
//   (H = X^T M X), so the eigenvalues carry the rounding of M, not of the shift: at or near null
//   they are 1e-16-level noise, as a dense decomposition's are.
// - Converged when every wanted Ritz pair has |M x - theta x| <= 1e-12 x the largest eigenvalue
//   (the eigenvalue then exact to that squared over the gap). A null vector's component along an
//   eigenvector of eigenvalue lambda shrinks by mu / (lambda + mu) per step, 1e-4 or less at the
//   line calibration's threshold 1e-7, so null vectors converge in a few steps; the block holds
//   twice the wanted count (at least 8 more) so that the last wanted one converges too.
// Deterministic: sequential, fixed start vectors, no randomness.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace aerocal::calib::internal {

struct SymmetricEigenpairs {
  bool ok = false;
  Eigen::VectorXd values;   // ascending
  Eigen::MatrixXd vectors;  // n x values.size(), orthonormal columns
  double largest = 0.0;     // the largest eigenvalue of the matrix
  int iterations = 0;       // subspace iterations (0: dense)
};

/// Every eigenpair of the symmetric matrix whose lower triangle is `lower` (dense
/// SelfAdjointEigenSolver): the reference, and the path for small matrices.
SymmetricEigenpairs DenseEigenpairs(const Eigen::SparseMatrix<double>& lower);

/// The `count` smallest eigenpairs (ascending) and the largest eigenvalue of the positive
/// semi-definite matrix whose lower triangle is `lower`. Dense up to `dense_limit` rows (or when
/// the block would be more than a quarter of the matrix); not ok when the iteration does not
/// converge or the shifted matrix cannot be factorised (the caller then decomposes densely).
SymmetricEigenpairs SmallestEigenpairs(const Eigen::SparseMatrix<double>& lower,
                                       int count,
                                       int dense_limit = 200);

}  // namespace aerocal::calib::internal
