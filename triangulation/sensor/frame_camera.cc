#include "triangulation/sensor/frame_camera.h"

#include "calib/residuals/collinearity.h"

#include <algorithm>

namespace aerocal::triangulation {
namespace {
using Model = calib::Camera::Model;
}  // namespace

bool FrameCamera::Measures(const ImageObservation& observation) const {
  return observation.subimage.empty();
}

void FrameCamera::RegisterBlocks(const SensorContext& context) {
  std::vector<int> fixed;
  std::vector<std::string> names;
  for (int i = 0; i < Model::kNumParams; ++i) {
    const std::string name(Model::kParams[i].name);
    names.push_back(name);
    const auto& free = context.options.free_interior;
    if (std::find(free.begin(), free.end(), name) == free.end()) fixed.push_back(i);
  }
  const int n = context.index.NumCameras();
  interior_.resize(n);
  blocks_.assign(n, -1);
  for (CameraIndex k = 0; k < n; ++k) {
    const std::string& id = context.index.CameraId(k);
    interior_[k] = context.project.cameras.at(id).interior;
    blocks_[k] = context.builder.AddBlock(
        "camera " + id, interior_[k].data(), Model::kNumParams, calib::BlockKind::kInterior, names);
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
  const ObservationSite site = context.Site(observation);
  ObservationTerm term;
  term.group = calib::kGroupImage;
  term.cost = calib::CollinearityResidual::Create(
      site.camera->frame(), observation.pixel, observation.sigma_px);
  term.blocks = {blocks_[site.camera_index], site.pose.rotation, site.pose.center, point};
  return term;
}

}  // namespace aerocal::triangulation
