#include "triangulation/sensor/imaging_model.h"

#include "calib/core/error.h"

namespace aerocal::triangulation {

DenseIndex::DenseIndex(const Project& project) {
  for (const auto& [id, camera] : project.cameras) {
    (void)camera;
    camera_by_id_[id] = static_cast<CameraIndex>(camera_ids_.size());
    camera_ids_.push_back(id);
  }
  for (const auto& e : project.exposures) {
    exposure_by_image_[e.image] = static_cast<ExposureIndex>(camera_of_exposure_.size());
    camera_of_exposure_.push_back(Camera(e.camera));
  }
}

CameraIndex DenseIndex::Camera(const std::string& id) const {
  const auto it = camera_by_id_.find(id);
  AEROCAL_CHECK(it != camera_by_id_.end()) << "unknown camera " << id;
  return it->second;
}

ExposureIndex DenseIndex::Exposure(const std::string& image) const {
  const auto it = exposure_by_image_.find(image);
  AEROCAL_CHECK(it != exposure_by_image_.end()) << "unknown image " << image;
  return it->second;
}

ExposureIndex DenseIndex::FindExposure(const std::string& image) const {
  const auto it = exposure_by_image_.find(image);
  return it == exposure_by_image_.end() ? -1 : it->second;
}

ObservationSite SensorContext::Site(const ImageObservation& observation) const {
  ObservationSite site;
  site.index = index.Exposure(observation.image);
  site.camera_index = index.CameraOfExposure(site.index);
  site.exposure = &project.exposures[site.index];
  site.camera = &project.cameras.at(index.CameraId(site.camera_index));
  if (site.index < static_cast<int>(poses.size())) site.pose = poses[site.index];
  return site;
}

}  // namespace aerocal::triangulation
