// The small dense products of the reduced system (reduced_system.h): blocks of a few rows and
// columns (a residual's 2 rows, a point's 3 tangent entries, an exposure's 3 + 3, the interior's
// 10), where Eigen's dynamic-size expressions cost more in set-up than in arithmetic. Every entry
// is one dot product over the shared dimension in index order, then added once: a fixed order,
// so the same inputs give the same bits. Internal to calib/problem.
#pragma once

namespace aerocal::calib::internal {

namespace kernel_detail {
// The generic loop; kRows, kM, kN > 0 fix the sizes at compile time (the loops unrolled and the
// cells addressed by constants), 0 takes the runtime ones. The same operations in the same order
// either way: the same bits.
template <int kRows, int kM, int kN>
void AddTransposedProductSized(
    const double* a, const double* b, int rows, int m, int n, double sign, double* out) {
  if constexpr (kRows > 0) rows = kRows;
  if constexpr (kM > 0) m = kM;
  if constexpr (kN > 0) n = kN;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) {
      double dot = 0.0;
      for (int k = 0; k < rows; ++k) dot += a[k * m + i] * b[k * n + j];
      out[i * n + j] += sign * dot;
    }
}

// The column count n of the block adjustment's shapes: 1 (a vector), 3 (a point, a rotation, a
// centre), 10 (the 10-parameter interior).
template <int kRows, int kM>
void DispatchColumns(
    const double* a, const double* b, int rows, int m, int n, double sign, double* out) {
  switch (n) {
    case 1:
      return AddTransposedProductSized<kRows, kM, 1>(a, b, rows, m, n, sign, out);
    case 3:
      return AddTransposedProductSized<kRows, kM, 3>(a, b, rows, m, n, sign, out);
    case 10:
      return AddTransposedProductSized<kRows, kM, 10>(a, b, rows, m, n, sign, out);
    default:
      return AddTransposedProductSized<kRows, kM, 0>(a, b, rows, m, n, sign, out);
  }
}

template <int kRows>
void DispatchRows(
    const double* a, const double* b, int rows, int m, int n, double sign, double* out) {
  switch (m) {
    case 3:
      return DispatchColumns<kRows, 3>(a, b, rows, m, n, sign, out);
    case 10:
      return DispatchColumns<kRows, 10>(a, b, rows, m, n, sign, out);
    default:
      return DispatchColumns<kRows, 0>(a, b, rows, m, n, sign, out);
  }
}
}  // namespace kernel_detail

/// out (m x n) += sign * a^T b, with a (rows x m) and b (rows x n); all row-major, sign +-1.
inline void AddTransposedProduct(
    const double* a, const double* b, int rows, int m, int n, double sign, double* out) {
  switch (rows) {  // the shapes of the block adjustment (2: a ray, 3: a point), unrolled
    case 2:
      return kernel_detail::DispatchRows<2>(a, b, rows, m, n, sign, out);
    case 3:
      return kernel_detail::DispatchRows<3>(a, b, rows, m, n, sign, out);
    default:
      return kernel_detail::AddTransposedProductSized<0, 0, 0>(a, b, rows, m, n, sign, out);
  }
}

/// AddTransposedProduct with the shared dimension and the column count of a fixed at compile time
/// (kRows, kM > 0; 0 takes the runtime value), for a caller that runs many products of one shape
/// (a row of S, a point's pairs): one switch on n per product instead of three size switches and
/// two calls. The same operations in the same order: the same bits.
template <int kRows, int kM>
inline void AddTransposedProductOf(
    const double* a, const double* b, int rows, int m, int n, double sign, double* out) {
  kernel_detail::DispatchColumns<kRows, kM>(a, b, rows, m, n, sign, out);
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
