#include "stitch/matching/local_mapping.h"

#include <Eigen/Dense>

#include <algorithm>
#include <random>

namespace aerocal::stitch {
namespace {

std::vector<int> Inliers(const std::vector<Eigen::Vector2d>& from,
                         const std::vector<Eigen::Vector2d>& to,
                         const LocalAffine& mapping,
                         double threshold_px) {
  std::vector<int> inliers;
  for (int i = 0; i < static_cast<int>(from.size()); ++i)
    if ((to[i] - mapping.Apply(from[i])).norm() < threshold_px) inliers.push_back(i);
  return inliers;
}

}  // namespace

bool FitAffine(const std::vector<Eigen::Vector2d>& from,
               const std::vector<Eigen::Vector2d>& to,
               const std::vector<int>& use,
               LocalAffine* mapping) {
  if (use.size() < 3) return false;
  // Centre on the mean for conditioning; solve [x y 1] p = target per output coordinate.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i : use) mean += from[i];
  mean /= static_cast<double>(use.size());
  Eigen::MatrixXd design(use.size(), 3);
  Eigen::MatrixXd target(use.size(), 2);
  for (int k = 0; k < static_cast<int>(use.size()); ++k) {
    design.row(k) << from[use[k]].x() - mean.x(), from[use[k]].y() - mean.y(), 1.0;
    target.row(k) = to[use[k]].transpose();
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(design);
  if (qr.rank() < 3) return false;
  const Eigen::MatrixXd p = qr.solve(target);  // 3 x 2
  mapping->linear = p.topRows<2>().transpose();
  mapping->offset = p.row(2).transpose() - mapping->linear * mean;
  return mapping->linear.allFinite() && mapping->offset.allFinite();
}

RansacResult RansacAffine(const std::vector<Eigen::Vector2d>& from,
                          const std::vector<Eigen::Vector2d>& to,
                          const RansacOptions& options) {
  RansacResult best;
  const int n = static_cast<int>(from.size());
  if (n < std::max(3, options.min_inliers)) return best;
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int it = 0; it < options.iterations; ++it) {
    std::vector<int> sample;
    while (sample.size() < 3) {
      const int k = pick(rng);
      if (std::find(sample.begin(), sample.end(), k) == sample.end()) sample.push_back(k);
    }
    LocalAffine candidate;
    if (!FitAffine(from, to, sample, &candidate)) continue;
    std::vector<int> inliers = Inliers(from, to, candidate, options.threshold_px);
    if (inliers.size() > best.inliers.size()) {
      best.mapping = candidate;
      best.inliers = std::move(inliers);
    }
  }
  // Refit on the consensus set until it no longer changes (a few rounds at most).
  for (int round = 0; round < 5 && best.inliers.size() >= 3; ++round) {
    LocalAffine refined;
    if (!FitAffine(from, to, best.inliers, &refined)) break;
    std::vector<int> inliers = Inliers(from, to, refined, options.threshold_px);
    best.mapping = refined;
    if (inliers == best.inliers) break;
    best.inliers = std::move(inliers);
  }
  best.ok = static_cast<int>(best.inliers.size()) >= options.min_inliers;
  return best;
}

}  // namespace aerocal::stitch
