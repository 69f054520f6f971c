// `aerocal calibrate --directions FILE --camera RIG`: the heads of a rig file calibrated from known
// directions in ONE adjustment (triangulation/calibration/direction_units_run.h); every row of the
// directions file names its head in the `unit` column. The result holds every head's interior
// (`cameras`, one per unit), the shared rotation to the instrument and each head's mount relative
// to the first unit (`calibration.units`); --write-camera writes the rig file again with the
// heads' interiors and mounts updated.
#pragma once

#include "tools/calibrate_directions.h"

#include <string>

namespace aerocal::tools {

/// True when `path` is a camera file with a `rig` section (several units).
bool IsRigCameraFile(const std::string& path);

/// The rig run (see the header comment). Throws InputError / ConfigError on bad input (options a
/// multi-unit run does not take are refused by name) before anything is written.
CalibrateOutcome CalibrateRigFromDirections(const DirectionsArgs& args);

}  // namespace aerocal::tools
