#include "tools/pushbroom_control_run.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/line_camera_io.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "stitch/image_io/image_io.h"
#include "triangulation/block/block_io.h"
#include "triangulation/pushbroom/reference_frames.h"

#include <filesystem>

namespace aerocal::tools {
namespace {

// Most cells of the L1 image of `pushbroom control` (two float maps and the image: about 1.2 GB).
constexpr double kMaxL1Cells = 1e8;

// The image of an exposure in `folder`: the id as a file name, else with .png, .tif, .jpg;
// `where` names the exposure's source in the error.
std::string ReferenceImagePath(const std::string& folder,
                               const triangulation::Exposure& e,
                               const std::string& where) {
  namespace fs = std::filesystem;
  for (const char* ext : {"", ".png", ".tif", ".tiff", ".jpg"}) {
    const fs::path p = fs::path(folder) / (e.image + ext);
    if (fs::is_regular_file(p)) return p.string();
  }
  throw InputError(where + ": no image '" + e.image + "' (.png, .tif, .jpg) in " + folder);
}

}  // namespace

PushbroomControlRun RunPushbroomControl(const PushbroomControlRequest& request) {
  if (request.reference_exposures.empty() == request.reference_result.empty())
    throw ConfigError("give one of --reference-exposures and --reference-result");
  request.options.Validate();
  const calib::LineCamera camera = calib::ReadLineCamera(request.camera);
  const auto pos = triangulation::PosTrajectory::Read(request.pos);
  const calib::Camera reference_camera = calib::ReadCamera(request.reference_camera);
  // The orientations: exposures.csv, or the block result of `aerocal adjust` (its used exposures).
  int skipped = 0;
  const auto exposures =
      request.reference_result.empty()
          ? triangulation::ReadExposures(request.reference_exposures)
          : triangulation::ReadAdjustedExposures(request.reference_result, &skipped);
  // A list without a reference exposure (a header only) is bad input, not a failed control (exit
  // 2).
  if (exposures.empty())
    throw InputError(request.reference_result.empty()
                         ? request.reference_exposures + ":1: no reference exposure (a header only)"
                         : request.reference_result + ": no used reference exposure");
  // The L1 image's size comes from --mean-height-m and --gsd-m: bounded before anything is
  // allocated (a plane far from the terrain gave a footprint of millions of cells per side).
  {
    triangulation::L1Grid grid;
    try {
      grid = triangulation::MakeL1Grid(
          camera, pos, request.options.mean_height_m, request.options.gsd_m);
    } catch (const InputError& e) {  // its messages say "pos.csv" for any POS file: name the inputs
      throw InputError(std::string(e.what()) + " (--pos " + request.pos + ", --camera " +
                       request.camera + ", --mean-height-m " +
                       FormatNumber(request.options.mean_height_m) + ")");
    }
    const double cells = double(grid.width) * double(grid.height);
    if (!(cells <= kMaxL1Cells))
      throw ConfigError("--mean-height-m / --gsd-m: the L1 image would have " +
                        std::to_string(grid.width) + " x " + std::to_string(grid.height) +
                        " cells, at most " + FormatNumber(kMaxL1Cells) +
                        " (the plane Z = " + FormatNumber(request.options.mean_height_m) +
                        " m is far from the line footprint)");
  }
  std::vector<std::string> image_paths;
  for (const auto& e : exposures)
    image_paths.push_back(ReferenceImagePath(
        request.reference_images,
        e,
        request.reference_result.empty()
            ? request.reference_exposures + ":" + std::to_string(e.line)
            : request.reference_result + ": exposures[" + std::to_string(e.line - 1) + "]"));
  const stitch::GrayImage line_image = stitch::ReadGrayImage(request.line_image);
  std::vector<triangulation::ReferenceFrame> frames;
  for (size_t k = 0; k < exposures.size(); ++k) {
    triangulation::ReferenceFrame f;
    f.id = exposures[k].image;
    f.center_m = exposures[k].center_m;
    f.opk_rad = exposures[k].opk_rad;
    f.image = stitch::ReadGrayImage(image_paths[k]);
    frames.push_back(std::move(f));
  }
  PushbroomControlRun run;
  run.result = triangulation::MakeCloudControl(
      camera, pos, line_image, reference_camera, frames, request.options);
  run.reference_exposures = static_cast<int>(exposures.size());
  run.skipped_exposures = skipped;
  run.document = triangulation::CloudControlToJson(run.result, request.options);
  return run;
}

}  // namespace aerocal::tools
