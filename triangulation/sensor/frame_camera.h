// The frame camera: one image per exposure with the exposure's pose, observations in the virtual
// image's pixel frame, collinearity with the camera's interior in the camera's OWN model (any
// registered model: the residual comes from calib::MakeCollinearityResidual, the one factory,
// calib/residuals/collinearity.h; CONVENTIONS.md). It owns one interior block per camera
// (CameraIndex, sized by the camera's model), whose free entries are AdjustOptions::free_interior
// named by that model's table (a subset manifold in the builder; a name the model does not have is
// a ConfigError); other sensor kinds put their geometry in front of these blocks (sub-image
// mappings, rig mounts: those need the 10-parameter model).
#pragma once

#include "calib/camera/camera.h"
#include "triangulation/sensor/imaging_model.h"

#include <vector>

namespace aerocal::triangulation {

class FrameCamera final : public ImagingModel {
 public:
  /// Virtual-image pixels (col, row).
  SensorKind Kind() const override { return SensorKind::kFrame; }
  /// One interior block per camera ("camera ID", entries named by its model's table).
  void RegisterBlocks(const SensorContext& context) override;
  ImageRay StartingRay(const SensorContext& context,
                       const ImageObservation& observation) const override;
  /// Group kGroupImage; blocks interior, rotation, centre, point.
  ObservationTerm Observe(const SensorContext& context,
                          const ImageObservation& observation,
                          calib::BlockId point) override;
  /// The term Observe builds, for other kinds that end in a virtual-image pixel of the frame
  /// camera (the sub-image kind at the camera file's mappings).
  ObservationTerm Term(const SensorContext& context,
                       const ImageObservation& observation,
                       calib::BlockId point) const;

  /// The interior block of a camera and its current values (table order).
  calib::BlockId InteriorBlock(CameraIndex camera) const { return blocks_[camera]; }
  const calib::InteriorParams& Interior(CameraIndex camera) const { return interior_[camera]; }

 private:
  std::vector<calib::InteriorParams> interior_;  // sized once: the builder holds their addresses
  std::vector<calib::BlockId> blocks_;
};

}  // namespace aerocal::triangulation
