#include "stitch/quality/bar_target.h"

#include "calib/core/error.h"
#include "stitch/quality/limiting_frequency.h"

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {
namespace {

bool Inside(const GrayImage& image, const PixelRegion& r) {
  return r.col >= 0 && r.row >= 0 && r.width > 0 && r.height > 0 &&
         r.col + r.width <= image.cols() && r.row + r.height <= image.rows();
}

double Linear(float dn, double gamma) {
  const double v = std::max(0.0, static_cast<double>(dn));
  return gamma == 1.0 ? v : std::pow(v, gamma);
}

double RegionMean(const GrayImage& image, const PixelRegion& r, double gamma) {
  double sum = 0.0;
  for (int row = r.row; row < r.row + r.height; ++row)
    for (int col = r.col; col < r.col + r.width; ++col) sum += Linear(image(row, col), gamma);
  return sum / (static_cast<double>(r.width) * r.height);
}

// The linearised grey values averaged along the bars: one value per position across them.
std::vector<double> Profile(const GrayImage& image, const BarGroup& g, double gamma) {
  const PixelRegion& r = g.region;
  const bool across_cols = g.axis == MtfAxis::kX;
  const int length = across_cols ? r.width : r.height, along = across_cols ? r.height : r.width;
  std::vector<double> profile(length, 0.0);
  for (int i = 0; i < length; ++i) {
    for (int j = 0; j < along; ++j)
      profile[i] += across_cols ? Linear(image(r.row + j, r.col + i), gamma)
                                : Linear(image(r.row + i, r.col + j), gamma);
    profile[i] /= along;
  }
  return profile;
}

std::string GroupText(const BarGroup& g) {
  return "bar group at " + std::to_string(g.frequency_cy_px) + " cycles/px";
}

}  // namespace

void BarTargetOptions::Validate() const {
  if (!(gamma > 0.0 && gamma <= 10.0))
    throw ConfigError("gamma must be within (0, 10] (got " + std::to_string(gamma) + ")");
  if (!(threshold > 0.0 && threshold < 1.0))
    throw ConfigError("threshold must be within (0, 1) (got " + std::to_string(threshold) + ")");
}

BarTargetResult MeasureBarTarget(const GrayImage& image,
                                 const std::vector<BarGroup>& groups,
                                 const PixelRegion& bright,
                                 const PixelRegion& dark,
                                 const BarTargetOptions& options) {
  options.Validate();
  if (!Inside(image, bright))
    throw InputError("bright reference region: must lie inside the image");
  if (!Inside(image, dark)) throw InputError("dark reference region: must lie inside the image");
  BarTargetResult result;
  const double b = RegionMean(image, bright, options.gamma),
               d = RegionMean(image, dark, options.gamma);
  if (!(b > d && b + d > 0.0))
    throw InputError("reference regions: the bright one (" + std::to_string(b) +
                     ") must be brighter than the dark one (" + std::to_string(d) + ")");
  result.reference_modulation = (b - d) / (b + d);

  for (const BarGroup& g : groups) {
    if (!(g.frequency_cy_px > 0.0 && g.frequency_cy_px <= 0.5))
      throw InputError(GroupText(g) + ": the frequency must be within (0, 0.5] cycles/px");
    if (!Inside(image, g.region))
      throw InputError(GroupText(g) + ": the region must lie inside the image");
    const std::vector<double> profile = Profile(image, g, options.gamma);
    const double period = 1.0 / g.frequency_cy_px;
    const int windows = static_cast<int>(std::floor(profile.size() / period));
    if (windows < 2 || (g.axis == MtfAxis::kX ? g.region.height : g.region.width) < 4)
      throw InputError(GroupText(g) +
                       ": the region must hold two periods across and 4 px along the bars");
    double max_sum = 0.0, min_sum = 0.0;
    for (int w = 0; w < windows; ++w) {
      const int begin = static_cast<int>(std::floor(w * period));
      const int end = std::min<int>(profile.size(), static_cast<int>(std::floor((w + 1) * period)));
      const auto [lo, hi] = std::minmax_element(profile.begin() + begin, profile.begin() + end);
      max_sum += *hi;
      min_sum += *lo;
    }
    const double i_max = max_sum / windows, i_min = min_sum / windows;
    BarGroupModulation m;
    m.frequency_cy_px = g.frequency_cy_px;
    m.modulation = (i_max - i_min) / (i_max + i_min);
    m.contrast_transfer = m.modulation / result.reference_modulation;
    result.groups.push_back(m);
  }
  std::sort(result.groups.begin(), result.groups.end(), [](const auto& a, const auto& b) {
    return a.frequency_cy_px < b.frequency_cy_px;
  });

  const LimitingFrequency limit = FindLimitingFrequencyOf(result.groups, options.threshold);
  result.limiting_frequency_cy_px = limit.frequency_cy_px;
  result.limit_in_range = limit.in_range;
  return result;
}

}  // namespace aerocal::stitch
