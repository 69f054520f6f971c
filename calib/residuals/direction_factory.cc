// The direction residual factory (direction.h): one functor per registered model.
#include "calib/residuals/direction.h"

namespace aerocal::calib {

std::unique_ptr<ceres::CostFunction> MakeDirectionResidual(
    CameraModelId model,
    const PixelFrame& frame,
    const Eigen::Matrix3d& instrument_rotation,
    const Eigen::Vector2d& pixel,
    const Eigen::Matrix2d& covariance_mm2) {
  return VisitCameraModel(model, [&](auto m) {
    return ModelDirectionResidual<decltype(m)>::Create(
        frame, instrument_rotation, pixel, covariance_mm2);
  });
}

}  // namespace aerocal::calib
