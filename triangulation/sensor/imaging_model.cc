#include "triangulation/sensor/imaging_model.h"

#include "calib/core/error.h"

namespace aerocal::triangulation {

ObservationSite SensorContext::Site(const ImageObservation& observation) const {
  ObservationSite site;
  site.index = index.Exposure(observation.image);
  site.camera_index = index.CameraOfExposure(site.index);
  site.exposure = &project.exposures[site.index];
  site.camera = &project.cameras.at(index.CameraId(site.camera_index));
  if (site.index < static_cast<int>(poses.size())) site.pose = poses[site.index];
  return site;
}

std::string ImagingModel::Describe(const ImageObservation& observation) const {
  return "image " + observation.image + " point " + observation.point;
}

void ImagingModel::Annotate(const ImageObservation& observation,
                            ObservationResidual* residual) const {
  (void)observation;
  (void)residual;
}

void ImagingModel::Annotate(const ImageObservation& observation,
                            RejectedObservation* rejected) const {
  (void)observation;
  (void)rejected;
}

}  // namespace aerocal::triangulation
