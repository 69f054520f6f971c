#include "tools/image_sources.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "stitch/resample/tiff_raster.h"

#include <algorithm>
#include <cctype>

namespace aerocal::tools {
namespace {

bool IsTiff(const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == "tif" || ext == "tiff";
}

}  // namespace

std::vector<std::unique_ptr<stitch::RasterSource>> OpenImages(const std::string& images,
                                                              const std::vector<std::string>& ids,
                                                              const std::string& what,
                                                              const std::string& file) {
  std::vector<std::unique_ptr<stitch::RasterSource>> owned(ids.size());
  for (const std::string& item : SplitCommaList(images)) {
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw ConfigError("--images: expected ID=PATH, got '" + item + "'");
    const std::string id = item.substr(0, eq), path = item.substr(eq + 1);
    const auto it = std::find(ids.begin(), ids.end(), id);
    if (it == ids.end()) throw ConfigError("--images: " + what + " '" + id + "' is not in " + file);
    const size_t k = static_cast<size_t>(it - ids.begin());
    if (owned[k]) throw ConfigError("--images: " + what + " " + id + " given twice");
    if (IsTiff(path))
      owned[k] = stitch::OpenTiff(path);
    else
      owned[k] = std::make_unique<stitch::MemoryRaster>(stitch::ReadImageFile(path));
  }
  for (size_t k = 0; k < owned.size(); ++k)
    if (!owned[k]) throw ConfigError("--images: no image for " + what + " " + ids[k]);
  return owned;
}

}  // namespace aerocal::tools
