// Collinearity residuals with the 10-parameter camera (CONVENTIONS.md). The residual is formed in
// the corrected (ideal) photo space, no iteration:
//   r = ((xb + dx, yb + dy) - (-c U / W, -c V / W)) / sigma_mm        [2, unitless]
// with [U V W] = R^T (X - X0), R = Rx(omega) Ry(phi) Rz(kappa), sigma_mm = sigma_px * pixel_size.
#pragma once

#include <Eigen/Core>

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/pixel_frame.h"
#include "calib/camera/rotation.h"
#include "calib/camera/subimage_mapping.h"
#include "calib/residuals/autodiff_residual.h"

namespace aerocal::calib {

namespace internal {
template <typename T>
bool CollinearityError(const T* interior, const T* opk, const T* center, const T* point,
                       const T* measured_xy_mm, double inverse_sigma_mm, T* residual) {
  T uvw[3];
  ImageSpaceFromObject(opk, center, point, uvw);
  if (!(uvw[2] < T(0))) return false;  // point on or behind the projection plane
  T ideal[2];
  BrownFraser10Model::IdealFromMeasured(interior, measured_xy_mm, ideal);
  const T c = interior[BrownFraser10Model::kC];
  residual[0] = (ideal[0] + c * uvw[0] / uvw[2]) * T(inverse_sigma_mm);
  residual[1] = (ideal[1] + c * uvw[1] / uvw[2]) * T(inverse_sigma_mm);
  return true;
}
}  // namespace internal

/// Observation (col, row) in the virtual image's pixel frame.
/// blocks: interior[10] (table units), opk[3] (rad), center[3] (m), point[3] (m).
struct CollinearityResidual : AutoDiffResidual<CollinearityResidual, 2, 10, 3, 3, 3> {
  CollinearityResidual(const PixelFrame& frame, const Eigen::Vector2d& pixel, double sigma_px)
      : inverse_sigma_mm_(1.0 / (sigma_px * frame.pixel_size_mm)) {
    frame.PhotoFromPixel(pixel.data(), xy_mm_);
  }
  template <typename T>
  bool operator()(const T* interior, const T* opk, const T* center, const T* point, T* r) const {
    const T xy[2] = {T(xy_mm_[0]), T(xy_mm_[1])};
    return internal::CollinearityError(interior, opk, center, point, xy, inverse_sigma_mm_, r);
  }

 private:
  double xy_mm_[2];
  double inverse_sigma_mm_;
};

/// Observation (u, v) in a RAW sub-image; the sub-image mapping (conditioned parameters, see
/// subimage_mapping.h) takes it to the virtual image, then collinearity as above.
/// blocks: mapping[Mapping::kNumParams], interior[10], opk[3] (rad), center[3] (m), point[3] (m).
template <typename Mapping>
struct SubimageCollinearityResidual
    : AutoDiffResidual<SubimageCollinearityResidual<Mapping>, 2, Mapping::kNumParams, 10, 3, 3, 3> {
  SubimageCollinearityResidual(const PixelFrame& frame, const MappingConditioning& cond,
                               const Eigen::Vector2d& uv, double sigma_px)
      : frame_(frame),
        uv_conditioned_{(uv.x() - cond.cu) / cond.scale, (uv.y() - cond.cv) / cond.scale},
        inverse_sigma_mm_(1.0 / (sigma_px * frame.pixel_size_mm)) {}
  template <typename T>
  bool operator()(const T* mapping, const T* interior, const T* opk, const T* center,
                  const T* point, T* r) const {
    const T uv[2] = {T(uv_conditioned_[0]), T(uv_conditioned_[1])};
    T virtual_px[2], xy[2];
    Mapping::Apply(mapping, uv, virtual_px);
    frame_.PhotoFromPixel(virtual_px, xy);
    return internal::CollinearityError(interior, opk, center, point, xy, inverse_sigma_mm_, r);
  }

 private:
  PixelFrame frame_;
  double uv_conditioned_[2];
  double inverse_sigma_mm_;
};

}  // namespace aerocal::calib
