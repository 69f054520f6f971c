// The frame camera's residual factory (collinearity.h): one functor per registered model.
#include "calib/residuals/collinearity.h"

namespace aerocal::calib {

std::unique_ptr<ceres::CostFunction> MakeCollinearityResidual(CameraModelId model,
                                                              const PixelFrame& frame,
                                                              const Eigen::Vector2d& pixel,
                                                              double sigma_px) {
  return VisitCameraModel(model, [&](auto m) {
    return ModelCollinearityResidual<decltype(m)>::Create(frame, pixel, sigma_px);
  });
}

}  // namespace aerocal::calib
