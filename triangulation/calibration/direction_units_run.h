// Several units of one instrument (the heads of a rig) calibrated from directions in ONE
// adjustment (CalibrateUnitsFromDirections, direction_calibration.h) in the form the command
// writes: per unit its start, its calibration adjustment (AdjustmentOfDirections: camera
// estimate, residuals, validity) and one AdjustmentResult holding every unit's camera and
// residuals with the one solve's statistics.
//
// Starting values: a unit that sees two or more distinct known targets starts its rotation to the
// instrument by Wahba's problem on them (StartRotationFromDirections); any other unit (a
// goniometer's) from the first unit's start and the design mounts of the file,
// R_k = R_1 M_1^T M_k (M = rig_from_unit). Unknown targets start from the first unit that sees
// them. No groups here: the command refuses them for a rig (tools/calibrate_direction_units.h).
#pragma once

#include "triangulation/calibration/direction_run.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

/// One unit as the camera file gives it.
struct DirectionUnitStart {
  std::string id;
  calib::Camera camera;                                        // start interior, format, model
  Eigen::Vector3d design_mount_rad = Eigen::Vector3d::Zero();  // rig_from_unit (omega, phi, kappa)
};

struct DirectionUnitsRun {
  DirectionUnitsCalibration calibration;  // units in the order of `ids`; the first is the reference
  std::vector<std::string> ids;
  std::vector<Eigen::Vector3d> start_opk_rad;  // per unit: start of instrument_from_unit
  std::vector<std::string> start_rotation;     // per unit: how it was started
  std::vector<int> observations;               // per unit
  AdjustmentResult all;  // every unit's camera estimate and residuals (image "UNIT[ SETTING]")
  /// Per unit: its calibration adjustment (AdjustmentOfDirections: camera estimate, interior
  /// covariance from the joint solve, residuals, validity), for a budget per unit.
  std::vector<CalibrationAdjustment> adjustments;
};

/// Calibrates the `units` that have observations (`unit_of_observation` names each observation's
/// unit) in one adjustment; the first of them is the reference of the mounts. Throws InputError
/// at a unit's first row when it has fewer scalar observations than its unknowns (free interior
/// and rotation), and as RunDirectionCalibration otherwise.
DirectionUnitsRun RunDirectionUnitsCalibration(
    const std::vector<DirectionUnitStart>& units,
    std::vector<DirectionTarget> targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& unit_of_observation,
    const DirectionRunOptions& options = {});

}  // namespace aerocal::triangulation
