// Collinearity residuals (CONVENTIONS.md) for a camera in ANY registered model (camera_model.h),
// with [U V W] = R^T (X - X0), ideal = -c (U, V) / W, c = the model's PrincipalDistanceMm:
// - a model in correction form (kCorrectionForm, the 10-parameter model) is compared in the
//   corrected (ideal) photo space, no iteration:
//     r = (IdealFromMeasured(xy) - ideal) / sigma_mm
// - a forward model (OpenCV, COLMAP, Metashape, Pix4D: distortion from ideal to measured) is
//   compared where it is measured, as those tools do (reprojection error):
//     r = (xy - MeasuredFromIdeal(ideal)) / sigma_mm
// [2, unitless], sigma_mm = sigma_px * pixel_size, xy the measured photo coordinates (mm). The
// exposure rotation R is a unit quaternion block q = [w, x, y, z] (object_from_image,
// calib/camera/rotation.h), moved by the builder's rotation-increment manifold; R(q) equals
// Rx(omega) Ry(phi) Rz(kappa) of the files. Every family is templated on the model and made by
// its factory through VisitCameraModel: MakeCollinearityResidual (frame camera),
// MakeSubimageCollinearityResidual (raw sub-image through its mapping),
// MakeRigHeadCollinearityResidual (head of a rig); a new model needs nothing here.
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/camera_model.h"
#include "calib/camera/pixel_frame.h"
#include "calib/camera/rig.h"
#include "calib/camera/rotation.h"
#include "calib/camera/subimage_mapping.h"
#include "calib/residuals/autodiff_residual.h"

#include <Eigen/Core>

#include <memory>

