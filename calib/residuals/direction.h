// Direction observations of a laboratory geometric calibration (issue 36 item 6): a collimator
// array (each collimator's direction known in the instrument frame, its cross measured in the
// image) or a goniometer (the camera turned to known settings, one fixed target measured).
// Observations are directions, not points: no projection centre and no scale.
//
//   t(a, e) = (sin a cos e, sin e, -cos a cos e)   the direction in the instrument frame from its
//                                                 azimuth a and elevation e (rad); a = e = 0 is -z,
//                                                 the nominal viewing direction of the camera
//   [U V W] = R^T G^T t
//   r = W_2x2 ((xb + dx, yb + dy) - (-c U / W, -c V / W))     [2, unitless]
//
// with R the camera's rotation (instrument_from_camera, quaternion block; camera frame as
// CONVENTIONS.md: x right, y up, looking along -z), G the instrument's known rotation for this
// observation (a goniometer setting turning the camera mount; identity for a collimator array)
// and the collinearity condition of the camera model (collinearity.h,
// internal::CollinearityErrorFromImageSpace: compared in the corrected photo space for the
// 10-parameter model). W_2x2 whitens the 2x2 covariance of the observation in the focal plane
// (DirectionCovarianceMm2: the image measurement and the direction's angular sigma through c).
// blocks: interior[Model::kNumParams] (table units), rotation[4] (quaternion), direction[2]
// (a, e in rad; fixed for a collimator, free for a goniometer's target).
// A multi-CCD camera's raw sub-image: ModelSubimageDirectionResidual puts the sub-image's mapping
// (blocks: mapping first) in front of the same condition (internal::DirectionError).
#pragma once

#include "calib/camera/camera_model.h"
#include "calib/camera/pixel_frame.h"
#include "calib/camera/rotation.h"
#include "calib/camera/subimage_mapping.h"
#include "calib/residuals/autodiff_residual.h"
#include "calib/residuals/collinearity.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cmath>
#include <memory>

