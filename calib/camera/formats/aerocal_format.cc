// Our camera file (FORMATS.md "Camera file", any registry model) and the heads of a rig file.
#include "calib/camera/camera_io.h"
#include "calib/camera/formats/camera_formats.h"
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/yaml_util.h"

#include <cmath>

namespace aerocal::calib {

CameraFile CameraFileFromCamera(const Camera& ours) {
  CameraFile file;
  file.name = ours.name;
  file.camera = ours.AsModelCamera();
  bool any = false;
  const int n = ours.interior.size();
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    if (ours.interior_sigma[i]) {
      any = true;
      covariance(i, i) = *ours.interior_sigma[i] * *ours.interior_sigma[i];
    }
  if (any) {
    file.covariance = covariance;
    file.notes.push_back("interior_sigma read as a diagonal covariance (terms without a sigma: 0)");
  }
  return file;
}

CameraFile ReadAerocalCamera(const std::string& path, const CameraReadOptions& options) {
  const YAML::Node root = LoadYamlFile(path);
  CameraFile file;
  if (root.IsMap() && root["rig"]) {
    const Rig rig = ParseRig(root, path);
    const RigHead* head = nullptr;
    std::string ids;
    for (const RigHead& h : rig.heads) {
      ids += (ids.empty() ? "" : ", ") + h.id;
      if (h.id == options.camera_id) head = &h;
    }
    if (!head && options.camera_id.empty() && rig.heads.size() == 1) head = &rig.heads.front();
    if (!head)
      ThrowInputError(WhereIs(root["rig"], path),
                      options.camera_id.empty()
                          ? "a rig file: name a head with --camera (" + ids + ")"
                          : "no head '" + options.camera_id + "' (heads: " + ids + ")");
    file = CameraFileFromCamera(head->camera);
    file.name = head->id;
    file.chosen_by_camera_id = !options.camera_id.empty();
  } else {
    file = CameraFileFromCamera(ParseCamera(root, path, CameraModels::kAny));
  }
  const PixelFrame frame = file.camera.frame;
  internal::ResolveFormat(
      &file, options, {path, 1}, frame.width_px, frame.height_px, frame.pixel_size_mm);
  return file;
}

void WriteAerocalCamera(const std::string& path, const CameraFile& file) {
  Camera ours = Camera::OfModel(file.camera.model).WithModelCamera(file.camera);
  ours.name = file.name;
  if (file.covariance)
    for (int i = 0; i < ours.interior.size(); ++i) {
      const double variance = (*file.covariance)(i, i);
      if (variance > 0 && std::isfinite(variance)) ours.interior_sigma[i] = std::sqrt(variance);
    }
  WriteCamera(path, ours);
}

}  // namespace aerocal::calib
