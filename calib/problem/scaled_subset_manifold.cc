#include "calib/problem/scaled_subset_manifold.h"

#include "calib/core/error.h"

#include <algorithm>

namespace aerocal::calib {

ScaledSubsetManifold::ScaledSubsetManifold(int size,
                                           std::vector<int> free_entries,
                                           std::vector<double> scales)
    : size_(size), free_(std::move(free_entries)), scales_(std::move(scales)) {}

void ScaledSubsetManifold::SetScales(std::vector<double> scales) {
  AEROCAL_CHECK(scales.size() == free_.size()) << "one scale per free entry";
  scales_ = std::move(scales);
}

bool ScaledSubsetManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  std::copy(x, x + size_, x_plus_delta);
  for (size_t k = 0; k < free_.size(); ++k) x_plus_delta[free_[k]] += scales_[k] * delta[k];
  return true;
}

bool ScaledSubsetManifold::PlusJacobian(const double*, double* jacobian) const {
  const int t = TangentSize();
  std::fill(jacobian, jacobian + size_ * t, 0.0);
  for (int k = 0; k < t; ++k) jacobian[free_[k] * t + k] = scales_[k];
  return true;
}

bool ScaledSubsetManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (size_t k = 0; k < free_.size(); ++k) y_minus_x[k] = (y[free_[k]] - x[free_[k]]) / scales_[k];
  return true;
}

bool ScaledSubsetManifold::MinusJacobian(const double*, double* jacobian) const {
  const int t = TangentSize();
  std::fill(jacobian, jacobian + size_ * t, 0.0);
  for (int k = 0; k < t; ++k) jacobian[k * size_ + free_[k]] = 1.0 / scales_[k];
  return true;
}

}  // namespace aerocal::calib