namespace aerocal::calib {

/// t(a, e) of the header comment (unit vector, instrument frame).
template <typename T>
void DirectionFromAngles(const T* azimuth_elevation, T* t) {
  using std::cos;
  using std::sin;
  const T ce = cos(azimuth_elevation[1]);
  t[0] = sin(azimuth_elevation[0]) * ce;
  t[1] = sin(azimuth_elevation[1]);
  t[2] = -cos(azimuth_elevation[0]) * ce;
}

/// Covariance (mm^2) of a direction observation in the focal plane at the measured photo point
/// `xy_mm` (relative to the principal point) of a camera of principal distance `c_mm`: the image
/// measurement (sigma_px * pixel_size_mm, isotropic) plus the direction's angular sigma
/// `sigma_rad` (isotropic, per axis) mapped by the projection: c / cos^2(theta) radially and
/// c / cos(theta) tangentially, theta the off-axis angle (tan theta = |xy| / c).
inline Eigen::Matrix2d DirectionCovarianceMm2(const Eigen::Vector2d& xy_mm,
                                              double c_mm,
                                              double sigma_px,
                                              double pixel_size_mm,
                                              double sigma_rad) {
  const double image = sigma_px * pixel_size_mm;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity() * image * image;
  const double r = xy_mm.norm();
  const double cos2 = 1.0 / (1.0 + (r / c_mm) * (r / c_mm));  // cos^2 theta
  const double radial = c_mm * sigma_rad / cos2, tangential = c_mm * sigma_rad / std::sqrt(cos2);
  const Eigen::Vector2d u = r > 0.0 ? Eigen::Vector2d(xy_mm / r) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d v(-u.y(), u.x());
  cov += radial * radial * u * u.transpose() + tangential * tangential * v * v.transpose();
  return cov;
}

namespace internal {
/// The direction condition of the header comment at the measured photo point `xy` (mm; T so that
/// a sub-image mapping in front of it can move it): t(direction) turned by G^T (`gt`, row-major)
/// and R^T into [U V W], the camera model's collinearity error, whitened by `whitening` (2x2,
/// row-major). Shared by the frame and the sub-image direction residuals.
template <typename Model, typename T>
bool DirectionError(const T* interior,
                    const T* rotation,
                    const T* direction,
                    const PixelFrame& frame,
                    const double* gt,
                    const double* whitening,
                    const T* xy,
                    T* r) {
  T t[3], g_t[3], q_r[9], uvw[3];
  DirectionFromAngles(direction, t);
  for (int i = 0; i < 3; ++i)
    g_t[i] = T(gt[3 * i]) * t[0] + T(gt[3 * i + 1]) * t[1] + T(gt[3 * i + 2]) * t[2];
  ObjectFromImageRotationOfQuaternion(rotation, q_r);
  for (int i = 0; i < 3; ++i) uvw[i] = q_r[i] * g_t[0] + q_r[3 + i] * g_t[1] + q_r[6 + i] * g_t[2];
  T d[2];
  if (!CollinearityErrorFromImageSpace<Model>(interior, frame, uvw, xy, 1.0, d)) return false;
  r[0] = T(whitening[0]) * d[0] + T(whitening[1]) * d[1];
  r[1] = T(whitening[2]) * d[0] + T(whitening[3]) * d[1];
  return true;
}

/// G^T (row-major) and W = L^-1 with covariance = L L^T (|W v|^2 = v^T covariance^-1 v).
inline void DirectionWeights(const Eigen::Matrix3d& instrument_rotation,
                             const Eigen::Matrix2d& covariance_mm2,
                             double* gt,
                             double* whitening) {
  const Eigen::Matrix3d g_transposed = instrument_rotation.transpose();
  for (int i = 0; i < 9; ++i) gt[i] = g_transposed(i / 3, i % 3);
  const Eigen::Matrix2d w = Eigen::Matrix2d(covariance_mm2.llt().matrixL()).inverse();
  for (int i = 0; i < 4; ++i) whitening[i] = w(i / 2, i % 2);
}
}  // namespace internal

template <typename Model>
struct ModelDirectionResidual
    : AutoDiffResidual<ModelDirectionResidual<Model>, 2, Model::kNumParams, 4, 2> {
  /// `instrument_rotation` G (row-major use: t' = G^T t), `pixel` the measured (col, row) in
  /// `frame`, `covariance_mm2` of the observation in the focal plane (DirectionCovarianceMm2).
  ModelDirectionResidual(const PixelFrame& frame,
                         const Eigen::Matrix3d& instrument_rotation,
                         const Eigen::Vector2d& pixel,
                         const Eigen::Matrix2d& covariance_mm2)
      : frame_(frame) {
    frame.PhotoFromPixel(pixel.data(), xy_mm_);
    internal::DirectionWeights(instrument_rotation, covariance_mm2, gt_, whitening_);
  }

  template <typename T>
  bool operator()(const T* interior, const T* rotation, const T* direction, T* r) const {
    const T xy[2] = {T(xy_mm_[0]), T(xy_mm_[1])};
    return internal::DirectionError<Model>(
        interior, rotation, direction, frame_, gt_, whitening_, xy, r);
  }

 private:
  PixelFrame frame_;
  double xy_mm_[2];
  double gt_[9];
  double whitening_[4];
};

/// A direction measured at (u, v) in a RAW sub-image of a multi-CCD camera: the sub-image's
/// mapping (conditioned parameters, calib/camera/subimage_mapping.h) takes it to the virtual
/// image, whose interior and rotation the direction condition above uses. `frame` is the virtual
/// image's pixel frame, `covariance_mm2` the observation's in the virtual focal plane (sub-image
/// pixels taken at the virtual pixel size: the mappings' scale is 1 to ~1e-3).
/// blocks: mapping[Mapping::kNumParams] (conditioned), interior[Model::kNumParams] (table units),
/// rotation[4] (quaternion), direction[2] (a, e in rad).
template <typename Model, typename Mapping>
struct ModelSubimageDirectionResidual
    : AutoDiffResidual<ModelSubimageDirectionResidual<Model, Mapping>,
                       2,
                       Mapping::kNumParams,
                       Model::kNumParams,
                       4,
                       2> {
  ModelSubimageDirectionResidual(const PixelFrame& frame,
                                 const MappingConditioning& cond,
                                 const Eigen::Vector2d& uv,
                                 const Eigen::Matrix3d& instrument_rotation,
                                 const Eigen::Matrix2d& covariance_mm2)
      : frame_(frame),
        uv_conditioned_{(uv.x() - cond.cu) / cond.scale, (uv.y() - cond.cv) / cond.scale} {
    internal::DirectionWeights(instrument_rotation, covariance_mm2, gt_, whitening_);
  }

  template <typename T>
  bool operator()(
      const T* mapping, const T* interior, const T* rotation, const T* direction, T* r) const {
    const T uv[2] = {T(uv_conditioned_[0]), T(uv_conditioned_[1])};
    T virtual_px[2], xy[2];
    Mapping::Apply(mapping, uv, virtual_px);
    frame_.PhotoFromPixel(virtual_px, xy);
    return internal::DirectionError<Model>(
        interior, rotation, direction, frame_, gt_, whitening_, xy, r);
  }

 private:
  PixelFrame frame_;
  double uv_conditioned_[2];
  double gt_[9];
  double whitening_[4];
};

/// The factory by model id (VisitCameraModel), blocks as ModelDirectionResidual. Defined in
/// direction_factory.cc (compiled once, library aerocal::residual_factories).
std::unique_ptr<ceres::CostFunction> MakeDirectionResidual(
    CameraModelId model,
    const PixelFrame& frame,
    const Eigen::Matrix3d& instrument_rotation,
    const Eigen::Vector2d& pixel,
    const Eigen::Matrix2d& covariance_mm2);

/// The sub-image direction factory (VisitCameraModel x VisitMappingModel), blocks as
/// ModelSubimageDirectionResidual. Defined in subimage_direction_factory.cc.
std::unique_ptr<ceres::CostFunction> MakeSubimageDirectionResidual(
    CameraModelId model,
    MappingModel mapping,
    const PixelFrame& frame,
    const MappingConditioning& cond,
    const Eigen::Vector2d& uv,
    const Eigen::Matrix3d& instrument_rotation,
    const Eigen::Matrix2d& covariance_mm2);

}  // namespace aerocal::calib
