// Camera file (YAML) reader and writer, FORMATS.md "Camera file". Unknown keys, wrong types,
// impossible values (pixel size <= 0, a mapping with the wrong number of parameters, a reference
// point on an unknown sub-image) are InputError("FILE:LINE: what").
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/camera_model.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace aerocal::calib {

/// Which camera models a reader accepts: the flight commands (`flight`, `batch`: their
/// self-calibration candidates name the 10-parameter model's terms) read with the default and
/// refuse another model with "convert it first"; the adjustment's cameras (frame, sub-image, rig
/// head), rig files, `calibrate`, `stitch`, `match` and `resample` (no interior term) take any.
enum class CameraModels { kBrownFraser10Only, kAny };

/// `model:` one of the registry's names (default brown_fraser_10); `interior:` and
/// `interior_sigma:` keyed by that model's parameter names (absent = 0 / not weighted), the
/// principal-distance parameters > 0; sub-images and reference points with any model (the
/// mappings are 2D, in pixels).
Camera ReadCamera(const std::string& path, CameraModels models = CameraModels::kBrownFraser10Only);
/// `record_keys`: further keys of `root` that its caller reads (a rig head's id, mount...), not
/// refused as unknown (reading the camera keys in place: a copy of them into a new node merged the
/// whole document's memory per head in yaml-cpp, which made rig files quadratic).
Camera ParseCamera(const YAML::Node& root,
                   const std::string& file,
                   CameraModels models = CameraModels::kBrownFraser10Only,
                   const std::vector<std::string>& record_keys = {});
/// YAML text of a camera (full precision, every interior term written).
std::string CameraToYaml(const Camera& camera);
/// Writes atomically.
void WriteCamera(const std::string& path, const Camera& camera);

/// A camera file in ANY registered model as a ModelCamera (ParseCamera with CameraModels::kAny;
/// sub-images and sigmas are not part of a ModelCamera). The mapping is the parameter table: a new
/// model needs nothing here.
ModelCamera ParseModelCamera(const YAML::Node& root, const std::string& file);
ModelCamera ReadModelCamera(const std::string& path);
std::string ModelCameraToYaml(const ModelCamera& camera, const std::string& name);

}  // namespace aerocal::calib
