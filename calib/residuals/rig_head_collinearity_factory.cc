// The rig-head residual factory (collinearity.h): one functor per registered model, evaluated
// with Jets over the varying blocks only (rig_head_cost_function.h) where the held ones are held.
#include "calib/residuals/rig_head_cost_function.h"

namespace aerocal::calib {

std::unique_ptr<ceres::CostFunction> MakeRigHeadCollinearityResidual(
    CameraModelId model,
    const PixelFrame& head_frame,
    const Eigen::Vector2d& pixel,
    double sigma_px,
    const Eigen::Vector3d& velocity_mps) {
  return VisitCameraModel(model, [&](auto m) -> std::unique_ptr<ceres::CostFunction> {
    return std::make_unique<RigHeadReducedJetCostFunction<decltype(m)>>(
        head_frame, pixel, sigma_px, velocity_mps);
  });
}

}  // namespace aerocal::calib
