// The camera models of `aerocal calibrate` shared by its test-field / board path (cmd_calibrate.cc)
// and its directions path (calibrate_directions.cc): the --model option, the parameters calibrated
// by default per model, the camera file's camera converted into another model as a start, the
// stability warnings and the RMS image residual.
#pragma once

#include "calib/camera/camera.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/calibration/calibration.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::tools {

/// --model: brown10 (our 10-parameter model's short name) or a registered model name; ConfigError
/// naming the option otherwise.
calib::CameraModelId ModelOfOption(const std::string& name);

/// The parameters calibrated by default: those of the 10-parameter model but the affinity, and
/// OpenCV's of cv::calibrateCamera's default flags (k4-k6 fixed at 0); every one otherwise.
std::string DefaultSelfCalibration(calib::CameraModelId model);

/// The camera file's camera in `model`: converted (calib/camera/convert_camera.h; the parameters
/// not calibrated (`free`) are held at 0 in the fit, as a start they would stay there). Prints the
/// conversion's summary.
calib::Camera StartInModel(const calib::Camera& camera,
                           calib::CameraModelId model,
                           const std::vector<std::string>& free);

/// One `group_stability` warning per flagged parameter of the stability test in `json`'s
/// `warnings` (printed too).
void AddStabilityWarnings(const triangulation::StabilityReport& stability, nlohmann::json* json);

/// The RMS image residual per point (sqrt of the mean squared residual vector), as OpenCV's RMS,
/// px.
double RmsPx(const triangulation::AdjustmentResult& r);

/// The default radii of the certified distortion values: 1/4 .. 4/4 of the format's half diagonal,
/// mm, rounded to 0.1 mm (--radii-mm overrides them).
std::vector<double> DefaultCertifiedRadiiMm(const calib::Camera& camera);

}  // namespace aerocal::tools
