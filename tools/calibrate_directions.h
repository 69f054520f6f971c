// `aerocal calibrate --directions FILE`: laboratory geometric calibration from known directions
// (a collimator array or a goniometer sequence; triangulation/calibration/direction_io.h for the
// file, direction_run.h for the adjustment). Reading, calling the library, writing the result in
// the form of a test-field calibration (the same `calibration` section, budget and certificate
// inputs; the method states the instrument) and the camera file in the requested model / format.
#pragma once

#include "calib/camera/camera.h"
#include "tools/calibrate_request.h"
#include "triangulation/calibration/direction_io.h"
#include "triangulation/calibration/direction_run.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <map>
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

/// What every direction run takes from the options: the free interior (--self-calibration), the
/// budget (--budget, --radii-mm; no target radius); the output paths checked.
struct DirectionSetup {
  triangulation::DirectionRunOptions options;
  triangulation::BudgetOptions budget;
  /// --radii-mm or the budget file named the radii; otherwise budget.radii_mm are the camera's
  /// defaults (a rig's heads then take each its own format's: DefaultCertifiedRadiiMm).
  bool radii_given = false;
};
/// Throws ConfigError naming the option on bad values; `camera` gives the model and the default
/// radii.
DirectionSetup ReadDirectionSetup(const DirectionsArgs& args, const calib::Camera& camera);

/// The `group` column names two groups or more (or none): InputError at FILE:0 otherwise.
void CheckGroups(const triangulation::DirectionData& data, const std::string& path);
/// True when the directions file has a `unit` column.
bool HasUnitColumn(const std::string& directions);

/// The result document's top (AdjustmentToJson, command, validity, self_calibration) and its
/// `calibration.data` section.
nlohmann::json DirectionResultJson(const triangulation::AdjustmentResult& result,
                                   const DirectionSetup& setup);
nlohmann::json DirectionDataJson(const triangulation::DirectionData& data, size_t groups);
/// Angles (rad) as [omega, phi, kappa] in deg; sigmas (rad) in arc seconds, null when not known.
nlohmann::json DegreesJson(const Eigen::Vector3d& rad);
nlohmann::json ArcsecOrNullJson(const Eigen::Vector3d& rad, bool known);
/// The estimated targets {id: {azimuth_deg, elevation_deg, sigma_arcsec [2] or null}}.
nlohmann::json EstimatedTargetsJson(const std::map<std::string, Eigen::Vector2d>& angles_rad,
                                    const std::map<std::string, Eigen::Vector2d>& sigma_rad);
/// The outcome's document, validity (valid and the groups agree) and not-valid lines.
void FinishDirectionOutcome(const triangulation::AdjustmentResult& result,
                            nlohmann::json json,
                            bool groups_agree,
                            CalibrateOutcome* outcome);

/// Runs the calibration and writes --write-camera (not the result file; `out` is checked when
/// given). Throws InputError / ConfigError on bad input before anything is written.
CalibrateOutcome CalibrateFromDirections(const DirectionsArgs& args);

/// The command: CalibrateFromDirections, its lines printed, the result file written; the exit
/// code (0 valid and the groups agree, 3 otherwise).
int CalibrateFromDirectionsFile(const DirectionsArgs& args);

}  // namespace aerocal::tools
