// `aerocal calibrate --directions FILE --camera MULTI_CCD.yaml`: a multi-CCD camera's sub-images
// calibrated from known directions in ONE adjustment
// (triangulation/calibration/direction_subimages_run.h) when every row of the directions file
// names its sub-image in the `unit` column: the virtual camera's interior (its budget, groups and
// stability as a single camera's), the instrument rotation, and per sub-image its mapping with
// U (k = 2) as `<SUB>.<param>` quantities of the budget; the reference sub-image's mapping entries
// that the rank of the normal matrix leaves undetermined are held (the gauge, stated in
// `calibration.gauge`). --write-camera writes the camera file again (aerocal format) with the
// estimated interior and mappings.
#pragma once

#include "calib/camera/camera.h"
#include "tools/calibrate_directions.h"

namespace aerocal::tools {

/// The sub-image run (see the header comment); `camera` is args.camera read. Throws InputError /
/// ConfigError on bad input (--model and a --camera-format other than aerocal refused by name)
/// before anything is written.
CalibrateOutcome CalibrateSubimagesFromDirections(const DirectionsArgs& args,
                                                  const calib::Camera& camera);

}  // namespace aerocal::tools
