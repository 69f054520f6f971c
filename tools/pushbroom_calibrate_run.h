// `aerocal pushbroom calibrate` as one request and one run: shared by the command
// (tools/cmd_pushbroom.cc, which writes the files) and Python's `aerocal.pushbroom_calibrate`.
#pragma once

#include "calib/camera/line_camera.h"
#include "triangulation/pushbroom/line_calibration.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::tools {

struct LineCalibrationRequest {
  std::string camera, pos, observations, points;
  double sigma_px = 0.3;
  std::string degree = "auto";
  std::string datum = "gauge";
  std::string pos_prior = "on";
  std::string boresight = "fixed", lever_arm = "fixed";  // fixed | free | weighted
  double boresight_sigma_deg = 0.0;
  triangulation::LineCalibrationOptions options;  // the options the command binds directly
};

struct LineCalibrationRun {
  calib::LineCamera camera;  // as read
  triangulation::LineCalibrationResult result;
  nlohmann::json json;          // the result document (kind pushbroom)
  std::string printed, errors;  // the command's stdout and stderr lines
  bool Ok() const { return result.valid && result.report.converged; }
};

/// Checks the request (ConfigError naming the option), reads the files (InputError FILE:LINE) and
/// calibrates; writes nothing.
LineCalibrationRun RunLineCalibration(const LineCalibrationRequest& request);

}  // namespace aerocal::tools
