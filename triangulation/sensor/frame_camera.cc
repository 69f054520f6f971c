#include "triangulation/sensor/frame_camera.h"

#include "calib/core/error.h"
#include "calib/residuals/collinearity.h"

#include <algorithm>

namespace aerocal::triangulation {
void FrameCamera::RegisterBlocks(const SensorContext& context) {
  const int n = context.index.NumCameras();
  interior_.resize(n);
  blocks_.assign(n, -1);
  const auto& free = context.options.free_interior;
  for (CameraIndex k = 0; k < n; ++k) {
    const std::string& id = context.index.CameraId(k);
    const calib::Camera& camera = context.project.cameras.at(id);
    // Free entries by the names of the camera's own model (AdjustOptions::free_interior).
    const std::vector<calib::ParamInfo> table = camera.Params();
    std::vector<std::string> names;
    std::vector<int> fixed;
    for (int i = 0; i < static_cast<int>(table.size()); ++i) {
      names.emplace_back(table[i].name);
      if (std::find(free.begin(), free.end(), names.back()) == free.end()) fixed.push_back(i);
    }
    for (const std::string& name : free)
      if (camera.ParamIndex(name) < 0)
        throw ConfigError("free_interior: '" + name + "' is not a parameter of camera " + id +
                          " in model " + std::string(calib::CameraModelName(camera.model)) +
                          " (its parameters: " + calib::JoinParamNames(table) + ")");
    interior_[k] = camera.interior;
    blocks_[k] = context.builder.AddBlock("camera " + id,
                                          interior_[k].data(),
                                          interior_[k].size(),
                                          calib::BlockKind::kInterior,
                                          names);
    context.builder.FixEntries(blocks_[k], fixed);
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
  term.cost = calib::MakeCollinearityResidual(
      site.camera->model, site.camera->frame(), observation.pixel, observation.sigma_px);
  term.blocks = {blocks_[site.camera_index], site.pose.rotation, site.pose.center, point};
  return term;
}

}  // namespace aerocal::triangulation
