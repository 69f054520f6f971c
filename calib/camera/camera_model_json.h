// A camera model's parameter table as JSON, for the result documents (calib/core/result_file.h):
// readers (the report, the certificate) take names, units and groups from it instead of restating
// the model.
#pragma once

#include "calib/camera/camera_model.h"

#include <nlohmann/json.hpp>

namespace aerocal::calib {

/// {name, id, parameters: [{name, unit, group}]} in table order (camera_model.h).
nlohmann::json CameraModelTableToJson(CameraModelId model);

}  // namespace aerocal::calib
