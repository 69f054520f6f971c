// `aerocal calibrate` from a test field or a planar board, as one request (the command's options)
// and one outcome (the result document, what the command prints, its exit code): shared by the
// command (tools/cmd_calibrate.cc) and Python's `aerocal.calibrate`
// (tools/python/bind_calibrate.cc). The direction calibration (--directions) is
// tools/calibrate_directions.h.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace aerocal::tools {

/// Board points: design coordinates; the default sigma stands for the print / machining accuracy.
inline constexpr double kDefaultBoardSigmaMm = 0.01;

struct CalibrateRequest {
  std::string camera;                // camera file: pixel size, format, an approximate c
  std::string observations, points;  // a test field (together) ...
  std::string images, board;         // ... or a planar board: glob and "chessboard:9x6:25"
  // ... or the board's marks measured elsewhere (Python's arrays), with `board`: per image id,
  // columns x rows marks in the detector's order (tools/board_detection.h, BoardsFromMarks)
  std::vector<std::pair<std::string, std::vector<Eigen::Vector2d>>> corners;
  std::string groups, budget, write_marks, write_camera, camera_format = "aerocal";
  std::string self_calibration;  // default: the model's (DefaultSelfCalibration)
  std::string model;             // default: the camera file's
  std::string out;               // the result file, checked before the work ("" : not written here)
  double sigma_px = 0.5, board_sigma_mm = kDefaultBoardSigmaMm;
  std::vector<double> radii_mm;
  bool no_snooping = false, no_closed_form = false;
  double suspect_effect_limit = 1.0;
};

struct CalibrateOutcome {
  nlohmann::json doc;   // the result document (kind "adjust" with `calibration`)
  std::string printed;  // what the command prints on stdout
  std::string errors;   // ... and on stderr
  bool valid = false;   // the calibration valid and its groups stable
  int ExitCode() const { return valid ? 0 : 3; }
};

/// Runs the calibration of a test field or a planar board; writes --write-camera and
/// --write-marks, not the result file. InputError / ConfigError naming the file or the option.
CalibrateOutcome RunCalibration(const CalibrateRequest& request);

}  // namespace aerocal::tools
