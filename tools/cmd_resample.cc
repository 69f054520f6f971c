// aerocal resample: the virtual image of one frame from its sub-image files and a stitch result
// (stitch/resample/virtual_image.h).
#include <cctype>
#include <cstdio>
#include <memory>
#include <sstream>

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/io/stitch_result_json.h"
#include "stitch/resample/tiff_raster.h"
#include "stitch/resample/virtual_image.h"
#include "tools/command_registry.h"

namespace aerocal::tools {
namespace {

struct ResampleArgs {
  std::string camera, mapping, frame, images, out, interp = "bilinear";
  double fill = 0.0;
  int strip_rows = 256;
  bool bigtiff = false;
};

bool IsTiff(const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == "tif" || ext == "tiff";
}

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

  // ID=path pairs; every sub-image needs exactly one image.
  std::vector<std::unique_ptr<stitch::RasterSource>> owned(camera.subimages.size());
  std::stringstream list(args.images);
  std::string item;
  while (std::getline(list, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw ConfigError("--images: expected ID=PATH, got '" + item + "'");
    const std::string id = item.substr(0, eq), path = item.substr(eq + 1);
    const int k = camera.SubimageIndex(id);
    if (k < 0) throw ConfigError("--images: sub-image '" + id + "' is not in " + args.camera);
    if (owned[k]) throw ConfigError("--images: sub-image " + id + " given twice");
    if (IsTiff(path))
      owned[k] = stitch::OpenTiff(path);
    else
      owned[k] = std::make_unique<stitch::MemoryRaster>(stitch::ReadImageFile(path));
  }
  std::vector<stitch::RasterSource*> sources;
  for (size_t k = 0; k < owned.size(); ++k) {
    if (!owned[k]) throw ConfigError("--images: no image for sub-image " + camera.subimages[k].id);
    sources.push_back(owned[k].get());
  }
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
  app.add_option("--out", args->out, "Virtual image (TIFF; BigTIFF beyond 4 GB)")->required();
  app.add_option("--interp", args->interp, "bilinear | bicubic")->capture_default_str();
  app.add_option("--fill", args->fill, "Grey value of pixels no sub-image covers")
      ->capture_default_str();
  app.add_option("--strip-rows", args->strip_rows, "Rows per processing strip (memory bound), 1..65536")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  app.add_flag("--bigtiff", args->bigtiff, "Write BigTIFF even when classic TIFF would do");
  return [args] { return RunResample(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(resample, "resample",
                         "Resample the sub-images of a frame into the virtual image", Setup);

}  // namespace aerocal::tools
