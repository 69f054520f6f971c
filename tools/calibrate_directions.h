// `aerocal calibrate --directions FILE`: laboratory geometric calibration from known directions
// (a collimator array or a goniometer sequence; triangulation/calibration/direction_io.h for the
// file, direction_run.h for the adjustment). Reading, calling the library, writing the result in
// the form of a test-field calibration (the same `calibration` section, budget and certificate
// inputs; the method states the instrument) and the camera file in the requested model / format.
#pragma once

#include "tools/calibrate_request.h"

#include <string>
#include <vector>

namespace aerocal::tools {

struct DirectionsArgs {
  std::string camera, directions, budget, out, write_camera, camera_format = "aerocal";
  std::string self_calibration;  // default: the model's (DefaultSelfCalibration)
  std::string model;             // default: the camera file's
  double sigma_px = 0.5;         // image sigma of rows without sigma_px, px
  std::vector<double>
      radii_mm;  // certified distortion radii (default: 1/4 .. 4/4 of the half diagonal)
};

/// Runs the calibration and writes --write-camera (not the result file; `out` is checked when
/// given). Throws InputError / ConfigError on bad input before anything is written.
CalibrateOutcome CalibrateFromDirections(const DirectionsArgs& args);

/// The command: CalibrateFromDirections, its lines printed, the result file written; the exit
/// code (0 valid and the groups agree, 3 otherwise).
int CalibrateFromDirectionsFile(const DirectionsArgs& args);

}  // namespace aerocal::tools
