// The small dense products of the reduced system (reduced_system.h): blocks of a few rows and
// columns (a residual's 2 rows, a point's 3 tangent entries, an exposure's 3 + 3, the interior's
// 10), where Eigen's dynamic-size expressions cost more in set-up than in arithmetic. Every entry
// is one dot product over the shared dimension in index order, then added once: a fixed order,
// so the same inputs give the same bits. Internal to calib/problem.
#pragma once

namespace aerocal::calib::internal {

namespace kernel_detail {
template <int kRows>
void AddTransposedProductFixed(
    const double* a, const double* b, int m, int n, double sign, double* out) {
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) {
      double dot = 0.0;
      for (int k = 0; k < kRows; ++k) dot += a[k * m + i] * b[k * n + j];
      out[i * n + j] += sign * dot;
    }
}
}  // namespace kernel_detail

/// out (m x n) += sign * a^T b, with a (rows x m) and b (rows x n); all row-major, sign +-1.
inline void AddTransposedProduct(
    const double* a, const double* b, int rows, int m, int n, double sign, double* out) {
  switch (rows) {  // the shapes of the block adjustment, unrolled
    case 2:
      return kernel_detail::AddTransposedProductFixed<2>(a, b, m, n, sign, out);
    case 3:
      return kernel_detail::AddTransposedProductFixed<3>(a, b, m, n, sign, out);
    default:
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < n; ++j) {
          double dot = 0.0;
          for (int k = 0; k < rows; ++k) dot += a[k * m + i] * b[k * n + j];
          out[i * n + j] += sign * dot;
        }
  }
}

/// out (m x n) = a b, with a (m x k) and b (k x n); all row-major.
inline void MultiplyInto(const double* a, const double* b, int m, int k, int n, double* out) {
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) {
      double dot = 0.0;
      for (int l = 0; l < k; ++l) dot += a[i * k + l] * b[l * n + j];
      out[i * n + j] = dot;
    }
}

/// out (rows) -= a x, with a (rows x n) row-major.
inline void SubtractProduct(const double* a, const double* x, int rows, int n, double* out) {
  for (int i = 0; i < rows; ++i) {
    double dot = 0.0;
    for (int k = 0; k < n; ++k) dot += a[i * n + k] * x[k];
    out[i] -= dot;
  }
}

}  // namespace aerocal::calib::internal
