// The limiting frequency of a resolution target read at a modulation threshold (bar_target.h,
// siemens_star.h): where the contrast transfer, measured at increasing frequencies, first falls
// below the threshold, linear in log(frequency) between the last sample at or above it and the
// first below.
#pragma once

#include <vector>

namespace aerocal::stitch {

struct LimitingFrequency {
  /// cycles/px; NaN when the lowest frequency is already below the threshold; the highest
  /// frequency with in_range = false when none falls below it (the limit lies beyond the samples).
  double frequency_cy_px = 0.0;
  bool in_range = true;
};

/// `frequencies` increasing (cycles/px, > 0) with their `contrast_transfer`, the same size.
LimitingFrequency FindLimitingFrequency(const std::vector<double>& frequencies,
                                        const std::vector<double>& contrast_transfer,
                                        double threshold);

/// The same over rows with members frequency_cy_px and contrast_transfer (increasing frequency).
template <typename Rows>
LimitingFrequency FindLimitingFrequencyOf(const Rows& rows, double threshold) {
  std::vector<double> f, ct;
  for (const auto& row : rows) {
    f.push_back(row.frequency_cy_px);
    ct.push_back(row.contrast_transfer);
  }
  return FindLimitingFrequency(f, ct, threshold);
}

}  // namespace aerocal::stitch
