// The work of `aerocal batch` units: the flight a manifest describes, a unit's input hash, and the
// run of one unit (one exposure's stitching with its model choice, stitch::StitchFrame, exactly as
// `aerocal flight` adjusts it in step 1), written atomically with its done record.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/adjustment/flight_stability.h"
#include "tools/batch_manifest.h"
#include "tools/flight_command.h"

#include <memory>
#include <string>
#include <vector>

namespace aerocal::tools {

/// The `flight` arguments of a manifest parsed and checked as `aerocal flight` does
/// (ConfigError "flight arguments: ..." when they no longer parse). Relative paths in them start
/// from manifest.directory: EnterPlanDirectory first.
std::shared_ptr<FlightArgs> ParseFlightArguments(const std::vector<std::string>& arguments);

/// Makes manifest.directory the working directory (InputError when it is not there).
void EnterPlanDirectory(const BatchManifest& manifest);

/// What every unit of a flight shares: the camera and the stitching options, and their hash.
struct UnitContext {
  calib::Camera camera;
  stitch::BatchOptions options;
  std::string shared_hash;  // camera file text, stitching options, aerocal version
};
UnitContext MakeUnitContext(const FlightArgs& flight);

/// Hash of everything a unit's output depends on: the shared part and its input file.
std::string UnitInputHash(const UnitContext& context,
                          const BatchManifest& manifest,
                          const BatchUnit& unit);

/// Runs `unit` whose inputs hash to `input_hash` (UnitInputHash): its output and done record
/// written atomically; on failure a failed record and the log, nothing else. Returns false on
/// failure with the message in `error`; `input_error` tells a bad input (exit 2) from an internal
/// error (exit 1).
bool RunUnit(const UnitContext& context,
             const BatchManifest& manifest,
             const BatchUnit& unit,
             const std::string& input_hash,
             std::string* error,
             bool* input_error);

}  // namespace aerocal::tools
