#include "triangulation/sensor/frame_camera.h"

#include "calib/core/error.h"
#include "calib/residuals/frame_collinearity_cost_function.h"
#include "calib/residuals/prior.h"

#include <algorithm>

namespace aerocal::triangulation {

InteriorLayout InteriorLayoutOf(const calib::Camera& camera,
                                const std::vector<std::string>& free,
                                const std::string& who) {
  // Free entries by the names of the camera's own model.
  const std::vector<calib::ParamInfo> table = camera.Params();
  InteriorLayout layout;
  for (int i = 0; i < static_cast<int>(table.size()); ++i) {
    layout.names.emplace_back(table[i].name);
    if (std::find(free.begin(), free.end(), layout.names.back()) == free.end())
      layout.fixed.push_back(i);
  }
  for (const std::string& name : free)
    if (camera.ParamIndex(name) < 0)
      throw ConfigError("free_interior: '" + name + "' is not a parameter of " + who +
                        " in model " + std::string(calib::CameraModelName(camera.model)) +
                        " (its parameters: " + calib::JoinParamNames(table) + ")");
  return layout;
}

std::unique_ptr<ceres::CostFunction> InteriorPriorOf(const calib::Camera& camera,
                                                     const std::vector<std::string>& free) {
  std::vector<int> indices;
  std::vector<double> values, sigmas;
  for (const auto& name : free) {
    const int i = camera.ParamIndex(name);  // >= 0: InteriorLayoutOf checked the names
    if (!camera.interior_sigma[i]) continue;
    indices.push_back(i);
    values.push_back(camera.interior[i]);
    sigmas.push_back(*camera.interior_sigma[i]);
  }
  if (indices.empty()) return nullptr;
  return std::make_unique<calib::PriorCostFunction>(
      camera.interior.size(), indices, values, sigmas);
}

void FrameCamera::RegisterBlocks(const SensorContext& context) {
  const int n = context.index.NumCameras();
  interior_.resize(n);
  blocks_.assign(n, -1);
  for (CameraIndex k = 0; k < n; ++k) {
    const std::string& id = context.index.CameraId(k);
    const calib::Camera& camera = context.project.cameras.at(id);
    const InteriorLayout layout =
        InteriorLayoutOf(camera, context.options.free_interior, "camera " + id);
    interior_[k] = camera.interior;
    blocks_[k] = context.builder.AddBlock("camera " + id,
                                          interior_[k].data(),
                                          interior_[k].size(),
                                          calib::BlockKind::kInterior,
                                          layout.names);
    context.builder.FixEntries(blocks_[k], layout.fixed);
  }
}

ImageRay FrameCamera::StartingRay(const SensorContext& context,
                                  const ImageObservation& observation) const {
  const ObservationSite site = context.Site(observation);
  return RayFromPixel(
      *site.camera, site.exposure->opk_rad, site.exposure->center_m, observation.pixel);
}

ObservationTerm FrameCamera::Observe(const SensorContext& context,
                                     const ImageObservation& observation,
                                     calib::BlockId point) {
  return Term(context, observation, point);
}

ObservationTerm FrameCamera::Term(const SensorContext& context,
                                  const ImageObservation& observation,
                                  calib::BlockId point) const {
  const ObservationSite site = context.Site(observation);
  ObservationTerm term;
  term.group = calib::kGroupImage;
  term.cost = calib::MakeFrameCollinearityResidual(
      site.camera->model, site.camera->frame(), observation.pixel, observation.sigma_px);
  term.blocks = {blocks_[site.camera_index], site.pose.rotation, site.pose.center, point};
  return term;
}

}  // namespace aerocal::triangulation
