// The sub-image direction residual factory (direction.h): one functor per registered camera model
// and mapping model (its own file, built in parallel with the other factories).
#include "calib/residuals/direction.h"

namespace aerocal::calib {

std::unique_ptr<ceres::CostFunction> MakeSubimageDirectionResidual(
    CameraModelId model,
    MappingModel mapping,
    const PixelFrame& frame,
    const MappingConditioning& cond,
    const Eigen::Vector2d& uv,
    const Eigen::Matrix3d& instrument_rotation,
    const Eigen::Matrix2d& covariance_mm2) {
  return VisitCameraModel(model, [&](auto m) {
    return VisitMappingModel(mapping, [&](auto map) {
      return ModelSubimageDirectionResidual<decltype(m), decltype(map)>::Create(
          frame, cond, uv, instrument_rotation, covariance_mm2);
    });
  });
}

}  // namespace aerocal::calib
