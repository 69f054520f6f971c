#include "triangulation/block/platform.h"

#include "calib/core/error.h"

#include <algorithm>
#include <tuple>

namespace aerocal::triangulation {

std::string_view SensorKindName(SensorKind kind) {
  switch (kind) {
    case SensorKind::kSubimage:
      return "subimage";
    case SensorKind::kRigHead:
      return "rig head";
    case SensorKind::kLine:
      return "line";
    case SensorKind::kFrame:
      break;
  }
  return "frame";
}

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

SensorIndex Platform::FindSensor(SensorKind kind, CameraIndex camera, int part) const {
  for (SensorIndex s = 0; s < static_cast<SensorIndex>(sensors.size()); ++s)
    if (sensors[s].kind == kind && sensors[s].camera == camera && sensors[s].part == part) return s;
  return -1;
}

PointIndex Platform::FindPoint(const std::string& id) const {
  const auto it = std::lower_bound(point_ids.begin(), point_ids.end(), id);
  return it != point_ids.end() && *it == id ? static_cast<PointIndex>(it - point_ids.begin()) : -1;
}

bool Platform::Observes(SensorKind kind) const {
  return std::any_of(observations.begin(), observations.end(), [&](const PlatformObservation& o) {
    return sensors[o.sensor].kind == kind;
  });
}

SensorKind ObservationKind(const ImageObservation& observation) {
  if (!observation.head.empty()) return SensorKind::kRigHead;
  if (!observation.subimage.empty()) return SensorKind::kSubimage;
  return SensorKind::kFrame;
}

namespace {

// The sensors of one camera: the camera itself, its sub-images, the heads of its rig.
void AddSensorsOfCamera(const Project& project, CameraIndex k, const std::string& id, Platform* p) {
  const calib::Camera& camera = project.cameras.at(id);
  p->sensors.push_back({SensorKind::kFrame, k, -1, "camera " + id});
  for (int s = 0; s < static_cast<int>(camera.subimages.size()); ++s)
    p->sensors.push_back({SensorKind::kSubimage, k, s, "sub-image " + camera.subimages[s].id});
  const auto rig = project.rigs.find(id);
  if (rig == project.rigs.end()) return;
  for (int h = 0; h < static_cast<int>(rig->second.heads.size()); ++h) {
    const calib::RigHead& head = rig->second.heads[h];
    p->sensors.push_back(
        {SensorKind::kRigHead, k, h, "head " + head.id, head.mount_rad, head.lever_arm_m, 0.0});
  }
}

// The part of the camera that took `o`: its sub-image, its rig head, or -1.
int PartOf(const Project& project, const std::string& camera_id, const ImageObservation& o) {
  switch (ObservationKind(o)) {
    case SensorKind::kSubimage:
      return project.cameras.at(camera_id).SubimageIndex(o.subimage);
    case SensorKind::kRigHead:
      return project.rigs.at(camera_id).HeadIndex(o.head);
    default:
      return -1;
  }
}

}  // namespace

Platform BuildPlatform(const Project& project) {
  Platform p(project);
  for (CameraIndex k = 0; k < p.index.NumCameras(); ++k)
    AddSensorsOfCamera(project, k, p.index.CameraId(k), &p);
  std::map<std::tuple<SensorKind, CameraIndex, int>, SensorIndex> sensor_of;
  for (SensorIndex s = 0; s < static_cast<SensorIndex>(p.sensors.size()); ++s)
    sensor_of[{p.sensors[s].kind, p.sensors[s].camera, p.sensors[s].part}] = s;
  for (const ImageObservation& o : project.observations) p.point_ids.push_back(o.point);
  std::sort(p.point_ids.begin(), p.point_ids.end());
  p.point_ids.erase(std::unique(p.point_ids.begin(), p.point_ids.end()), p.point_ids.end());
  p.observations.reserve(project.observations.size());
  for (const ImageObservation& o : project.observations) {
    PlatformObservation x;
    x.exposure = p.index.Exposure(o.image);
    const CameraIndex camera = p.index.CameraOfExposure(x.exposure);
    const int part = PartOf(project, p.index.CameraId(camera), o);
    const auto sensor = sensor_of.find({ObservationKind(o), camera, part});
    AEROCAL_CHECK(sensor != sensor_of.end())
        << "image " << o.image << " point " << o.point << ": no sensor (unvalidated project)";
    x.sensor = sensor->second;
    x.point = p.FindPoint(o.point);
    p.observations.push_back(x);
  }
  return p;
}

}  // namespace aerocal::triangulation
