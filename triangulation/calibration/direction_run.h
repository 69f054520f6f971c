// A laboratory calibration from directions (direction_calibration.h) in the form of a test-field
// calibration run (calibration.h): the adjustment of all observations, one per observation group
// and the stability of the groups (GroupStability), so that the uncertainty budget
// (uncertainty_budget.h), the `calibration` JSON section and the certificate are the test
// field's, not a second copy.
//
// The directions' angular sigmas (collimators, goniometer settings) are part of each
// observation's a-priori covariance (DirectionCovarianceMm2), so the adjustment's covariance, the
// budget's type-A component "image measurements", already holds them; no `control_cofactor` is
// computed (a direction calibration has no control coordinates).
//
// What a direction run puts into the AdjustmentResult of each run: the solve report, sigma0 (and
// in px: sigma0 times the RMS of the observations' a-priori focal-plane sigmas, which include the
// directions' angular sigmas), the camera estimate with sigmas, one residual per observation
// (image = the setting, or "collimator"; point = the target), the determinability and the
// validity (not converged, no covariance, a rank defect or sigma0 above max_sigma0: not valid).
// No exposures, control or check points: a direction calibration has no positions.
#pragma once

#include "triangulation/calibration/calibration.h"
#include "triangulation/calibration/direction_calibration.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct DirectionRunOptions {
  DirectionCalibrationOptions calibration;
  double stability_alpha = 0.05;  // level of the group agreement test, (0, 1)
  double max_sigma0 = 3.0;        // above it a run is not valid (AdjustOptions::max_sigma0), > 0
};

struct DirectionRun {
  CalibrationRun run;        // all, groups, stability (no control_cofactor: see the header comment)
  DirectionCalibration all;  // the rotation, the estimated targets, the residuals
  Eigen::Vector3d start_opk_rad = Eigen::Vector3d::Zero();  // StartRotationFromDirections
};

/// Calibrates `start` (model, format, start interior; its id `camera_id`) from `observations` of
/// `targets`; `group_of_observation` is empty or names each observation's group ("": none; groups
/// need two or more and each determines its unknowns). The rotation starts from the known
/// targets (StartRotationFromDirections), unknown targets from their first ray. Throws
/// InputError for a group that cannot be adjusted alone (fewer observations than unknowns).
DirectionRun RunDirectionCalibration(const std::string& camera_id,
                                     const calib::Camera& start,
                                     std::vector<DirectionTarget> targets,
                                     const std::vector<DirectionObservation>& observations,
                                     const std::vector<std::string>& group_of_observation,
                                     const DirectionRunOptions& options = {});

/// Throws InputError at the observation's FILE:LINE when its direction is more than ~87 deg off
/// the camera's axis at the start rotation `start_opk_rad`: the residual is undefined there (no
/// camera sees it), so the input is refused before solving.
void CheckDirectionsInFront(const Eigen::Vector3d& start_opk_rad,
                            const std::vector<DirectionTarget>& targets,
                            const std::vector<DirectionObservation>& observations);

/// One direction calibration as a calibration adjustment (see the header comment).
CalibrationAdjustment AdjustmentOfDirections(const std::string& camera_id,
                                             const calib::Camera& start,
                                             const DirectionCalibration& calibration,
                                             const std::vector<DirectionObservation>& observations,
                                             const std::vector<std::string>& free_interior,
                                             double max_sigma0);

}  // namespace aerocal::triangulation
