// Manifold that keeps some entries of a block fixed and scales the free ones:
//   x + delta = x with x[free_k] += scale_k * delta_k.
// The builder sets scale_k = 1 / (norm of the Jacobian column of entry k), so the tangent-space
// Jacobian has unit columns. This keeps Ceres' covariance (DENSE_SVD / SPARSE_QR, whose rank test
// is a condition number) meaningful when parameters differ by many orders of magnitude
// (K3 in mm^-6 next to ground coordinates in m). The ambient covariance is unchanged by scaling.
#pragma once

#include <ceres/manifold.h>

#include <vector>

namespace aerocal::calib {

class ScaledSubsetManifold : public ceres::Manifold {
 public:
  ScaledSubsetManifold(int size, std::vector<int> free_entries, std::vector<double> scales);
  int AmbientSize() const override { return size_; }
  int TangentSize() const override { return static_cast<int>(free_.size()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
  /// New scales for the same free entries (the builder keeps one manifold per block and rescales
  /// it; Ceres re-reads the Plus Jacobian whenever it sets a block's state).
  void SetScales(std::vector<double> scales);
  const std::vector<int>& free_entries() const { return free_; }

 private:
  int size_;
  std::vector<int> free_;
  std::vector<double> scales_;
};

}  // namespace aerocal::calib
