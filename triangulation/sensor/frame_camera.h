// The frame camera: one image per exposure with the exposure's pose, observations in the virtual
// image's pixel frame, collinearity with the camera's interior in the camera's OWN model (any
// registered model: the residual comes from calib::MakeFrameCollinearityResidual, a hand-written
// Jacobian for the 10-parameter model, else collinearity.h's one factory; CONVENTIONS.md). It
// owns one interior block per camera (CameraIndex, sized by the camera's model), whose free
// entries are AdjustOptions::free_interior named by that model's table (a subset manifold in the
// builder; a name the model does not have is a ConfigError); other sensor kinds put their geometry
// in front of these blocks (sub-image mappings, rig mounts), in the same model.
#pragma once

#include "calib/camera/camera.h"
#include "triangulation/sensor/imaging_model.h"

#include <ceres/cost_function.h>

#include <memory>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// An interior block of a camera in any registered model: its entry names (the model's table) and
/// the entries held fixed (those not named in `free`, AdjustOptions::free_interior). ConfigError
/// when a free name is not a parameter of the model; `who` names the camera ("camera RC30", "rig
/// R head B").
struct InteriorLayout {
  std::vector<std::string> names;
  std::vector<int> fixed;
};
InteriorLayout InteriorLayoutOf(const calib::Camera& camera,
                                const std::vector<std::string>& free,
                                const std::string& who);

/// The prior (group kGroupInteriorPrior) of the free entries of `camera` that carry an a-priori
/// sigma, around the camera file's values; nullptr when none does. `free` checked by
/// InteriorLayoutOf.
std::unique_ptr<ceres::CostFunction> InteriorPriorOf(const calib::Camera& camera,
                                                     const std::vector<std::string>& free);

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
