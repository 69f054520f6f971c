#include "triangulation/sensor/mapped_subimage_camera.h"

#include "triangulation/sensor/frame_camera.h"

namespace aerocal::triangulation {

ImageObservation MappedSubimageCamera::AsAdjusted(const SensorContext& context,
                                                  const ImageObservation& observation) const {
  const calib::Camera& camera = *context.Site(observation).camera;
  ImageObservation mapped = observation;
  mapped.pixel = camera.subimages[camera.SubimageIndex(observation.subimage)].VirtualFromSub(
      observation.pixel);
  mapped.subimage.clear();
  return mapped;
}

ImageRay MappedSubimageCamera::StartingRay(const SensorContext& context,
                                           const ImageObservation& observation) const {
  return context.frame.StartingRay(context, observation);
}

ObservationTerm MappedSubimageCamera::Observe(const SensorContext& context,
                                              const ImageObservation& observation,
                                              calib::BlockId point) {
  return context.frame.Term(context, observation, point);
}

}  // namespace aerocal::triangulation
