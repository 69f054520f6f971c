// The sub-image camera at the camera file's mappings: a multi-CCD camera's raw sub-image pixels
// (u, v) taken into the virtual image once, by the mapping of their sub-image in the camera file
// (CONVENTIONS.md "Sub-image to virtual image"), and adjusted there as the frame camera's
// observations (its interior, the exposure's pose, group kGroupImage). It owns no block. The
// kind the block adjustment uses for sub-image observations when it is not asked to refine the
// mappings (that is SubimageCamera, the joint adjustment).
#pragma once

#include "triangulation/sensor/imaging_model.h"

namespace aerocal::triangulation {

class MappedSubimageCamera final : public ImagingModel {
 public:
  SensorKind Kind() const override { return SensorKind::kSubimage; }
  /// None: the frame camera's interiors carry it.
  void RegisterBlocks(const SensorContext& context) override { (void)context; }
  /// The virtual-image pixel (col, row) of the raw one by the camera file's mapping; the
  /// observation is kept, labelled and reported as a virtual-image one from here on.
  ImageObservation AsAdjusted(const SensorContext& context,
                              const ImageObservation& observation) const override;
  /// The frame camera's, of the virtual-image observation.
  ImageRay StartingRay(const SensorContext& context,
                       const ImageObservation& observation) const override;
  /// The frame camera's term (kGroupImage) of the virtual-image observation.
  ObservationTerm Observe(const SensorContext& context,
                          const ImageObservation& observation,
                          calib::BlockId point) override;
};

}  // namespace aerocal::triangulation
