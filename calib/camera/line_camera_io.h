// Line-camera file (YAML) reader and writer, FORMATS.md "Line camera" (model: line_camera.h).
//
//   name: GFHK-sim
//   line:
//     detectors: 900            # N, 1 .. 1e6
//     pitch_mm: 0.01            # 1e-5 .. 1
//     c: 8.5                    # principal distance, (0, 1e4] mm
//     line_axis: x              # optional: y = the values below are written with the line along
//                               # the camera's y axis (the patent's convention; converted to ours
//                               # at the reader: x = y_file, y = -x_file, and back at the writer)
//     mount_deg: [0, 0, 0]      # camera -> body, omega phi kappa, |.| <= 360
//     lever_arm_m: [0, 0, 0]    # camera centre in the body frame, |.| <= 1000
//     subcameras:               # optional (ours): the physical line cameras, in detector order
//       - {id: L, detectors: 300, c: 8.5, pitch_mm: 0.01, mount_deg: [0, -20, 0]}
//     dx_mm: [...N]             # calibration table, |.| <= 1000 mm ...
//     dy_mm: [...N]
//     calibration:              # ... or polynomials, one per range within one sub-camera
//       - {first: 0, last: 299, dx: [a0, a1, ...], dy: [...]}   # in u in [-1, 1], <= 10 terms
//
// Every error is InputError("FILE:LINE: what (got X)"); unknown keys are errors.
#pragma once

#include "calib/camera/line_camera.h"

#include <yaml-cpp/yaml.h>

#include <string>

namespace aerocal::calib {

/// True when the YAML root has a `line` section (a line-camera file).
bool IsLineCameraFile(const YAML::Node& root);
LineCamera ParseLineCamera(const YAML::Node& root, const std::string& file);
LineCamera ReadLineCamera(const std::string& path);
/// YAML text at full precision (angles in degrees).
std::string LineCameraToYaml(const LineCamera& camera);
/// Writes atomically.
void WriteLineCamera(const std::string& path, const LineCamera& camera);

}  // namespace aerocal::calib
