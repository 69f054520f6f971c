// One rig exposure's stitched level image with the refined increments and offsets of a rig stitch
// run (stitch/rig/stitched_image.h): shared by `aerocal rig stitch --stitched-out` (tools/
// cmd_rig.cc, tiled TIFFs in the output set) and Python's `RigStitchResult.stitched_image`
// (tools/python/bind_rig.cc, numpy arrays).
#pragma once

#include "stitch/resample/raster.h"
#include "stitch/rig/stitched_image.h"
#include "tools/rig_stitch_run.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

namespace aerocal::tools {

/// The head images of one exposure, opened in rig order (<image>_<head>.tif under the folder,
/// HeadImagePath): TIFFs strip by strip, other formats read whole.
struct RigExposureImages {
  std::vector<std::unique_ptr<stitch::RasterSource>> owned;
  std::vector<stitch::RasterSource*> sources;
  int bits() const { return sources.front()->Info().bits; }
};
RigExposureImages OpenRigExposureImages(const calib::Rig& rig,
                                        const std::string& folder,
                                        const std::string& image);

/// The refined figures of exposure `image` in the run's result; nullptr where the result has none
/// (an exposure without ties in the adjustment).
const stitch::RigStitchExposureResult* RefinedExposure(const RigStitchRun& run,
                                                       const std::string& image);
/// The same, an InputError naming the image where the result has none (no stitched image of it).
const stitch::RigStitchExposureResult& RequireRefinedExposure(const RigStitchRun& run,
                                                              const std::string& image);

/// Makes the stitched image of exposure `image` (one of run.exposures, with a refined result)
/// from `heads` into `image_sink` (the virtual camera's format, the heads' depth) and `mask_sink`
/// (the same format, 8 bit): the pose with the refined increments and the fitted offsets, the
/// level plane at the exposure's z_ref. InputError naming the image when the run has no refined
/// result for it.
stitch::StitchedImageReport StitchRigExposure(const RigStitchRun& run,
                                              const std::string& image,
                                              RigExposureImages& heads,
                                              const stitch::StitchedImageOptions& options,
                                              stitch::RasterSink* image_sink,
                                              stitch::RasterSink* mask_sink);

/// The report's figures as `stitched_images[]` of the rig_stitch result lists them (size, depth,
/// valid pixels, radiometry per head, overlap disagreement per head pair, warnings).
nlohmann::json StitchedImageReportJson(const stitch::StitchedImageReport& report);

}  // namespace aerocal::tools
