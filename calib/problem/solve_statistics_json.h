// The solve statistics of a result, from the builder's SolveReport: ONE writer for every result
// that reports a solve (adjust, pushbroom, rig_stitch; docs/schema/common.schema.json):
//   {"redundancy", "iterations", "converged", "termination", "linear_solver", "seconds",
//    "groups": [{"name", "n", "rms_sigma"}]}
// sigma0 and the observation counts stay with each result: their meaning differs between kinds
// (a pushbroom result counts image points, an adjustment scalar residuals).
#pragma once

#include "calib/problem/problem_builder.h"

#include <nlohmann/json.hpp>

#include <vector>

namespace aerocal::calib {

/// Every residual group: name, scalar observations n, rms_sigma (RMS of the whitened residuals,
/// in a-priori sigmas; null when not finite).
nlohmann::json ResidualGroupsToJson(const std::vector<ResidualGroupStats>& groups);

/// The keys above; merged into a result with `json.update(SolveStatisticsToJson(report))`.
nlohmann::json SolveStatisticsToJson(const SolveReport& report);

}  // namespace aerocal::calib
