// A camera as the camera file (FORMATS.md "Camera file", calib/README.md "Camera file") describes
// it: the virtual image format, pixel size, the camera model (any registered model,
// camera_model.h; default the 10-parameter model brown_fraser10.h) with its interior parameters in
// the model's table order and units, optional a-priori sigmas, and for a multi-CCD camera the
// sub-image mappings and maker reference points.
// Pixel (col, row) and photo (x, y) frames per CONVENTIONS.md (pixel_frame.h):
//   x = (col - (W - 1) / 2) p,  y = -(row - (H - 1) / 2) p.
// The adjustment works in the camera's own model: the frame camera, the raw sub-images through
// their mappings and the heads of a rig (the residual factories of calib/residuals/collinearity.h).
// The flight commands still read the 10-parameter model only (camera_io.h).
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/camera_model.h"
#include "calib/camera/pixel_frame.h"
#include "calib/camera/subimage_mapping.h"

#include <Eigen/Core>

#include <array>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::calib {

/// The 10-parameter model, the default of a camera file (and the model of the code that names its
/// terms: the camera file formats of DBAT, PhotoModeler, Australis; the calibration report): use
/// this name (`using Model = Camera::Model`) instead of naming BrownFraser10Model again.
using AdjustmentCameraModel = BrownFraser10Model;

/// Per-parameter values of a camera model (values, sigmas, free flags) in the model's table order.
/// Default-constructed: the size of the default model (brown_fraser_10), every entry T{}, so
/// `interior = {}` resets a 10-parameter camera; ForModel sizes it for any registered model.
template <typename T>
class ParamVector {
 public:
  using value_type = T;
  using iterator = typename std::vector<T>::iterator;
  using const_iterator = typename std::vector<T>::const_iterator;

  ParamVector() : values_(AdjustmentCameraModel::kNumParams) {}
  ParamVector(std::initializer_list<T> values) : values_(values) {}
  explicit ParamVector(std::vector<T> values) : values_(std::move(values)) {}
  template <typename It>
  ParamVector(It first, It last) : values_(first, last) {}
  /// Entries T{} for every parameter of `model`.
  static ParamVector ForModel(CameraModelId model) {
    return ParamVector(std::vector<T>(CameraModelParamCount(model)));
  }

  int size() const { return static_cast<int>(values_.size()); }
  decltype(auto) operator[](int i) { return values_[i]; }
  decltype(auto) operator[](int i) const { return values_[i]; }
  T* data() { return values_.data(); }
  const T* data() const { return values_.data(); }
  iterator begin() { return values_.begin(); }
  iterator end() { return values_.end(); }
  const_iterator begin() const { return values_.begin(); }
  const_iterator end() const { return values_.end(); }
  const std::vector<T>& values() const { return values_; }
  bool operator==(const ParamVector& other) const { return values_ == other.values_; }
  bool operator!=(const ParamVector& other) const { return values_ != other.values_; }

 private:
  std::vector<T> values_;
};

using InteriorParams = ParamVector<double>;
using InteriorSigmas = ParamVector<std::optional<double>>;

/// Maker-surveyed point seen in sub-image `subimage` at (u, v), with virtual position (U, V).
struct ReferencePoint {
  std::string id;
  std::string subimage;
  double u = 0, v = 0;     // sub-image pixel
  double U = 0, V = 0;     // virtual-image pixel
  double sigma_px = 0.05;  // a-priori sigma of (U, V) relative to (u, v), px
};

struct Camera {
  using Model = AdjustmentCameraModel;
  std::string name;
  CameraModelId model = Model::kId;  // the camera file's `model:` (default brown_fraser_10)
  double pixel_size_mm = 0.0;
  /// Half-width of the pixel pitch's tolerance (the maker's +-, mm; a rectangular distribution),
  /// when the camera file states one: a type-B component of a calibration's budget.
  std::optional<double> pixel_size_tolerance_mm;
  int width_px = 0, height_px = 0;  // virtual image format
  /// The model's parameters in its table order and units (brown_fraser_10: c, x0, y0, K1, K2, K3,
  /// P1, P2, B1, B2); size CameraModelParamCount(model).
  InteriorParams interior{};
  /// A-priori standard deviations (table units) of interior parameters; absent = not weighted.
  InteriorSigmas interior_sigma{};
  std::vector<SubimageMapping> subimages;
  std::vector<ReferencePoint> reference_points;

  /// A camera in `model` with every parameter 0 and no sigma.
  static Camera OfModel(CameraModelId model);

  /// The model's parameter table (names, units, groups) and the index of a name in it (-1: none).
  std::vector<ParamInfo> Params() const { return CameraModelParams(model); }
  int ParamIndex(std::string_view name) const;
  /// The principal distance (mm) of the ideal photo coordinates (model_common.h).
  double c_mm() const;
  /// Sets the principal distance to `c_mm` (> 0): a principal-distance parameter in mm is set, one
  /// in pixels scaled with the others of its group (fx and fy together).
  void SetPrincipalDistanceMm(double c_mm);
  /// The principal point in photo coordinates (mm): the measured point whose ideal coordinates
  /// are (0, 0) (x0, y0 of the 10-parameter model).
  Eigen::Vector2d PrincipalPointMm() const;
  /// Ideal photo coordinates (mm, reduced to the principal point, at c_mm()) of a measured pixel;
  /// false where the model's inversion does not converge.
  bool IdealFromPixel(const Eigen::Vector2d& pixel, Eigen::Vector2d* ideal_mm) const;
  /// Measured pixel of ideal photo coordinates (mm); false where the inversion does not converge.
  bool PixelFromIdeal(const Eigen::Vector2d& ideal_mm, Eigen::Vector2d* pixel) const;
  /// The camera as {model, params, frame} (camera_model.h) and back (name, sigmas, sub-images of
  /// `this` kept; throws LogicError when the parameter count does not fit the model).
  ModelCamera AsModelCamera() const;
  Camera WithModelCamera(const ModelCamera& camera) const;

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
  bool ProjectToPixel(const Eigen::Vector3d& opk_rad,
                      const Eigen::Vector3d& center_m,
                      const Eigen::Vector3d& point_m,
                      Eigen::Vector2d* pixel) const;

  /// Index of a sub-image by id; -1 when absent.
  int SubimageIndex(const std::string& id) const;
};

/// The distortion-free central projection on a format: the default model with only the principal
/// distance c (mm, > 0) and the principal point (x0, y0) (mm) set; ideal = photo - (x0, y0).
Camera PinholeCamera(double c_mm, double x0_mm, double y0_mm, const PixelFrame& frame);

}  // namespace aerocal::calib
