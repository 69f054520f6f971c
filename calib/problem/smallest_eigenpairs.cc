#include "calib/problem/smallest_eigenpairs.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace aerocal::calib::internal {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

constexpr double kRelativeShift = 1e-10;     // mu / largest eigenvalue
constexpr double kRelativeResidual = 1e-12;  // converged: |M x - theta x| / largest eigenvalue
constexpr int kMaxIterations = 300;
constexpr int kMaxLanczosSteps = 300;

// Fixed pseudo-random start vectors in [-1, 1) (splitmix64 of the entry's index): far from
// orthogonal to any eigenvector, and the same on every run and machine.
Eigen::MatrixXd StartVectors(int n, int columns) {
  Eigen::MatrixXd x(n, columns);
  for (int j = 0; j < columns; ++j)
    for (int i = 0; i < n; ++i) {
      uint64_t z = (static_cast<uint64_t>(j) << 32) + static_cast<uint64_t>(i) + 1;
      z += 0x9e3779b97f4a7c15ULL;
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      z ^= z >> 31;
      x(i, j) = static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
    }
  return x;
}

// An orthonormal basis of the columns of y (Householder QR; columnwise backward stable, so
// columns of very different length, as (M + mu I)^-1 makes them, keep their own precision).
Eigen::MatrixXd Orthonormal(const Eigen::MatrixXd& y) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(y);
  return qr.householderQ() * Eigen::MatrixXd::Identity(y.rows(), y.cols());
}

// The largest eigenvalue: Lanczos with full re-orthogonalisation, until the residual bound of the
// largest Ritz value |beta_k s_k| is below 1e-12 of it (or the Krylov space is invariant).
double LargestEigenvalue(const SparseMatrix& lower) {
  const int n = static_cast<int>(lower.rows());
  const int steps = std::min(n, kMaxLanczosSteps);
  Eigen::MatrixXd v(n, steps);
  Eigen::VectorXd alpha(steps), beta(steps);
  v.col(0) = StartVectors(n, 1).col(0).normalized();
  double largest = 0.0;
  for (int k = 0; k < steps; ++k) {
    Eigen::VectorXd w = lower.selfadjointView<Eigen::Lower>() * v.col(k);
    alpha(k) = v.col(k).dot(w);
    for (int pass = 0; pass < 2; ++pass)
      w -= v.leftCols(k + 1) * (v.leftCols(k + 1).transpose() * w);
    beta(k) = w.norm();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz;
    ritz.computeFromTridiagonal(alpha.head(k + 1), beta.head(k), Eigen::ComputeEigenvectors);
    largest = std::max(ritz.eigenvalues()(k), largest);
    const double bound = beta(k) * std::abs(ritz.eigenvectors()(k, k));
    if (k + 1 == steps || bound <= kRelativeResidual * largest || !(beta(k) > 0)) break;
    v.col(k + 1) = w / beta(k);
  }
  return largest;
}

// LLT of lower + mu I, mu grown by 100 until the factorisation succeeds (at most 4 tries).
bool FactorizeShifted(const SparseMatrix& lower,
                      double largest,
                      Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower>* llt) {
  SparseMatrix identity(lower.rows(), lower.cols());
  identity.setIdentity();
  double mu = kRelativeShift * largest;
  for (int attempt = 0; attempt < 4; ++attempt, mu *= 100.0) {
    llt->compute(lower + mu * identity);
    if (llt->info() == Eigen::Success) return true;
  }
  return false;
}

}  // namespace

SymmetricEigenpairs DenseEigenpairs(const SparseMatrix& lower) {
  SymmetricEigenpairs out;
  const Eigen::MatrixXd m = Eigen::MatrixXd(lower).selfadjointView<Eigen::Lower>();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m);
  if (eig.info() != Eigen::Success) return out;
  out.values = eig.eigenvalues();
  out.vectors = eig.eigenvectors();
  out.largest = out.values.size() ? out.values.maxCoeff() : 0.0;
  out.ok = true;
  return out;
}

SymmetricEigenpairs SmallestEigenpairs(const SparseMatrix& lower, int count, int dense_limit) {
  const int n = static_cast<int>(lower.rows());
  count = std::clamp(count, 0, n);
  const int block = std::min(n, count + std::max(count, 8));
  if (n <= dense_limit || 4 * block > n) {
    SymmetricEigenpairs out = DenseEigenpairs(lower);
    if (!out.ok) return out;
    out.values = out.values.head(count).eval();
    out.vectors = out.vectors.leftCols(count).eval();
    return out;
  }
  SymmetricEigenpairs out;
  out.largest = LargestEigenvalue(lower);
  if (!(out.largest > 0)) return out;
  Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower> llt;
  if (!FactorizeShifted(lower, out.largest, &llt)) return out;
  Eigen::MatrixXd x = Orthonormal(StartVectors(n, block));
  for (int iteration = 1; iteration <= kMaxIterations; ++iteration) {
    Eigen::MatrixXd y = llt.solve(x);
    for (int j = 0; j < block; ++j) y.col(j).normalize();
    x = Orthonormal(y);
    // Rayleigh-Ritz with M: the Ritz pairs of the subspace, ascending.
    Eigen::MatrixXd mx = lower.selfadjointView<Eigen::Lower>() * x;
    const Eigen::MatrixXd h = x.transpose() * mx;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(0.5 * (h + h.transpose()));
    x = x * ritz.eigenvectors();
    mx = mx * ritz.eigenvectors();
    bool converged = true;
    for (int j = 0; j < count && converged; ++j)
      converged =
          (mx.col(j) - ritz.eigenvalues()(j) * x.col(j)).norm() <= kRelativeResidual * out.largest;
    if (converged) {
      out.values = ritz.eigenvalues().head(count);
      out.vectors = x.leftCols(count);
      out.iterations = iteration;
      out.ok = true;
      return out;
    }
  }
  return out;
}

}  // namespace aerocal::calib::internal
