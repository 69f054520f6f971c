// The imaging-model interface: what a sensor kind (frame camera, multi-CCD camera with sub-image
// mappings, rig head, line camera) tells the block adjustment, so that the adjustment keeps only
// points, datum, priors, statistics and data snooping and never branches on the kind.
//
// A sensor kind
// - registers the parameter blocks it owns with THE problem builder once, by dense index
//   (RegisterBlocks: interior per camera, mappings per sub-image, mounts per head, ...);
// - is handed the observations of its kind (Kind, the platform's sensors) and gives their ray at
//   the starting values (StartingRay: forward intersection of the point starting values, done
//   once, by the adjustment);
// - for one observation returns the blocks its residual touches and the residual itself, a small
//   templated functor, WHITENED (Observe); the adjustment adds it under the term's group, labels
//   it, snoops it and reports it;
// - may add residuals on its own blocks only (AddOwnResiduals: stitching measurements, mount
//   priors), after the adjustment's priors;
// - says how its observations read in reports (Describe) and what it adds to their result
//   entries (Annotate), so that the adjustment's result writer needs no kind test.
// The exposure poses belong to the platform (the adjustment registers one rotation and one centre
// block per exposure, PoseBlocks by ExposureIndex); the GNSS/IMU priors sit on them. Other kinds
// put their own geometry between the pose and the frame camera's interior (SensorContext::frame).
//
// Ids are strings only at the file boundary and in reports; inside, cameras, exposures, sensors and
// points are dense indices (triangulation/block/platform.h), assigned once when the adjustment
// starts. Which kind takes an observation is the platform's word (its sensor), never a test of the
// observation's columns; the kinds are made by MakeImagingModel (make_imaging_model.h).
#pragma once

#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/block/block.h"
#include "triangulation/block/platform.h"

#include <ceres/cost_function.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// The platform's pose of one exposure: rotation image -> object (a unit quaternion block
/// [w, x, y, z], ProblemBuilder::AddRotationBlock; residuals turn it into R with
/// calib::ObjectFromImageRotationOfQuaternion) and projection centre (m).
struct PoseBlocks {
  calib::BlockId rotation = -1;
  calib::BlockId center = -1;
};

/// One observation's contribution, as a sensor kind builds it.
struct ObservationTerm {
  std::string group;                          // calib::kGroupImage, kGroupSubimage, ...
  std::unique_ptr<ceres::CostFunction> cost;  // whitened, 2 components in photo space (x, y up)
  std::vector<calib::BlockId> blocks;         // in the cost's block order, the point's included
};

class FrameCamera;

/// Where an observation was taken: its exposure (starting values in `exposure`), the exposure's
/// camera and the platform's pose blocks.
struct ObservationSite {
  ExposureIndex index = -1;
  CameraIndex camera_index = -1;
  const Exposure* exposure = nullptr;
  const calib::Camera* camera = nullptr;
  PoseBlocks pose;
};

/// What every sensor kind may use. Valid for the adjustment's lifetime; `poses` is filled after
/// RegisterBlocks and before the first StartingRay/Observe.
struct SensorContext {
  const Project& project;
  const AdjustOptions& options;
  calib::ProblemBuilder& builder;
  const DenseIndex& index;
  const std::vector<PoseBlocks>& poses;  // by ExposureIndex
  const FrameCamera& frame;              // interior blocks of every camera (frame_camera.h)
  const Platform* platform = nullptr;    // the block's sensors (null: a kind used on its own)

  ObservationSite Site(const ImageObservation& observation) const;
};

class ImagingModel {
 public:
  virtual ~ImagingModel() = default;
  /// The kind of sensor this model adjusts: the adjustment hands it every observation of that
  /// kind (Platform::observations), never asking the observation's columns.
  virtual SensorKind Kind() const = 0;
  /// Registers the kind's own parameter blocks with context.builder, once, by dense index.
  /// Called once, before the platform poses are registered.
  virtual void RegisterBlocks(const SensorContext& context) = 0;
  /// The observation as the adjustment keeps, labels and reports it; itself by default (the
  /// sub-image kind at the camera file's mappings hands over the virtual-image pixel).
  virtual ImageObservation AsAdjusted(const SensorContext& context,
                                      const ImageObservation& observation) const {
    (void)context;
    return observation;
  }
  /// The ray of `observation` (of this kind, as AsAdjusted returned it) at the starting values.
  virtual ImageRay StartingRay(const SensorContext& context,
                               const ImageObservation& observation) const = 0;
  /// The residual of `observation` (of this kind, as AsAdjusted returned it, its exposure used)
  /// on the ground point block `point`: blocks and whitened cost; the term's group is also the
  /// group data snooping tests. Called once per observation the adjustment keeps.
  virtual ObservationTerm Observe(const SensorContext& context,
                                  const ImageObservation& observation,
                                  calib::BlockId point) = 0;
  /// Residuals on the kind's own blocks only (stitching measurements, priors of mounts), added
  /// after the adjustment's priors. None by default.
  virtual void AddOwnResiduals(const SensorContext& context) { (void)context; }
  /// An observation in reports and snooping findings: "image 0012 point T442" by default; a kind
  /// names its part ("image 0012 head left point T442").
  virtual std::string Describe(const ImageObservation& observation) const;
  /// What the kind adds to an observation's entry in the result (its sub-image, its head):
  /// nothing by default.
  virtual void Annotate(const ImageObservation& observation, ObservationResidual* residual) const;
  virtual void Annotate(const ImageObservation& observation, RejectedObservation* rejected) const;
};

}  // namespace aerocal::triangulation
