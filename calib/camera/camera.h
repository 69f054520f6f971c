// A camera as the camera file (FORMATS.md "Camera file") describes it: the virtual image format,
// pixel size, the 10-parameter interior orientation (brown_fraser10.h), optional a-priori sigmas,
// and for a multi-CCD camera the sub-image mappings and maker reference points.
// Pixel (col, row) and photo (x, y) frames per CONVENTIONS.md (pixel_frame.h):
//   x = (col - (W - 1) / 2) p,  y = -(row - (H - 1) / 2) p.
// The adjustment keeps this camera in the 10-parameter model (Camera::Model, the one place that
// names it); a camera in any other registered model is a ModelCamera (camera_model.h), converted
// with ConvertCamera (convert_camera.h).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/pixel_frame.h"
#include "calib/camera/subimage_mapping.h"

namespace aerocal::calib {

/// The camera model of the adjustment's cameras: use this name (`using Model = Camera::Model`)
/// instead of naming BrownFraser10Model again.
using AdjustmentCameraModel = BrownFraser10Model;
using InteriorParams = std::array<double, AdjustmentCameraModel::kNumParams>;

/// Maker-surveyed point seen in sub-image `subimage` at (u, v), with virtual position (U, V).
struct ReferencePoint {
  std::string id;
  std::string subimage;
  double u = 0, v = 0;          // sub-image pixel
  double U = 0, V = 0;          // virtual-image pixel
  double sigma_px = 0.05;       // a-priori sigma of (U, V) relative to (u, v), px
};

struct Camera {
  using Model = AdjustmentCameraModel;
  std::string name;
  double pixel_size_mm = 0.0;
  int width_px = 0, height_px = 0;  // virtual image format
  InteriorParams interior{};        // table order c, x0, y0, K1, K2, K3, P1, P2, B1, B2
  /// A-priori standard deviations (table units) of interior parameters; absent = not weighted.
  std::array<std::optional<double>, Model::kNumParams> interior_sigma{};
  std::vector<SubimageMapping> subimages;
  std::vector<ReferencePoint> reference_points;

  double c_mm() const { return interior[Model::kC]; }

  /// The virtual image's pixel frame (pixel <-> photo coordinates).
  PixelFrame frame() const { return {pixel_size_mm, width_px, height_px}; }
  Eigen::Vector2d PhotoFromPixel(const Eigen::Vector2d& pixel) const {
    return frame().PhotoFromPixel(pixel);
  }
  Eigen::Vector2d PixelFromPhoto(const Eigen::Vector2d& xy_mm) const {
    return frame().PixelFromPhoto(xy_mm);
  }

  /// Measured virtual-image pixel of an object point seen from an exposure (opk rad, centre m).
  /// False when the point is behind the camera or the distortion inversion fails.
  bool ProjectToPixel(const Eigen::Vector3d& opk_rad, const Eigen::Vector3d& center_m,
                      const Eigen::Vector3d& point_m, Eigen::Vector2d* pixel) const;

  /// Index of a sub-image by id; -1 when absent.
  int SubimageIndex(const std::string& id) const;
};

}  // namespace aerocal::calib
