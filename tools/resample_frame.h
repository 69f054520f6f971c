// The inputs of one frame's resampling (`aerocal resample` and Python's `aerocal.resample`): the
// camera with the stitch result's mappings, one raster per sub-image, the options, and the TIFF
// description, read and checked once for both callers.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/resample/raster.h"
#include "stitch/resample/virtual_image.h"

#include <memory>
#include <string>
#include <vector>

namespace aerocal::tools {

struct ResampleRequest {
  std::string camera, mapping, frame;
  std::string images;  // "I=a.tif,II=b.tif,..."
  std::string interpolation = "bilinear";
  double fill = 0.0;
  int strip_rows = 256;
};

struct PreparedResample {
  calib::Camera camera;  // the nominal camera with the mappings of `mapping` (and `frame`)
  std::vector<std::unique_ptr<stitch::RasterSource>> owned;
  std::vector<stitch::RasterSource*> sources;  // in the camera's sub-image order
  stitch::ResampleOptions options;
  stitch::RasterInfo
      virtual_info;         // the virtual image: format of the camera, bands and bits of the inputs
  std::string description;  // the TIFF description (stitch::MappingDescription)
};

/// Reads and checks everything; InputError / ConfigError naming the file or the option
/// (`--fill` outside the images' grey range, a camera without sub-images, ...).
PreparedResample PrepareResample(const ResampleRequest& request);

}  // namespace aerocal::tools
