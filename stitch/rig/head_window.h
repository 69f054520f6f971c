// Small windows of one head image projected onto the level virtual grid of a rig exposure, for
// the tie matching (rig_tie_matching.h) when only the neighbourhoods of the ties are needed
// instead of whole-format projections (issue 35: 4 heads x the whole virtual format, twice for
// the coverage, blurred twice, was most of a rig exposure's time).
//
// The map is the `rig convert` one (stitch/rig/rig_convert.h): head pixel = plane homography
// (head <- virtual) of the virtual pixel plus the head's correction grid, bilinearly interpolated
// at the virtual pixel, exactly as ResampleVirtualImage evaluates it (the homography in double,
// the grid in float). Coverage is the resampler's rule: the head position lies within
// [0, W-1] x [0, H-1] and in front of the homography (w > 0). Grey values are bilinear in float
// (the whole-format path resampled 16-bit values, i.e. to 1/256 DN).
#pragma once

#include "stitch/image_io/gray_image.h"
#include "stitch/resample/virtual_image.h"
#include "stitch/rig/rig_conversion.h"

#include <Eigen/Core>

#include <optional>

namespace aerocal::stitch {

/// A window of the virtual grid: virtual pixel (x0 + c, y0 + r) is element (r, c).
struct VirtualWindow {
  int x0 = 0, y0 = 0;
  GrayImage values;  // projected grey values (0 outside the coverage)
  GrayImage weight;  // 1 where the head covers the pixel, 0 elsewhere
};

class HeadWindowSampler {
 public:
  /// `image`: head `head`'s pixels (its format); `grid`: its correction grid (step 0: none).
  /// Both are referenced, not copied.
  HeadWindowSampler(const RigConverter& converter,
                    int head,
                    const GrayImage& image,
                    const MapCorrectionGrid& grid);

  /// Head pixel of a virtual pixel; nullopt outside the coverage.
  std::optional<Eigen::Vector2f> HeadPosition(double col, double row) const;
  bool Covers(double col, double row) const { return HeadPosition(col, row).has_value(); }

  /// True when the disc of `radius_px` around the virtual pixel lies in the coverage (17 points:
  /// the centre and 16 on the circle; the coverage is a smooth, nearly convex quadrilateral).
  bool CoversDisc(double col, double row, double radius_px) const;

  /// The window [x0, x0 + cols) x [y0, y0 + rows) of the virtual grid.
  VirtualWindow Project(int x0, int y0, int cols, int rows) const;

  /// The same window low-passed by a Gaussian of `sigma_px` normalised over the coverage
  /// (blur(values * weight) / blur(weight); 0 where the blurred weight is below 1e-3), exact
  /// in the window's interior (its `PrefilterBorderPx` outer pixels see the window's edge).
  /// sigma 0: the plain projection.
  VirtualWindow ProjectSmoothed(int x0, int y0, int cols, int rows, double sigma_px) const;

 private:
  Eigen::Matrix3d head_from_virtual_;
  const GrayImage& image_;
  const MapCorrectionGrid& grid_;
};

/// Outer pixels of a smoothed window that depend on pixels beyond it (OpenCV's Gaussian kernel
/// radius for float images: round(4 sigma)).
int PrefilterBorderPx(double sigma_px);

}  // namespace aerocal::stitch
