// A camera as the camera file (FORMATS.md "Camera file") describes it: the virtual image format,
// pixel size, the 10-parameter interior orientation (brown_fraser10.h), optional a-priori sigmas,
// and for a multi-CCD camera the sub-image mappings and maker reference points.
// Pixel (col, row) and photo (x, y) frames per CONVENTIONS.md:
//   x = (col - (W - 1) / 2) p,  y = -(row - (H - 1) / 2) p.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/subimage_mapping.h"

namespace aerocal::calib {

using InteriorParams = std::array<double, BrownFraser10Model::kNumParams>;

/// Maker-surveyed point seen in sub-image `subimage` at (u, v), with virtual position (U, V).
struct ReferencePoint {
  std::string id;
  std::string subimage;
  double u = 0, v = 0;          // sub-image pixel
  double U = 0, V = 0;          // virtual-image pixel
  double sigma_px = 0.05;       // a-priori sigma of (U, V) relative to (u, v), px
};

struct Camera {
  std::string name;
  double pixel_size_mm = 0.0;
  int width_px = 0, height_px = 0;  // virtual image format
  InteriorParams interior{};        // table order c, x0, y0, K1, K2, K3, P1, P2, B1, B2
  /// A-priori standard deviations (table units) of interior parameters; absent = not weighted.
  std::array<std::optional<double>, BrownFraser10Model::kNumParams> interior_sigma{};
  std::vector<SubimageMapping> subimages;
  std::vector<ReferencePoint> reference_points;

  double c_mm() const { return interior[BrownFraser10Model::kC]; }

  /// Pixel (col, row) -> photo (x, y) mm. Templated so residuals can differentiate through it.
  template <typename T>
  void PhotoFromPixel(const T* pixel, T* xy_mm) const {
    xy_mm[0] = (pixel[0] - T(0.5 * (width_px - 1))) * T(pixel_size_mm);
    xy_mm[1] = -(pixel[1] - T(0.5 * (height_px - 1))) * T(pixel_size_mm);
  }
  Eigen::Vector2d PhotoFromPixel(const Eigen::Vector2d& pixel) const {
    Eigen::Vector2d xy;
    PhotoFromPixel(pixel.data(), xy.data());
    return xy;
  }
  Eigen::Vector2d PixelFromPhoto(const Eigen::Vector2d& xy_mm) const {
    return {xy_mm.x() / pixel_size_mm + 0.5 * (width_px - 1),
            -xy_mm.y() / pixel_size_mm + 0.5 * (height_px - 1)};
  }

  /// Measured virtual-image pixel of an object point seen from an exposure (opk rad, centre m).
  /// False when the point is behind the camera or the distortion inversion fails.
  bool ProjectToPixel(const Eigen::Vector3d& opk_rad, const Eigen::Vector3d& center_m,
                      const Eigen::Vector3d& point_m, Eigen::Vector2d* pixel) const;

  /// Index of a sub-image by id; -1 when absent.
  int SubimageIndex(const std::string& id) const;
};

}  // namespace aerocal::calib
