#include "tools/resample_frame.h"

#include "calib/camera/camera_io.h"
#include "calib/core/error.h"
#include "stitch/io/stitch_result_json.h"
#include "tools/image_sources.h"

namespace aerocal::tools {

PreparedResample PrepareResample(const ResampleRequest& request) {
  PreparedResample p;
  // Any registered model: the virtual image is made through the sub-image mappings (pixels); the
  // interior is not used.
  const calib::Camera nominal = calib::ReadCamera(request.camera, calib::CameraModels::kAny);
  if (nominal.subimages.empty())
    throw InputError(request.camera + ": the camera has no sub-images");
  p.camera = stitch::ApplyStitchResult(nominal, request.mapping, request.frame);
  p.options.interpolation = stitch::ParseInterpolation(request.interpolation);
  p.options.fill = request.fill;
  p.options.strip_rows = request.strip_rows;
  if (p.options.strip_rows < 1) throw ConfigError("--strip-rows must be > 0");
  std::vector<std::string> ids;
  for (const auto& s : p.camera.subimages) ids.push_back(s.id);
  p.owned = OpenImages(request.images, ids, "sub-image", request.camera);
  for (const auto& source : p.owned) p.sources.push_back(source.get());
  const stitch::RasterInfo first = p.sources.front()->Info();
  const double max_value = first.bits == 8 ? 255.0 : 65535.0;
  if (request.fill < 0 || request.fill > max_value)
    throw ConfigError("--fill must be within 0.." + std::to_string(static_cast<int>(max_value)) +
                      " for " + std::to_string(first.bits) + "-bit images");
  p.virtual_info = {p.camera.width_px, p.camera.height_px, first.bands, first.bits};
  p.description = stitch::MappingDescription(
      p.camera, request.mapping + (request.frame.empty() ? "" : " frame " + request.frame));
  return p;
}

}  // namespace aerocal::tools
