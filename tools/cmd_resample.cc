// aerocal resample: the virtual image of one frame from its sub-image files and a stitch result
// (stitch/resample/virtual_image.h).
#include <cstdio>
#include <memory>
#include <sstream>

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "stitch/io/stitch_result_json.h"
#include "stitch/resample/tiff_raster.h"
#include "stitch/resample/virtual_image.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/image_sources.h"

namespace aerocal::tools {
namespace {

struct ResampleArgs {
  std::string camera, mapping, frame, images, out, interp = "bilinear";
  double fill = 0.0;
  int strip_rows = 256;
  bool bigtiff = false;
};

int RunResample(const ResampleArgs& args) {
  CheckOutputFile(args.out, "--out");
  const calib::Camera nominal = calib::ReadCamera(args.camera);
  if (nominal.subimages.empty()) throw InputError(args.camera + ": the camera has no sub-images");
  const calib::Camera camera = stitch::ApplyStitchResult(nominal, args.mapping, args.frame);
  stitch::ResampleOptions options;
  options.interpolation = stitch::ParseInterpolation(args.interp);
  options.fill = args.fill;
  options.strip_rows = args.strip_rows;
  if (options.strip_rows < 1) throw ConfigError("--strip-rows must be > 0");

  std::vector<std::string> ids;
  for (const auto& s : camera.subimages) ids.push_back(s.id);
  const auto owned = OpenImages(args.images, ids, "sub-image", args.camera);
  std::vector<stitch::RasterSource*> sources;
  for (const auto& source : owned) sources.push_back(source.get());
  const stitch::RasterInfo first = sources.front()->Info();
  const double max_value = first.bits == 8 ? 255.0 : 65535.0;
  if (args.fill < 0 || args.fill > max_value)
    throw ConfigError("--fill must be within 0.." + std::to_string(static_cast<int>(max_value)) +
                      " for " + std::to_string(first.bits) + "-bit images");

  stitch::TiffWriteOptions tiff;
  tiff.description = stitch::MappingDescription(
      camera, args.mapping + (args.frame.empty() ? "" : " frame " + args.frame));
  tiff.force_bigtiff = args.bigtiff;
  stitch::TiffWriter writer(args.out, {camera.width_px, camera.height_px, first.bands, first.bits},
                            tiff);
  const stitch::ResampleReport report =
      stitch::ResampleVirtualImage(camera, sources, &writer, options);
  writer.Commit();
  const double mpx = static_cast<double>(camera.width_px) * camera.height_px / 1e6;
  std::printf("virtual image %d x %d px (%d bit, %d band%s%s): %ld px covered, %ld in overlaps, "
              "%ld filled; %.1f Mpx/s\n",
              camera.width_px, camera.height_px, first.bits, first.bands, first.bands > 1 ? "s" : "",
              writer.bigtiff() ? ", BigTIFF" : "", report.covered, report.overlap, report.filled,
              mpx / std::max(report.seconds, 1e-9));
  return kExitOk;
}

CommandRun Setup(CLI::App& app) {
  auto args = std::make_shared<ResampleArgs>();
  app.add_option("--camera", args->camera, "Camera file (YAML) with the sub-images")->required();
  app.add_option("--mapping", args->mapping, "Stitch result JSON (aerocal stitch)")->required();
  app.add_option("--frame", args->frame, "Frame whose mappings are used (default: the top level)");
  app.add_option("--images", args->images, "Sub-image files: I=a.tif,II=b.tif,...")->required();
  app.add_option("--out", args->out, "Output file: the virtual image (TIFF; BigTIFF beyond 4 GB)")->required();
  app.add_option("--interp", args->interp, "bilinear | bicubic")->capture_default_str();
  app.add_option("--fill", args->fill, "Grey value of pixels no sub-image covers")->check(FiniteRange(0, 65535))
      ->capture_default_str();
  app.add_option("--strip-rows", args->strip_rows, "Rows per processing strip (memory bound), 1..65536")
      ->check(FiniteRange(1, 65536))
      ->capture_default_str();
  app.add_flag("--bigtiff", args->bigtiff, "Write BigTIFF even when classic TIFF would do");
  return [args] { return RunResample(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(resample, "resample",
                         "Resample the sub-images of a frame into the virtual image", Setup);

}  // namespace aerocal::tools
