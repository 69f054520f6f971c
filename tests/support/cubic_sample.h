// The tests' own Keys cubic convolution (a = -0.5) of a raster at a real position, edge samples
// repeated: independent of the library's resampler, it renders "photographed" test images.
#pragma once

#include "stitch/resample/raster.h"

#include <algorithm>
#include <cmath>

namespace aerocal::testing {

inline double SampleCubic(const stitch::MemoryRaster& image, double x, double y, int band = 0) {
  auto weight = [](double t) {
    t = std::abs(t);
    if (t < 1) return 1.5 * t * t * t - 2.5 * t * t + 1;
    if (t < 2) return -0.5 * t * t * t + 2.5 * t * t - 4 * t + 2;
    return 0.0;
  };
  const int ix = static_cast<int>(std::floor(x)), iy = static_cast<int>(std::floor(y));
  const stitch::RasterInfo info = image.Info();
  double sum = 0;
  for (int r = -1; r <= 2; ++r)
    for (int c = -1; c <= 2; ++c) {
      const int col = std::clamp(ix + c, 0, info.width - 1),
                row = std::clamp(iy + r, 0, info.height - 1);
      sum += weight(x - (ix + c)) * weight(y - (iy + r)) * image.At(col, row, band);
    }
  return sum;
}

}  // namespace aerocal::testing
