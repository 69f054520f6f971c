// Weighted prior on selected entries of one parameter block (control-point coordinates, GNSS/IMU
// exterior orientation, a-priori interior sigmas):   r_k = (x[i_k] - x0_k) / sigma_k   [unitless].
// Linear, so the Jacobian is written analytically (rows of the identity scaled by 1/sigma); its
// GradientChecker test is in tests/calib/residuals_test.cc.
#pragma once

#include <memory>
#include <vector>

#include <ceres/cost_function.h>

namespace aerocal::calib {

class PriorCostFunction : public ceres::CostFunction {
 public:
  /// `block_size` entries in the block; `indices`, `values` and `sigmas` (> 0) have equal length.
  PriorCostFunction(int block_size, std::vector<int> indices, std::vector<double> values,
                    std::vector<double> sigmas);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// Prior on all entries of a block.
  static std::unique_ptr<ceres::CostFunction> Create(const std::vector<double>& values,
                                                     const std::vector<double>& sigmas);

 private:
  int block_size_;
  std::vector<int> indices_;
  std::vector<double> values_, inverse_sigmas_;
};

}  // namespace aerocal::calib
