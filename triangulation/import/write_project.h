// Writes an imported block as FORMATS.md files into a folder: camera_<id>.yaml, exposures.csv,
// observations.csv, points.csv and project.yaml naming them (with the frame stated), so the
// conversion is done once and `aerocal adjust --project FOLDER` runs on the result.
#pragma once

#include "triangulation/block/block.h"

#include <string>

namespace aerocal::triangulation {

/// The imported block as `adjust` can take it: an exposure without any observation is left out
/// with a warning naming it (and `source`); InputError("SOURCE: ...") when no block remains (no
/// observations, fewer than two observed exposures, a camera without a usable format).
Project UsableImportedBlock(const Project& project, const std::string& source);

/// The `frame:` line of project.yaml for the frame (crs: with its keys; else projected: TEXT).
std::string FrameYaml(const FrameSpec& frame);

/// Every file is written atomically; the folder is created when missing.
void WriteProjectFolder(const Project& project, const std::string& folder);

}  // namespace aerocal::triangulation
