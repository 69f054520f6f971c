// The stitching result document (FORMATS.md "Results (JSON)", kind "stitch"), and reading the
// mappings back for resampling.
//
// Single frame: the frame's result at the top level. Several frames: the top level holds the
// pooled statistics (sigma0 = sqrt(sum vtpv / sum r), redundancy = sum r, iterations = max,
// converged = all), `model` (the requested model, or for --model auto the one chosen most often),
// `subimages` with the flight mean of every parameter and as sigma its standard deviation over
// the frames, `frames: [...]` (each entry the same keys as a single-frame result) and `stability`.
// Keys added to FORMATS.md's are documented in stitch/README.md.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/adjustment/flight_stability.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::stitch {

/// One frame's result (with its model-choice table when `choice` is set).
nlohmann::json FrameResultToJson(const FrameAdjustment& adjustment, const ModelChoice* choice);

/// The whole document for a batch (one frame: that frame at the top level).
nlohmann::json StitchResultToJson(const BatchResult& result, const BatchOptions& options);

/// The camera with the mappings of a stitch result: those of frame `frame`, or the top level's
/// when `frame` is empty. InputError("PATH: ...") when the document, the frame or a sub-image of
/// the camera is missing.
calib::Camera ApplyStitchResult(const calib::Camera& camera,
                                const std::string& path,
                                const std::string& frame);

/// The same from a stitch document already read (a stitch result, or a flight result's
/// `stitching`); `path` names it in the errors.
calib::Camera ApplyStitchDocument(const calib::Camera& camera,
                                  const nlohmann::json& doc,
                                  const std::string& path,
                                  const std::string& frame);

}  // namespace aerocal::stitch
