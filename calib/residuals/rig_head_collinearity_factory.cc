// The rig-head residual factory (collinearity.h): one functor per registered model.
#include "calib/residuals/collinearity.h"

namespace aerocal::calib {

std::unique_ptr<ceres::CostFunction> MakeRigHeadCollinearityResidual(
    CameraModelId model,
    const PixelFrame& head_frame,
    const Eigen::Vector2d& pixel,
    double sigma_px,
    const Eigen::Vector3d& velocity_mps) {
  return VisitCameraModel(model, [&](auto m) {
    return ModelRigHeadCollinearityResidual<decltype(m)>::Create(
        head_frame, pixel, sigma_px, velocity_mps);
  });
}

}  // namespace aerocal::calib
