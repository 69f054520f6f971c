#include "calib/residuals/prior.h"

#include "calib/core/error.h"

#include <algorithm>

namespace aerocal::calib {

PriorCostFunction::PriorCostFunction(int block_size,
                                     std::vector<int> indices,
                                     std::vector<double> values,
                                     std::vector<double> sigmas)
    : block_size_(block_size), indices_(std::move(indices)), values_(std::move(values)) {
  AEROCAL_CHECK(indices_.size() == values_.size() && values_.size() == sigmas.size())
      << "prior sizes differ";
  for (double s : sigmas) {
    AEROCAL_CHECK(s > 0) << "prior sigma must be > 0, got " << s;
    inverse_sigmas_.push_back(1.0 / s);
  }
  for (int i : indices_) AEROCAL_CHECK(i >= 0 && i < block_size_) << "prior index " << i;
  set_num_residuals(static_cast<int>(indices_.size()));
  mutable_parameter_block_sizes()->push_back(block_size_);
}

bool PriorCostFunction::Evaluate(double const* const* parameters,
                                 double* residuals,
                                 double** jacobians) const {
  const int n = static_cast<int>(indices_.size());
  for (int k = 0; k < n; ++k)
    residuals[k] = (parameters[0][indices_[k]] - values_[k]) * inverse_sigmas_[k];
  if (jacobians && jacobians[0]) {
    std::fill(jacobians[0], jacobians[0] + n * block_size_, 0.0);
    for (int k = 0; k < n; ++k) jacobians[0][k * block_size_ + indices_[k]] = inverse_sigmas_[k];
  }
  return true;
}

std::unique_ptr<ceres::CostFunction> PriorCostFunction::Create(const std::vector<double>& values,
                                                               const std::vector<double>& sigmas) {
  std::vector<int> indices(values.size());
  for (size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
  return std::make_unique<PriorCostFunction>(
      static_cast<int>(values.size()), indices, values, sigmas);
}

LinearConstraintCostFunction::LinearConstraintCostFunction(std::vector<Eigen::MatrixXd> weights,
                                                           std::vector<Eigen::VectorXd> origins,
                                                           double sigma)
    : weights_(std::move(weights)), origins_(std::move(origins)) {
  AEROCAL_CHECK(!weights_.empty() && weights_.size() == origins_.size()) << "constraint blocks";
  AEROCAL_CHECK(sigma > 0) << "constraint sigma must be > 0, got " << sigma;
  for (size_t b = 0; b < weights_.size(); ++b) {
    AEROCAL_CHECK(weights_[b].rows() == weights_[0].rows() &&
                  weights_[b].cols() == origins_[b].size())
        << "constraint block " << b << " sizes";
    weights_[b] /= sigma;
    mutable_parameter_block_sizes()->push_back(static_cast<int>(origins_[b].size()));
  }
  set_num_residuals(static_cast<int>(weights_[0].rows()));
}

bool LinearConstraintCostFunction::Evaluate(double const* const* parameters,
                                            double* residuals,
                                            double** jacobians) const {
  Eigen::Map<Eigen::VectorXd> r(residuals, num_residuals());
  r.setZero();
  for (size_t b = 0; b < weights_.size(); ++b) {
    const Eigen::Map<const Eigen::VectorXd> x(parameters[b], origins_[b].size());
    r += weights_[b] * (x - origins_[b]);
    if (jacobians && jacobians[b])
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[b], weights_[b].rows(), weights_[b].cols()) = weights_[b];
  }
  return true;
}

}  // namespace aerocal::calib
