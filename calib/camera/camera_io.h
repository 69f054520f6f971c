// Camera file (YAML) reader and writer, FORMATS.md "Camera file". Unknown keys, wrong types,
// impossible values (pixel size <= 0, a mapping with the wrong number of parameters, a reference
// point on an unknown sub-image) are InputError("FILE:LINE: what").
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "calib/camera/camera.h"
#include "calib/camera/camera_model.h"

namespace aerocal::calib {

Camera ReadCamera(const std::string& path);
Camera ParseCamera(const YAML::Node& root, const std::string& file);
/// YAML text of a camera (full precision, every interior term written).
std::string CameraToYaml(const Camera& camera);
/// Writes atomically.
void WriteCamera(const std::string& path, const Camera& camera);

/// A camera file in ANY registered model (camera_model.h): the same keys as above, `model:` one of
/// the registry's names (default brown_fraser_10), `interior:` keyed by that model's parameter
/// names (absent = 0). A brown_fraser_10 file is read by ParseCamera (everything checked as
/// there; sub-images and sigmas are not part of a ModelCamera). The mapping is the parameter
/// table: a new model needs nothing here.
ModelCamera ParseModelCamera(const YAML::Node& root, const std::string& file);
ModelCamera ReadModelCamera(const std::string& path);
std::string ModelCameraToYaml(const ModelCamera& camera, const std::string& name);

}  // namespace aerocal::calib
