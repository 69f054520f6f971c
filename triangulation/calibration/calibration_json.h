// The `calibration` section of an `aerocal calibrate` result (calib/README "Result documents",
// triangulation/README "Camera calibration"), written next to the result struct it serialises
// (CalibrationRun, calibration.h): starting values, data counts, the interior covariance with
// correlations, the per-group runs, the stability table with its detectable changes, the
// uncertainty budget. The command adds what only it knows (method, camera file, model, the
// fit beside in another model, the OpenCV peer).
#pragma once

#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/calibration/calibration.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <vector>

namespace aerocal::triangulation {

/// One calibration run: converged, valid, sigma0, redundancy, the estimated interior in its model
/// with sigmas (null when fixed or not determinable), the check points.
nlohmann::json CalibrationRunToJson(const AdjustmentResult& result);

/// {names, covariance, correlation} of the free interior parameters; null when `cov` does not
/// match the camera's model.
nlohmann::json InteriorCovarianceToJson(const Eigen::MatrixXd& cov, const CameraEstimate& camera);

nlohmann::json StabilityToJson(const StabilityReport& stability);

/// start, data, interior_covariance, groups, stability, uncertainty, radii_mm.
nlohmann::json CalibrationToJson(const CalibrationRun& run,
                                 const std::vector<BudgetQuantity>& budget,
                                 const std::vector<double>& radii_mm,
                                 double c_camera_file_mm);

}  // namespace aerocal::triangulation
