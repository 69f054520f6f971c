// The imaging-model interface: what a sensor kind (frame camera, multi-CCD camera with sub-image
// mappings, rig head, line camera) tells the block adjustment, so that the adjustment keeps only
// points, datum, priors, statistics and data snooping and never branches on the kind.
//
// A sensor kind
// - registers the parameter blocks it owns with THE problem builder once, by dense index
//   (RegisterBlocks: interior per camera, mappings per sub-image, mounts per head, ...);
// - says which image observations it measures (Measures) and gives their ray at the starting
//   values (StartingRay: forward intersection of the point starting values, done once, by the
//   adjustment);
// - for one observation returns the blocks its residual touches and the residual itself, a small
//   templated functor, WHITENED (Observe); the adjustment adds it under the term's group, labels
//   it, snoops it and reports it;
// - may add residuals on its own blocks only (AddOwnResiduals: stitching measurements, mount
//   priors), after the adjustment's priors.
// The exposure poses belong to the platform (the adjustment registers one rotation and one centre
// block per exposure, PoseBlocks by ExposureIndex); the GNSS/IMU priors sit on them. Other kinds
// put their own geometry between the pose and the frame camera's interior (SensorContext::frame).
//
// Ids are strings only at the file boundary and in reports; inside, cameras and exposures are
// dense indices (DenseIndex), assigned once when the adjustment starts.
#pragma once

#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/block/block.h"

#include <ceres/cost_function.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace aerocal::triangulation {

using CameraIndex = int;    // position of a camera in DenseIndex::camera_ids (sorted ids)
using ExposureIndex = int;  // position of an exposure in Project::exposures
using PointIndex = int;     // position of a ground point among the adjustment's observed points
                            // (sorted ids; BlockAdjustment assigns them once)

/// Dense indices of the project's cameras and exposures. AEROCAL_CHECK (LogicError) on an unknown
/// id: the readers have validated every reference before an adjustment starts.
class DenseIndex {
 public:
  explicit DenseIndex(const Project& project);
  CameraIndex Camera(const std::string& id) const;
  ExposureIndex Exposure(const std::string& image) const;
  /// As Exposure, -1 when `image` is not an exposure of the project.
  ExposureIndex FindExposure(const std::string& image) const;
  /// The camera of an exposure.
  CameraIndex CameraOfExposure(ExposureIndex exposure) const {
    return camera_of_exposure_[exposure];
  }
  int NumCameras() const { return static_cast<int>(camera_ids_.size()); }
  int NumExposures() const { return static_cast<int>(camera_of_exposure_.size()); }
  const std::string& CameraId(CameraIndex camera) const { return camera_ids_[camera]; }

 private:
  std::vector<std::string> camera_ids_;
  std::map<std::string, CameraIndex> camera_by_id_;
  std::map<std::string, ExposureIndex> exposure_by_image_;
  std::vector<CameraIndex> camera_of_exposure_;
};

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

  ObservationSite Site(const ImageObservation& observation) const;
};

class ImagingModel {
 public:
  virtual ~ImagingModel() = default;
  /// "frame", "subimage", ...: the kind in notes and errors.
  virtual std::string Kind() const = 0;
  /// True when this sensor kind measures `observation` (the adjustment asks the kinds it was
  /// given first, the frame camera last).
  virtual bool Measures(const ImageObservation& observation) const = 0;
  /// Registers the kind's own parameter blocks with context.builder, once, by dense index.
  /// Called once, before the platform poses are registered.
  virtual void RegisterBlocks(const SensorContext& context) = 0;
  /// The ray of `observation` (which this kind measures) at the starting values.
  virtual ImageRay StartingRay(const SensorContext& context,
                               const ImageObservation& observation) const = 0;
  /// The residual of `observation` (measured by this kind, its exposure used) on the ground point
  /// block `point`: blocks and whitened cost. Called once per observation the adjustment keeps.
  virtual ObservationTerm Observe(const SensorContext& context,
                                  const ImageObservation& observation,
                                  calib::BlockId point) = 0;
  /// Residuals on the kind's own blocks only (stitching measurements, priors of mounts), added
  /// after the adjustment's priors. None by default.
  virtual void AddOwnResiduals(const SensorContext& context) { (void)context; }
};

}  // namespace aerocal::triangulation
