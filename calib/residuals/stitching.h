// Stitching residuals: sub-image (u, v) -> virtual (U, V) through a mapping with CONDITIONED
// parameters (subimage_mapping.h). Both are [2, unitless], whitened by the point's sigma in px.
#pragma once

#include "calib/camera/subimage_mapping.h"
#include "calib/residuals/autodiff_residual.h"

#include <Eigen/Core>

namespace aerocal::calib {

namespace internal {
/// A sub-image observation (u, v) with conditioned input and its whitening: the one formula of
/// both stitching residuals, r = (Map(u, v) - target) / sigma_px.
struct MappedObservation {
  MappedObservation(const MappingConditioning& cond, const Eigen::Vector2d& uv, double sigma_px)
      : uv_{(uv.x() - cond.cu) / cond.scale, (uv.y() - cond.cv) / cond.scale},
        inverse_sigma_(1.0 / sigma_px) {}
  template <typename Mapping, typename T>
  void Residual(const T* mapping, const T* target, T* r) const {
    const T uv[2] = {T(uv_[0]), T(uv_[1])};
    T out[2];
    Mapping::Apply(mapping, uv, out);
    r[0] = (out[0] - target[0]) * T(inverse_sigma_);
    r[1] = (out[1] - target[1]) * T(inverse_sigma_);
  }

 private:
  double uv_[2], inverse_sigma_;
};
}  // namespace internal

/// Maker reference point: r = (Map(u, v) - (U, V)_surveyed) / sigma_px.
/// blocks: mapping[Mapping::kNumParams].
template <typename Mapping>
struct StitchReferenceResidual
    : AutoDiffResidual<StitchReferenceResidual<Mapping>, 2, Mapping::kNumParams> {
  StitchReferenceResidual(const MappingConditioning& cond,
                          const Eigen::Vector2d& uv,
                          const Eigen::Vector2d& virtual_px,
                          double sigma_px)
      : observation_(cond, uv, sigma_px), target_{virtual_px.x(), virtual_px.y()} {}
  template <typename T>
  bool operator()(const T* mapping, T* r) const {
    const T target[2] = {T(target_[0]), T(target_[1])};
    observation_.Residual<Mapping>(mapping, target, r);
    return true;
  }

 private:
  internal::MappedObservation observation_;
  double target_[2];
};

/// Tie point: every sub-image that sees the point maps it to the same unknown virtual position.
/// r = (Map(u, v) - P) / sigma_px.  blocks: mapping[Mapping::kNumParams], P[2] (virtual px).
template <typename Mapping>
struct StitchTieResidual : AutoDiffResidual<StitchTieResidual<Mapping>, 2, Mapping::kNumParams, 2> {
  StitchTieResidual(const MappingConditioning& cond, const Eigen::Vector2d& uv, double sigma_px)
      : observation_(cond, uv, sigma_px) {}
  template <typename T>
  bool operator()(const T* mapping, const T* point, T* r) const {
    observation_.Residual<Mapping>(mapping, point, r);
    return true;
  }

 private:
  internal::MappedObservation observation_;
};

}  // namespace aerocal::calib
