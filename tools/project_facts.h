// The facts of the project an `adjust` result describes, for its report (tools/report): the same
// keys from the command and from the Python module's to_json(), so that both stay one document.
#pragma once

#include "triangulation/block/block.h"

#include <nlohmann/json.hpp>

namespace aerocal::tools {

/// Adds `aerocal_version`, `inputs` (every file the project was read from, with its size and
/// SHA-256, calib/core/file_digest.h), `camera_format` (the first camera's width_px, height_px,
/// pixel_size_mm) and `camera_names` ({id: the camera file's `name`}). Throws InputError when a
/// file cannot be read again.
void AddProjectFacts(const triangulation::Project& input, nlohmann::json* json);

}  // namespace aerocal::tools
