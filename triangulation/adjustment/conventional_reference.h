// The conventional adjustment that a self-calibration is compared with (`adjust --compare`, the
// flight workflow): the same block and observations, the camera file's interior held fixed.
//
// Gross errors are a property of the observations, not of the camera model: they are decided by
// the self-calibrating run (the complete model) and left out of both runs. The conventional run
// itself does not snoop: its residuals carry the camera error it cannot model, and Baarda's test
// would take those for gross errors (it rejects good rays of control points near the format
// corners and so moves the datum), which inflates the check-point errors the comparison is about.
#pragma once

#include "calib/core/progress.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"

namespace aerocal::triangulation {

/// Conventional adjustment of `project` without the observations `self_calibration` rejected
/// (they are listed in the result's `rejected`, with a note), interior fixed, no snooping, no
/// robust start. `options` gives everything else (priors, solver, thresholds).
/// `progress` (may be null) advances by BlockAdjustment::kRunStages.
AdjustmentResult AdjustConventionalReference(const Project& project,
                                             const AdjustOptions& options,
                                             const AdjustmentResult& self_calibration,
                                             Progress* progress = nullptr);

}  // namespace aerocal::triangulation
