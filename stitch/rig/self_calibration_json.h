// The result of `aerocal rig stitch` (kind "rig_stitch"; stitch/README.md "Self-calibrating
// stitching"): the issue-16 keys `rig_exposures` (FORMATS.md "Multi-head rig": per exposure and
// head domega, dphi, dkappa in degrees, dT_ms, sigma {...}; null where held or not determinable)
// and `stitching_rms_px: {before: {fit: {per_coordinate, pair_2d, pairs, ties}, check: {...}},
// after: {...}}` for the flight, each exposure and each zone (virtual pixels of the level image;
// the two metrics differ by sqrt(2), named in `metric`), plus sigma0, the time-offset correlations
// by name, the snooping and its standard positions, the plane model's relief displacement and the
// failures that make the run exit 3. And the terminal summary of the same result.
#pragma once

#include "calib/camera/rig.h"
#include "stitch/rig/self_calibration.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace aerocal::stitch {

/// Where the inputs came from, written into the document as given.
struct RigStitchSources {
  std::string camera, project;
  std::optional<double> relief_m;  // relief of the block off the plane (m); nullopt: not given
};

nlohmann::json RigStitchToJson(const calib::Rig& rig,
                               const RigStitchOptions& options,
                               const RigStitchResult& result,
                               const RigStitchSources& sources);

/// Lines for people: sigma0, the RMS before -> after per exposure and over the flight, the time
/// offsets, the rejections, the relief displacement, the warnings and failures.
std::string FormatRigStitchSummary(const RigStitchOptions& options,
                                   const RigStitchResult& result,
                                   const RigStitchSources& sources);

}  // namespace aerocal::stitch
