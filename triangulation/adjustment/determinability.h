// Determinability of the parameters of an adjustment from its covariance: a singular normal
// matrix (datum defect, parameters the observations cannot reach, with the null-space parameters
// the builder found), and every parameter of interest whose strongest correlation with any other
// parameter exceeds the threshold (e.g. c with the exposures' Z without GNSS or relief, x0 with
// P1). The run reports these; it does not pretend.
#pragma once

#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjustment_result.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::triangulation {

/// `prefix` selects the parameters of interest by name ("camera " for interior parameters);
/// `threshold` in (0, 1). Each inseparable pair is listed once, with a sentence in `warnings`.
Determinability AssessDeterminability(const calib::CovarianceReport& covariance,
                                      const std::string& prefix,
                                      double threshold);

/// {determinable, message, covariance_method, undetermined, high_correlations [{a, b,
/// correlation}], warnings}: the `determinability` of an adjustment result and of a rig's
/// parameters (docs/schema/adjust.schema.json#/definitions/determinability). `determinable` as
/// the caller decides it (the block: its covariance could be computed; the rig: and no rig
/// parameter is undetermined).
nlohmann::json DeterminabilityToJson(const Determinability& determinability, bool determinable);

}  // namespace aerocal::triangulation
