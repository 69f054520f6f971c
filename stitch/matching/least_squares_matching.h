// Least-squares matching (Gruen 1985; Ackermann 1984): refines a tie point to sub-pixel position.
// A square template around an integer pixel p_a of image a is matched into image b with an affine
// patch model and a radiometric gain/offset:
//   g_a(p_a + x) = r0 + r1 g_b(t + A x),   x in [-h, h]^2 (integer template offsets, px)
// 8 unknowns: t (2, image b px), A (2x2), r0 (DN), r1. Gauss-Newton on the 8x8 normal equations;
// g_b and its gradient come from the same bicubic (Keys, a = -0.5) interpolant, so the Jacobian is
// exact. Precision: sigma0^2 = v^T v / (n - 8), Cov(t) = sigma0^2 (N^-1)_tt.
#pragma once

#include "stitch/image_io/gray_image.h"

#include <Eigen/Core>

namespace aerocal::stitch {

struct LsmOptions {
  int half_size_px = 10;         // h: template is (2h+1)^2 px, >= 3
  int max_iterations = 30;       // Gauss-Newton steps, >= 1
  double convergence_px = 1e-3;  // stop when the shift update is below this, px
  double max_shift_px = 3.0;     // reject when t moves farther than this from its start, px
  double max_sigma_px = 0.2;     // reject when the position sigma (larger axis) exceeds this, px
  double min_correlation = 0.7;  // reject below this template/patch correlation after the fit
  void Validate() const;         // throws ConfigError naming the field
};

enum class LsmStatus { kConverged, kNotConverged, kOutside, kPoorPrecision, kLowCorrelation };

struct LsmResult {
  LsmStatus status = LsmStatus::kNotConverged;
  Eigen::Vector2d position_in_b = Eigen::Vector2d::Zero();  // t, image b px
  Eigen::Matrix2d cov_px2 = Eigen::Matrix2d::Zero();        // covariance of t, px^2
  double sigma0_dn = 0;                                     // grey-value residual RMS, DN
  double correlation = 0;  // correlation of template and fitted patch
  double gain = 1, offset = 0;
  int iterations = 0;
  bool ok() const { return status == LsmStatus::kConverged; }
  /// Position precision of the larger error-ellipse axis, px.
  double SigmaMaxPx() const;
};

/// Matches the template of `a` centred on integer pixel `p_a` into `b`, starting at `t0` (b px)
/// with linear part `a0` (image-b offsets per image-a offset). The template must lie inside `a`.
LsmResult MatchLeastSquares(const GrayImage& a,
                            const Eigen::Vector2i& p_a,
                            const GrayImage& b,
                            const Eigen::Vector2d& t0,
                            const Eigen::Matrix2d& a0,
                            const LsmOptions& options);

}  // namespace aerocal::stitch
