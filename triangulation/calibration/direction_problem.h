// The pieces every direction adjustment builds its problem from (direction_calibration.h for the
// cameras and rig heads, direction_subimages.h for a multi-CCD camera's sub-images): the
// interior's free entries, the targets' blocks, the observations' labels and start rays.
#pragma once

#include "calib/camera/camera.h"
#include "calib/problem/problem_builder.h"
#include "triangulation/calibration/direction_calibration.h"

#include <Eigen/Core>

#include <deque>
#include <map>
#include <string>
#include <vector>

namespace aerocal::triangulation::internal {

/// "FILE:LINE: unit U: direction observation N (target T, setting S)" (parts left out when empty).
std::string DirectionObservationText(size_t index,
                                     const DirectionObservation& observation,
                                     const std::string& unit);

/// The start camera's ray of a pixel (camera frame; the camera's principal point, no
/// distortion): a start value only.
Eigen::Vector3d DirectionStartRay(const calib::Camera& start, const Eigen::Vector2d& pixel);

/// Fixes the entries of `camera`'s interior block not named in `free` (all: the whole block).
/// Throws InputError for a name not in the model's table.
void FixInteriorEntries(const calib::Camera& camera,
                        const std::vector<std::string>& free,
                        calib::BlockId block,
                        calib::ProblemBuilder* builder);

/// The targets' blocks (a known target's fixed) at `angles` (stable addresses); the unknown ones
/// join `covariance_blocks`. Returns the method: "collimator array" when every target is known,
/// else "goniometer". Throws InputError for a target given twice.
std::string AddTargetBlocks(const std::vector<DirectionTarget>& targets,
                            calib::ProblemBuilder* builder,
                            std::deque<Eigen::Vector2d>* angles,
                            std::map<std::string, calib::BlockId>* target_block,
                            std::vector<calib::BlockId>* covariance_blocks);

/// Checks an observation's sigmas (sigma_px > 0, sigma_rad >= 0) and returns its focal-plane
/// covariance (DirectionCovarianceMm2) at the photo point `xy_mm` of a camera of principal
/// distance `c_mm`. Throws InputError naming the observation.
Eigen::Matrix2d DirectionObservationCovariance(size_t index,
                                               const DirectionObservation& observation,
                                               const std::string& unit,
                                               const Eigen::Vector2d& xy_mm,
                                               double c_mm,
                                               double pixel_size_mm);

}  // namespace aerocal::triangulation::internal
