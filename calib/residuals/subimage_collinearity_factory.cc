// The sub-image residual factory (collinearity.h): one functor per registered camera model and
// mapping model, the heaviest of the factories to compile (its own file, built in parallel).
#include "calib/residuals/collinearity.h"

namespace aerocal::calib {

std::unique_ptr<ceres::CostFunction> MakeSubimageCollinearityResidual(
    CameraModelId model,
    MappingModel mapping,
    const PixelFrame& frame,
    const MappingConditioning& cond,
    const Eigen::Vector2d& uv,
    double sigma_px) {
  return VisitCameraModel(model, [&](auto m) {
    return VisitMappingModel(mapping, [&](auto map) {
      return ModelSubimageCollinearityResidual<decltype(m), decltype(map)>::Create(
          frame, cond, uv, sigma_px);
    });
  });
}

}  // namespace aerocal::calib
