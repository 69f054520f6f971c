// Our camera file (FORMATS.md "Camera file", any registry model) and the heads of a rig file.
#include <cmath>

#include "calib/camera/camera_io.h"
#include "calib/camera/formats/camera_formats.h"
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/yaml_util.h"

namespace aerocal::calib {

CameraFile CameraFileFromCamera(const Camera& ours) {
  CameraFile file;
  file.name = ours.name;
  file.camera.model = CameraModelId::kBrownFraser10;
  file.camera.params.assign(ours.interior.begin(), ours.interior.end());
  file.camera.frame = ours.frame();
  bool any = false;
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(10, 10);
  for (int i = 0; i < 10; ++i)
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
  } else if (root.IsMap() && (!root["model"] || root["model"].Scalar() ==
                                                    BrownFraser10Model::kName)) {
    file = CameraFileFromCamera(ParseCamera(root, path));
  } else {
    file.camera = ParseModelCamera(root, path);
    file.name = root["name"] ? root["name"].Scalar() : "";
  }
  const PixelFrame frame = file.camera.frame;
  internal::ResolveFormat(&file, options, {path, 1}, frame.width_px, frame.height_px,
                          frame.pixel_size_mm);
  return file;
}

void WriteAerocalCamera(const std::string& path, const CameraFile& file) {
  if (file.camera.model != CameraModelId::kBrownFraser10) {
    WriteFileAtomically(path, ModelCameraToYaml(file.camera, file.name));
    return;
  }
  Camera ours;
  ours.name = file.name;
  ours.pixel_size_mm = file.camera.frame.pixel_size_mm;
  ours.width_px = file.camera.frame.width_px;
  ours.height_px = file.camera.frame.height_px;
  for (int i = 0; i < 10; ++i) ours.interior[i] = file.camera.params.at(i);
  if (file.covariance)
    for (int i = 0; i < 10; ++i) {
      const double variance = (*file.covariance)(i, i);
      if (variance > 0 && std::isfinite(variance)) ours.interior_sigma[i] = std::sqrt(variance);
    }
  WriteCamera(path, ours);
}

}  // namespace aerocal::calib
