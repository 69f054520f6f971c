// A multi-CCD camera's sub-images calibrated from directions (direction_subimages.h) in the form
// of a calibration run (calibration.h), as direction_run.h does for one camera: the adjustment of
// all observations, one per observation group and the groups' stability, so that the budget, the
// `calibration` JSON section and the certificate are those of the virtual camera's interior (one
// interior: the budget and the stability test are the single camera's), with the sub-images'
// mappings beside them.
//
// Start values: R by Wahba's problem on the known directions taken to the virtual image through
// the camera file's mappings (VirtualObservations), unknown targets from their first ray there.
// The residuals of the result carry their sub-image and (u, v); measured_px is the virtual pixel
// of (u, v) through the estimated mapping. A run whose gauge could not be derived is not valid.
#pragma once

#include "triangulation/calibration/direction_run.h"
#include "triangulation/calibration/direction_subimages.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct SubimageDirectionsRun {
  CalibrationRun run;                 // all (the certified result), groups, stability
  SubimageDirectionsCalibration all;  // the mappings, the gauge, R, the targets
  std::vector<SubimageDirectionsCalibration> groups;  // per group of run.groups
  Eigen::Vector3d start_opk_rad = Eigen::Vector3d::Zero();
};

/// Calibrates the multi-CCD camera `start` (id `camera_id`) from `observations` in its sub-images
/// (`subimage_of_observation`); `group_of_observation` empty or one group name per observation
/// ("" none; two groups or more, each able to determine its unknowns). Throws as
/// CalibrateSubimagesFromDirections and CheckDirectionsInFront, and InputError for a group with
/// fewer scalar observations than its unknowns.
SubimageDirectionsRun RunSubimageDirectionCalibration(
    const std::string& camera_id,
    const calib::Camera& start,
    std::vector<DirectionTarget> targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of_observation,
    const std::vector<std::string>& group_of_observation,
    const DirectionRunOptions& options = {});

}  // namespace aerocal::triangulation
