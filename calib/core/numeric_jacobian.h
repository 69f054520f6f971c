// THE central-difference Jacobian of the project (mapping parameter conversions, stitching
// precision), for functions whose autodiff form is not at hand.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace aerocal {

/// d f / d x at x by central differences with step 1e-6 max(1, |x_j|); f maps a parameter vector
/// to an Eigen vector (any fixed or dynamic size). Exact up to rounding for linear f.
template <typename F>
Eigen::MatrixXd NumericJacobian(const F& f, const std::vector<double>& x) {
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd jacobian;
  for (int j = 0; j < n; ++j) {
    const double step = 1e-6 * std::max(1.0, std::abs(x[j]));
    std::vector<double> plus = x, minus = x;
    plus[j] += step;
    minus[j] -= step;
    const Eigen::VectorXd a = f(plus), b = f(minus);
    if (j == 0) jacobian.resize(a.size(), n);
    jacobian.col(j) = (a - b) / (2 * step);
  }
  return jacobian;
}

}  // namespace aerocal
