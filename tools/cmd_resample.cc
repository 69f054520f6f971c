// aerocal resample: the virtual image of one frame from its sub-image files and a stitch result
// (stitch/resample/virtual_image.h).
#include "calib/core/atomic_file.h"
#include "stitch/resample/tiff_raster.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/resample_frame.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>

namespace aerocal::tools {
namespace {

struct ResampleArgs {
  ResampleRequest request;
  std::string out;
  bool bigtiff = false;
};

int RunResample(const ResampleArgs& args) {
  CheckOutputFile(args.out, "--out");
  PreparedResample p = PrepareResample(args.request);
  stitch::TiffWriteOptions tiff;
  tiff.description = p.description;
  tiff.force_bigtiff = args.bigtiff;
  stitch::TiffWriter writer(args.out, p.virtual_info, tiff);
  const stitch::ResampleReport report =
      stitch::ResampleVirtualImage(p.camera, p.sources, &writer, p.options);
  writer.Commit();
  const calib::Camera& camera = p.camera;
  const double mpx = static_cast<double>(camera.width_px) * camera.height_px / 1e6;
  std::printf(
      "virtual image %d x %d px (%d bit, %d band%s%s): %ld px covered, %ld in overlaps, "
      "%ld filled; %.1f Mpx/s\n",
      camera.width_px,
      camera.height_px,
      p.virtual_info.bits,
      p.virtual_info.bands,
      p.virtual_info.bands > 1 ? "s" : "",
      writer.bigtiff() ? ", BigTIFF" : "",
      report.covered,
      report.overlap,
      report.filled,
      mpx / std::max(report.seconds, 1e-9));
  return kExitOk;
}

CommandRun Setup(CLI::App& app) {
  auto args = std::make_shared<ResampleArgs>();
  app.add_option("--camera", args->request.camera, "Camera file (YAML) with the sub-images")
      ->required();
  app.add_option("--mapping", args->request.mapping, "Stitch result JSON (aerocal stitch)")
      ->required();
  app.add_option(
      "--frame", args->request.frame, "Frame whose mappings are used (default: the top level)");
  app.add_option("--images", args->request.images, "Sub-image files: I=a.tif,II=b.tif,...")
      ->required();
  app.add_option("--out", args->out, "Output file: the virtual image (TIFF; BigTIFF beyond 4 GB)")
      ->required();
  app.add_option("--interp", args->request.interpolation, "bilinear | bicubic")
      ->capture_default_str();
  app.add_option("--fill", args->request.fill, "Grey value of pixels no sub-image covers")
      ->check(FiniteRange(0, 65535))
      ->capture_default_str();
  app.add_option("--strip-rows",
                 args->request.strip_rows,
                 "Rows per processing strip (memory bound), 1..65536")
      ->check(FiniteRange(1, 65536))
      ->capture_default_str();
  app.add_flag("--bigtiff", args->bigtiff, "Write BigTIFF even when classic TIFF would do");
  return [args] { return RunResample(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(resample,
                         "resample",
                         "Resample the sub-images of a frame into the virtual image",
                         Setup);

}  // namespace aerocal::tools
