// The pixel frame of an image format: pixel (col, row) <-> photo (x, y) mm, the one place where
// CONVENTIONS.md's frames are written in code:
//   pixel (col, row): top-left pixel centre (0, 0), col right, row down;
//   photo (x, y) mm: origin at the format centre, y up:
//   x = (col - (W - 1) / 2) p,  y = -(row - (H - 1) / 2) p.
// Templated so residuals can differentiate through it. Every camera model (camera_model.h)
// converts its own pixel convention to this one at its boundary.
#pragma once

#include <Eigen/Core>

namespace aerocal::calib {

struct PixelFrame {
  double pixel_size_mm = 0.009;
  int width_px = 0, height_px = 0;

  template <typename T>
  void PhotoFromPixel(const T* pixel, T* xy_mm) const {
    xy_mm[0] = (pixel[0] - T(0.5 * (width_px - 1))) * T(pixel_size_mm);
    xy_mm[1] = -(pixel[1] - T(0.5 * (height_px - 1))) * T(pixel_size_mm);
  }
  template <typename T>
  void PixelFromPhoto(const T* xy_mm, T* pixel) const {
    pixel[0] = xy_mm[0] / T(pixel_size_mm) + T(0.5 * (width_px - 1));
    pixel[1] = -xy_mm[1] / T(pixel_size_mm) + T(0.5 * (height_px - 1));
  }
  Eigen::Vector2d PhotoFromPixel(const Eigen::Vector2d& pixel) const {
    Eigen::Vector2d xy;
    PhotoFromPixel(pixel.data(), xy.data());
    return xy;
  }
  Eigen::Vector2d PixelFromPhoto(const Eigen::Vector2d& xy_mm) const {
    Eigen::Vector2d pixel;
    PixelFromPhoto(xy_mm.data(), pixel.data());
    return pixel;
  }
};

}  // namespace aerocal::calib
