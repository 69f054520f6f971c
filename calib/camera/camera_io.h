// Camera file (YAML) reader and writer, FORMATS.md "Camera file". Unknown keys, wrong types,
// impossible values (pixel size <= 0, a mapping with the wrong number of parameters, a reference
// point on an unknown sub-image) are InputError("FILE:LINE: what").
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "calib/camera/camera.h"

namespace aerocal::calib {

Camera ReadCamera(const std::string& path);
Camera ParseCamera(const YAML::Node& root, const std::string& file);
/// YAML text of a camera (full precision, every interior term written).
std::string CameraToYaml(const Camera& camera);
/// Writes atomically.
void WriteCamera(const std::string& path, const Camera& camera);

}  // namespace aerocal::calib
