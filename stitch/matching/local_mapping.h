// Geometric verification of candidate matches: RANSAC (Fischler & Bolles 1981) on the local
// mapping between two sub-images inside one overlap strip. Between two affine sub-image mappings
// the mapping b <- a is itself affine, uv_b = M uv_a + m, so minimal samples are 3 matches; the
// winner is refitted by least squares on its inliers (and the inliers recounted). Seeded, hence
// deterministic.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace aerocal::stitch {

struct LocalAffine {
  Eigen::Matrix2d linear = Eigen::Matrix2d::Identity();
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  Eigen::Vector2d Apply(const Eigen::Vector2d& uv) const { return linear * uv + offset; }
};

struct RansacOptions {
  double threshold_px = 2.0;  // inlier when |uv_b - F(uv_a)| < this, px, > 0
  int iterations = 500;       // random minimal samples, >= 1
  int min_inliers = 6;        // fewer: no mapping (strip rejected), >= 3
  std::uint64_t seed = 7;
};

struct RansacResult {
  bool ok = false;
  LocalAffine mapping;
  std::vector<int> inliers;  // indices into the input, ascending
};

/// Least-squares affine from >= 3 correspondences (false when degenerate).
bool FitAffine(const std::vector<Eigen::Vector2d>& from,
               const std::vector<Eigen::Vector2d>& to,
               const std::vector<int>& use,
               LocalAffine* mapping);

RansacResult RansacAffine(const std::vector<Eigen::Vector2d>& from,
                          const std::vector<Eigen::Vector2d>& to,
                          const RansacOptions& options);

}  // namespace aerocal::stitch
