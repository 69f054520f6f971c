// The part of one sub-image that a strip of the virtual image needs (virtual_image.cc): a window
// of samples, the virtual -> sub-image projectivity, and the closed-form coverage of a virtual row.
// Internal to stitch/resample.
#pragma once

#include "stitch/resample/virtual_image.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace aerocal::stitch::internal {

struct Window {
  bool used = false;
  int x0 = 0, y0 = 0, w = 0, h = 0;               // in sub-image pixels
  int width_px = 0, height_px = 0;                // sub-image format
  Eigen::Matrix3d sub_from_virtual;               // homogeneous, scaled so that w > 0 in front
  const MapCorrectionGrid* correction = nullptr;  // none: the projectivity alone
  // w * h samples, then at least w + 2 samples of padding (read with weight 0 by the fast path).
  std::vector<std::uint8_t> bytes;
  // The fast path's samples: `bytes` (stride w), or the window in place in a source held in
  // memory (stride = the sub-image's width) when at least two more rows follow the window there.
  const std::uint8_t* samples = nullptr;
  int stride = 0;  // samples per row
};

/// The columns [first, last] of a virtual row that a strip makes (the whole row, or a region's):
/// output sample c - first holds column c.
struct ColumnSpan {
  int first = 0, last = -1;
  int Count() const { return last - first + 1; }
};

/// Columns [first, last] of virtual row V whose (u, v) lies inside the sub-image's pixel centres,
/// 0 <= u <= W-1, 0 <= v <= H-1 (each bound is a U + b >= 0 for a projectivity with w > 0);
/// false when none.
bool CoveredColumns(const Window& win, double V, int virtual_width, int* first, int* last);

}  // namespace aerocal::stitch::internal
