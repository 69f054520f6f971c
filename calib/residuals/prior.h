// Weighted prior on selected entries of one parameter block (control-point coordinates, GNSS/IMU
// exterior orientation, a-priori interior sigmas):   r_k = (x[i_k] - x0_k) / sigma_k   [unitless].
// Linear, so the Jacobian is written analytically (rows of the identity scaled by 1/sigma); its
// GradientChecker test is in tests/calib/residuals_test.cc.
#pragma once

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include <memory>
#include <vector>

namespace aerocal::calib {

class PriorCostFunction : public ceres::CostFunction {
 public:
  /// `block_size` entries in the block; `indices`, `values` and `sigmas` (> 0) have equal length.
  PriorCostFunction(int block_size,
                    std::vector<int> indices,
                    std::vector<double> values,
                    std::vector<double> sigmas);
  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// Prior on all entries of a block.
  static std::unique_ptr<ceres::CostFunction> Create(const std::vector<double>& values,
                                                     const std::vector<double>& sigmas);

 private:
  int block_size_;
  std::vector<int> indices_;
  std::vector<double> values_, inverse_sigmas_;
};

/// Linear constraints on several blocks, as pseudo-observations (a datum):
///   r = sum_b W_b (x_b - x0_b) / sigma   [unitless; W_b: rows x size_b, in the blocks' units].
/// Linear, so the Jacobian (W_b / sigma) is written analytically; GradientChecker test in
/// tests/calib/residuals_test.cc.
class LinearConstraintCostFunction : public ceres::CostFunction {
 public:
  /// `weights[b]` (rows x size of block b) and `origins[b]` (size of block b); equal row counts;
  /// sigma > 0.
  LinearConstraintCostFunction(std::vector<Eigen::MatrixXd> weights,
                               std::vector<Eigen::VectorXd> origins,
                               double sigma);
  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

 private:
  std::vector<Eigen::MatrixXd> weights_;  // already divided by sigma
  std::vector<Eigen::VectorXd> origins_;
};

}  // namespace aerocal::calib
