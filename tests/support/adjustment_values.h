// Every estimated value of an adjustment in one vector, and the largest relative difference of two
// such vectors: for comparing solver paths and thread counts (issue 31).
#pragma once

#include "triangulation/adjustment/adjustment_result.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace aerocal::testing {

/// sigma0, the interiors, the exterior orientations and the points, in a fixed order.
inline std::vector<double> AdjustmentValues(const triangulation::AdjustmentResult& r) {
  std::vector<double> v = {r.sigma0};
  for (const auto& c : r.cameras) v.insert(v.end(), c.estimated.begin(), c.estimated.end());
  for (const auto& e : r.exposures)
    for (int k = 0; k < 3; ++k) v.insert(v.end(), {e.center_m(k), e.opk_rad(k)});
  for (const auto& [id, x] : r.points_m) v.insert(v.end(), {x(0), x(1), x(2)});
  return v;
}

/// max |a_i - b_i| / max(|b_i|, 1); infinity when the sizes differ.
inline double MaxRelativeDifference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i)
    d = std::max(d, std::abs(a[i] - b[i]) / std::max(std::abs(b[i]), 1.0));
  return d;
}

}  // namespace aerocal::testing
