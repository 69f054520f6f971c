// JSON of the image-quality measurements (result kind "quality_mtf"; keys in
// stitch/quality/README.md). A value that could not be determined (an MTF that never falls to 0.5
// below 1 cycle/px) is written as null, never as a number.
#pragma once

#include "stitch/quality/slanted_edge.h"

#include <nlohmann/json.hpp>

namespace aerocal::stitch {

/// One edge: axis, angle, contrast, noise, MTF50 / MTF10 / MTF at Nyquist, the MTF50 budget with
/// u and U (k), the MTF curve and the ESF.
nlohmann::json SlantedEdgeToJson(const SlantedEdgeResult& result);

/// Repeated edges of one axis combined (type A and B).
nlohmann::json EdgeCombinationToJson(const EdgeMtfCombination& combination);

}  // namespace aerocal::stitch
