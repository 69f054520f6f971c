// Plausibility of a block before it is solved (issue 33 item 5): values that are legal but almost
// surely a mistake of units or of the file, said by name with the likely cause. Warnings, never
// errors: an unusual camera (a satellite's long focal length) must still run.
#pragma once

#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"

#include <vector>

namespace aerocal::triangulation {

/// Warning name: the principal distance is implausibly long for the format (c / diagonal above
/// kMaxPrincipalDistanceRatio: a full field of view under 2.9 degrees), the mark of a c given in
/// pixels where millimetres were expected.
inline constexpr const char* kWarningImplausiblePrincipalDistance =
    "implausible_principal_distance";
inline constexpr double kMaxPrincipalDistanceRatio = 20.0;

/// The warnings of every camera of `project` (rig heads included), in camera id order.
std::vector<ResultWarning> PlausibilityWarnings(const Project& project);

}  // namespace aerocal::triangulation
