// THE median of the project (the block, joint and stitching adjustments' median a-priori sigma).
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

namespace aerocal {

/// The median: the middle value of an odd count, the mean of the two middle values of an even
/// count; NaN (unknown, never 0) for no values.
inline double Median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

}  // namespace aerocal