namespace aerocal::calib {

namespace internal {
/// The one collinearity condition of aerocal: an object point already turned into the image-space
/// frame of its camera or head ([U V W] = R^T (X - X0)) against the measured photo coordinates,
/// in the camera model `Model` (header comment). Every collinearity residual (frame camera,
/// sub-image, rig head) ends here. False behind the projection plane or where the model's
/// inversion does not converge.
template <typename Model, typename T>
bool CollinearityErrorFromImageSpace(const T* interior,
                                     const PixelFrame& frame,
                                     const T* uvw,
                                     const T* measured_xy_mm,
                                     double inverse_sigma_mm,
                                     T* residual) {
  if (!(uvw[2] < T(0))) return false;  // point on or behind the projection plane
  const T c = Model::PrincipalDistanceMm(interior, frame);
  const T projected[2] = {-c * uvw[0] / uvw[2], -c * uvw[1] / uvw[2]};
  if constexpr (Model::kCorrectionForm) {
    T ideal[2];
    if (!Model::IdealFromMeasured(interior, frame, measured_xy_mm, ideal)) return false;
    residual[0] = (ideal[0] - projected[0]) * T(inverse_sigma_mm);
    residual[1] = (ideal[1] - projected[1]) * T(inverse_sigma_mm);
  } else {
    T measured[2];
    if (!Model::MeasuredFromIdeal(interior, frame, projected, measured)) return false;
    residual[0] = (measured_xy_mm[0] - measured[0]) * T(inverse_sigma_mm);
    residual[1] = (measured_xy_mm[1] - measured[1]) * T(inverse_sigma_mm);
  }
  return true;
}

template <typename Model, typename T>
bool CollinearityError(const T* interior,
                       const PixelFrame& frame,
                       const T* rotation,
                       const T* center,
                       const T* point,
                       const T* measured_xy_mm,
                       double inverse_sigma_mm,
                       T* residual) {
  T uvw[3];
  ImageSpaceFromObjectByQuaternion(rotation, center, point, uvw);
  return CollinearityErrorFromImageSpace<Model>(
      interior, frame, uvw, measured_xy_mm, inverse_sigma_mm, residual);
}
}  // namespace internal

/// Observation (col, row) in the virtual image's pixel frame, camera in `Model`.
/// blocks: interior[Model::kNumParams] (table units), rotation[4] (quaternion), center[3] (m),
/// point[3] (m).
template <typename Model>
struct ModelCollinearityResidual
    : AutoDiffResidual<ModelCollinearityResidual<Model>, 2, Model::kNumParams, 4, 3, 3> {
  ModelCollinearityResidual(const PixelFrame& frame, const Eigen::Vector2d& pixel, double sigma_px)
      : frame_(frame), inverse_sigma_mm_(1.0 / (sigma_px * frame.pixel_size_mm)) {
    frame.PhotoFromPixel(pixel.data(), xy_mm_);
  }
  template <typename T>
  bool operator()(
      const T* interior, const T* rotation, const T* center, const T* point, T* r) const {
    const T xy[2] = {T(xy_mm_[0]), T(xy_mm_[1])};
    return internal::CollinearityError<Model>(
        interior, frame_, rotation, center, point, xy, inverse_sigma_mm_, r);
  }

 private:
  PixelFrame frame_;
  double xy_mm_[2];
  double inverse_sigma_mm_;
};

/// The frame residual of the 10-parameter model (blocks interior[10], rotation[4], center[3],
/// point[3]).
using CollinearityResidual = ModelCollinearityResidual<BrownFraser10Model>;

/// THE residual factory: the collinearity residual of an observation (col, row) of a camera in
/// model `model` (blocks interior[CameraModelParamCount(model)], rotation[4], center[3],
/// point[3]).
/// Defined in collinearity_factory.cc (the factories are compiled once, library
/// aerocal::residual_factories: each instantiates its functor for every model).
std::unique_ptr<ceres::CostFunction> MakeCollinearityResidual(CameraModelId model,
                                                              const PixelFrame& frame,
                                                              const Eigen::Vector2d& pixel,
                                                              double sigma_px);

/// Observation (u, v) in a RAW sub-image; the sub-image mapping (conditioned parameters, see
/// subimage_mapping.h) takes it to the virtual image, then collinearity as above in the camera's
/// model `Model`.
/// blocks: mapping[Mapping::kNumParams], interior[Model::kNumParams], rotation[4] (quaternion),
/// center[3] (m), point[3] (m).
template <typename Model, typename Mapping>
struct ModelSubimageCollinearityResidual
    : AutoDiffResidual<ModelSubimageCollinearityResidual<Model, Mapping>,
                       2,
                       Mapping::kNumParams,
                       Model::kNumParams,
                       4,
                       3,
                       3> {
  ModelSubimageCollinearityResidual(const PixelFrame& frame,
                                    const MappingConditioning& cond,
                                    const Eigen::Vector2d& uv,
                                    double sigma_px)
      : frame_(frame),
        uv_conditioned_{(uv.x() - cond.cu) / cond.scale, (uv.y() - cond.cv) / cond.scale},
        inverse_sigma_mm_(1.0 / (sigma_px * frame.pixel_size_mm)) {}
  template <typename T>
  bool operator()(const T* mapping,
                  const T* interior,
                  const T* rotation,
                  const T* center,
                  const T* point,
                  T* r) const {
    const T uv[2] = {T(uv_conditioned_[0]), T(uv_conditioned_[1])};
    T virtual_px[2], xy[2];
    Mapping::Apply(mapping, uv, virtual_px);
    frame_.PhotoFromPixel(virtual_px, xy);
    return internal::CollinearityError<Model>(
        interior, frame_, rotation, center, point, xy, inverse_sigma_mm_, r);
  }

 private:
  PixelFrame frame_;
  double uv_conditioned_[2];
  double inverse_sigma_mm_;
};

/// The sub-image residual of the 10-parameter model (blocks mapping, interior[10], ...).
template <typename Mapping>
using SubimageCollinearityResidual = ModelSubimageCollinearityResidual<BrownFraser10Model, Mapping>;

/// The sub-image residual of a camera in model `model` with mappings of `mapping` (both
/// dispatches: VisitCameraModel, VisitMappingModel). Blocks as ModelSubimageCollinearityResidual.
/// Defined in subimage_collinearity_factory.cc.
std::unique_ptr<ceres::CostFunction> MakeSubimageCollinearityResidual(
    CameraModelId model,
    MappingModel mapping,
    const PixelFrame& frame,
    const MappingConditioning& cond,
    const Eigen::Vector2d& uv,
    double sigma_px);

/// Observation (col, row) in the pixel frame of head k of a rig (CONVENTIONS.md "Multi-head
/// rigs"): the head's pose is R_k = R M_k E_k, O_k = O + R t_k + v dT_k (calib/camera/rig.h
/// HeadPose), then the same collinearity as the frame camera with the head's own interior.
///   r = ((xb + dx, yb + dy) - (-c_k U / W, -c_k V / W)) / sigma_mm,  [U V W] = R_k^T (X - O_k)
/// in the head's camera model `Model`.
/// blocks: interior[Model::kNumParams] (head k, table units), rig_rotation[4] (quaternion of R,
///         as the frame camera's rotation block), rig_center[3] (m),
///         mount[3] (M_k omega, phi, kappa, rad), lever_arm[3] (t_k in the rig frame, m),
///         increment[3] (E_k, rad), dt[1] (dT_k, s), point[3] (m).
/// The platform velocity v (object frame, m/s) is data of the exposure, held by value.
/// A rig of one head with identity mount, zero lever arm, zero increment and dT = 0 gives exactly
/// ModelCollinearityResidual<Model> (tests/calib/residuals_test.cc checks it for every model).
template <typename Model>
struct ModelRigHeadCollinearityResidual : AutoDiffResidual<ModelRigHeadCollinearityResidual<Model>,
                                                           2,
                                                           Model::kNumParams,
                                                           4,
                                                           3,
                                                           3,
                                                           3,
                                                           3,
                                                           1,
                                                           3> {
  ModelRigHeadCollinearityResidual(const PixelFrame& head_frame,
                                   const Eigen::Vector2d& pixel,
                                   double sigma_px,
                                   const Eigen::Vector3d& velocity_mps)
      : frame_(head_frame),
        inverse_sigma_mm_(1.0 / (sigma_px * head_frame.pixel_size_mm)),
        velocity_mps_{velocity_mps.x(), velocity_mps.y(), velocity_mps.z()} {
    head_frame.PhotoFromPixel(pixel.data(), xy_mm_);
  }
  template <typename T>
  bool operator()(const T* interior,
                  const T* rig_rotation,
                  const T* rig_center,
                  const T* mount,
                  const T* lever_arm,
                  const T* increment,
                  const T* dt,
                  const T* point,
                  T* r) const {
    const T velocity[3] = {T(velocity_mps_[0]), T(velocity_mps_[1]), T(velocity_mps_[2])};
    T object_from_rig[9], object_from_head[9], head_center[3], uvw[3];
    ObjectFromImageRotationOfQuaternion(rig_rotation, object_from_rig);
    HeadPoseOfRotation(object_from_rig,
                       rig_center,
                       mount,
                       lever_arm,
                       increment,
                       dt,
                       velocity,
                       object_from_head,
                       head_center);
    ImageSpaceFromObjectByMatrix(object_from_head, head_center, point, uvw);
    const T xy[2] = {T(xy_mm_[0]), T(xy_mm_[1])};
    return internal::CollinearityErrorFromImageSpace<Model>(
        interior, frame_, uvw, xy, inverse_sigma_mm_, r);
  }

 private:
  PixelFrame frame_;
  double xy_mm_[2];
  double inverse_sigma_mm_;
  double velocity_mps_[3];
};

/// The rig-head residual of the 10-parameter model (blocks interior[10], ...).
using RigHeadCollinearityResidual = ModelRigHeadCollinearityResidual<BrownFraser10Model>;

/// The rig-head residual of a head in model `model` (VisitCameraModel); blocks as
/// ModelRigHeadCollinearityResidual.
/// Defined in rig_head_collinearity_factory.cc.
std::unique_ptr<ceres::CostFunction> MakeRigHeadCollinearityResidual(
    CameraModelId model,
    const PixelFrame& head_frame,
    const Eigen::Vector2d& pixel,
    double sigma_px,
    const Eigen::Vector3d& velocity_mps);

}  // namespace aerocal::calib
