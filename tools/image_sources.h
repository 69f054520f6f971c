// The `--images ID=PATH,ID=PATH,...` option of the resampling commands (resample, rig convert):
// one raster per id (TIFF read on demand, other formats through OpenCV into memory).
#pragma once

#include "stitch/resample/raster.h"

#include <memory>
#include <string>
#include <vector>

namespace aerocal::tools {

/// Opens one image per id of `ids` (in that order) from `images` ("ID=PATH,..."); `what` names the
/// ids in messages ("sub-image", "head"), `file` the file that lists them. ConfigError naming the
/// option for a malformed item, an unknown id, an id given twice or an id without an image.
std::vector<std::unique_ptr<stitch::RasterSource>> OpenImages(const std::string& images,
                                                              const std::vector<std::string>& ids,
                                                              const std::string& what,
                                                              const std::string& file);

}  // namespace aerocal::tools
