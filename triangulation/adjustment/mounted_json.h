// The one JSON form of a mounted block (calib/problem/mounted_block.h: {"mode", "value", "sigma"})
// for the results that keep a block's value and sigma as a 3-vector or a scalar in radians,
// seconds or metres: the platform (adjustment_result.cc), the rig heads (rig_head_camera.cc) and
// the line camera (pushbroom/line_calibration_json.cc). Value and sigma are written times `scale`,
// in the unit the key names (deg, ms, m). A held block has no a-posteriori sigma: its sigma is
// null whatever the covariance holds for it (0 from a fixed block), as is an unknown one.
#pragma once

#include "calib/problem/mounted_block.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <optional>

namespace aerocal::triangulation {

/// A 3-vector block (angles, lever arm): {mode, value [3], sigma [3 or null]}.
nlohmann::json MountedToJson(calib::BlockMode mode,
                             const Eigen::Vector3d& value,
                             const std::optional<Eigen::Vector3d>& sigma,
                             double scale);

/// A scalar block (time offset): {mode, value [1], sigma [1: number or null]}.
nlohmann::json MountedToJson(calib::BlockMode mode,
                             double value,
                             const std::optional<double>& sigma,
                             double scale);

}  // namespace aerocal::triangulation
