// The platform: what carries the sensors of a block and which sensor took each observation, as
// dense indices (CONVENTIONS.md "Multi-head rigs"; docs/architecture.md "The platform").
//
// A carrier (an aircraft, a rig) takes exposures; each exposure has one pose, the adjustment's
// (PoseBlocks in triangulation/sensor/imaging_model.h). Sensors ride on it:
//   frame     a frame camera: the carrier's pose is the camera's; one sensor per camera
//   subimage  one CCD of a multi-CCD camera, measured in raw sub-image pixels; one sensor per
//             (camera, sub-image), mapped into the camera's virtual image
//   rig head  one head of a multi-head rig: mount M_k, lever arm t_k, time offset dT_k relative
//             to the rig's virtual camera; one sensor per (rig, head)
//   line      a line (pushbroom) camera on a POS trajectory (built by the pushbroom calibration,
//             never from a block's files)
// BuildPlatform reads the project once and is the only place that tells the kind of an
// observation from its columns (ObservationKind); afterwards every observation is a
// (sensor, exposure, point) triple of dense indices, and strings are left to the readers, the
// writers and the messages. How a kind is adjusted (its blocks and residual) is its ImagingModel,
// made by MakeImagingModel (triangulation/sensor/make_imaging_model.h).
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <array>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace aerocal::triangulation {

using CameraIndex = int;    // position of a camera in DenseIndex::camera_ids (sorted ids)
using ExposureIndex = int;  // position of an exposure in Project::exposures
using PointIndex = int;     // position of an observed ground point in Platform::point_ids
using SensorIndex = int;    // position of a sensor in Platform::sensors

/// The kinds of sensor aerocal adjusts. Values are not written anywhere (names are).
enum class SensorKind { kFrame, kSubimage, kRigHead, kLine };
/// Every kind, in enum order (the factory, the docs and the tests iterate it).
inline constexpr std::array<SensorKind, 4> kSensorKinds = {
    SensorKind::kFrame, SensorKind::kSubimage, SensorKind::kRigHead, SensorKind::kLine};
/// "frame", "subimage", "rig head", "line": the kind in notes and errors.
std::string_view SensorKindName(SensorKind kind);

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

/// One sensor on the carrier. Mount, lever arm and time offset are the file's starting values
/// relative to the carrier (zero for a frame camera or a sub-image: they ARE the carrier's camera);
/// whether they are fixed, free or weighted is the kind's option (calib::BlockMode).
struct Sensor {
  SensorKind kind = SensorKind::kFrame;
  CameraIndex camera = -1;  // the camera (file) it belongs to
  int part = -1;            // sub-image index in the camera, head index in the rig; -1: none
  std::string name;         // "camera A", "sub-image III", "head left": messages only
  Eigen::Vector3d mount_rad = Eigen::Vector3d::Zero();    // carrier -> sensor (omega, phi, kappa)
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();  // in the carrier's frame
  double time_offset_s = 0.0;                             // sensor time - exposure time
};

/// One observation as dense indices.
struct PlatformObservation {
  SensorIndex sensor = -1;
  ExposureIndex exposure = -1;
  PointIndex point = -1;
};

struct Platform {
  explicit Platform(const Project& project) : index(project) {}
  DenseIndex index;                               // cameras and the carrier's exposures
  std::vector<Sensor> sensors;                    // by SensorIndex: cameras' order, then parts
  std::vector<PlatformObservation> observations;  // by Project::observations index
  std::vector<std::string> point_ids;             // by PointIndex: observed point ids, sorted

  /// The sensor (kind, camera, part), -1 when the platform has none.
  SensorIndex FindSensor(SensorKind kind, CameraIndex camera, int part) const;
  /// The point of `id`, -1 when no observation names it.
  PointIndex FindPoint(const std::string& id) const;
  /// True when an observation is of `kind`.
  bool Observes(SensorKind kind) const;
};

/// The kind of an observation as the block files say it (FORMATS.md "Block"): a `head` column
/// -> rig head, a `subimage` column -> subimage, else frame. The one place that reads them.
SensorKind ObservationKind(const ImageObservation& observation);

/// The platform of a validated project (block_io.h ReadProject): a frame sensor per camera, a
/// subimage sensor per sub-image of a camera, a rig-head sensor per head of a rig (its file's
/// mount and lever arm); every observation's (sensor, exposure, point).
Platform BuildPlatform(const Project& project);

}  // namespace aerocal::triangulation
