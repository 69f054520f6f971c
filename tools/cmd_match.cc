// aerocal match: tie points in the overlap strips of multi-CCD frames, measured on the pixels of
// the sub-images (stitch/matching/), written as stitch_obs.csv (FORMATS.md) for `aerocal stitch`.
// One frame (--frame, --images I=a.tif,II=b.tif,...) or a flight (--list: CSV frame,subimage,image
// with paths relative to the list file).
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include "calib/camera/camera_io.h"
#include "calib/core/csv.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/string_printf.h"
#include "stitch/image_io/image_io.h"
#include "stitch/matching/overlap_matcher.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"

namespace aerocal::tools {
namespace {

struct MatchArgs {
  std::string camera, frame, images, list, out, detector = "sift", lsm = "on";
  bool append = false;
  double sigma_px = 0.3;
  double cell_px = 100.0;
};

// frame -> sub-image id -> image path, frames in order of first appearance.
using FrameImages = std::vector<std::pair<std::string, std::map<std::string, std::string>>>;

FrameImages FromImagesOption(const std::string& frame, const std::string& images) {
  std::map<std::string, std::string> paths;
  for (const std::string& item : SplitCommaList(images)) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw ConfigError("--images: expected ID=PATH, got '" + item + "'");
    if (!paths.emplace(item.substr(0, eq), item.substr(eq + 1)).second)
      throw ConfigError("--images: sub-image " + item.substr(0, eq) + " given twice");
  }
  return {{frame, paths}};
}

// The list's rows are checked at their line: a sub-image the camera lacks, an image file that is
// not a readable regular file, a frame missing a sub-image (errors name list.csv:LINE).
FrameImages FromList(const std::string& list, const calib::Camera& camera) {
  const CsvTable table = CsvTable::Read(list);
  table.RequireColumns({"frame", "subimage", "image"});
  table.RejectUnknownColumns({"frame", "subimage", "image"});
  const std::filesystem::path dir = std::filesystem::path(list).parent_path();
  FrameImages frames;
  std::map<std::string, std::size_t> index;
  for (const CsvTable::Row& row : table.rows()) {
    const std::string frame = table.String(row, "frame");
    const std::string sub = table.String(row, "subimage");
    std::filesystem::path path = table.String(row, "image");
    if (frame.empty() || sub.empty() || path.empty())
      ThrowInputError(table.Where(row), "frame, subimage and image must not be empty");
    if (path.is_relative()) path = dir / path;
    if (camera.SubimageIndex(sub) < 0)
      ThrowInputError(table.Where(row), "sub-image " + sub + " (frame " + frame +
                                            ") is not in the camera file");
    try {
      CheckInputFile(path.string());
    } catch (const InputError& e) {
      ThrowInputError(table.Where(row), std::string("image ") + e.what());
    }
    if (!index.count(frame)) {
      index[frame] = frames.size();
      frames.push_back({frame, {}});
    }
    if (!frames[index[frame]].second.emplace(sub, path.string()).second)
      ThrowInputError(table.Where(row), "sub-image " + sub + " of frame " + frame + " listed twice");
  }
  if (frames.empty()) throw InputError(list + ": no frames listed");
  for (const auto& [frame, paths] : frames)
    for (const calib::SubimageMapping& sub : camera.subimages)
      if (!paths.count(sub.id))
        throw InputError(list + ": frame " + frame + ": no image for sub-image " + sub.id);
  return frames;
}

std::vector<stitch::GrayImage> LoadFrame(const calib::Camera& camera, const std::string& frame,
                                         const std::map<std::string, std::string>& paths) {
  for (const auto& [id, path] : paths)
    if (camera.SubimageIndex(id) < 0)
      throw InputError(path + ": sub-image " + id + " (frame " + frame + ") is not in the camera file");
  std::vector<stitch::GrayImage> images;
  for (const calib::SubimageMapping& sub : camera.subimages) {
    const auto it = paths.find(sub.id);
    if (it == paths.end()) throw InputError("frame " + frame + ": no image for sub-image " + sub.id);
    images.push_back(stitch::ReadSubimage(it->second, sub));
  }
  return images;
}

int RunMatch(const MatchArgs& args) {
  CheckOutputFile(args.out, "--out");
  const calib::Camera camera = calib::ReadCamera(args.camera);
  if (camera.subimages.size() < 2)
    throw InputError(args.camera + ": matching needs a camera with two or more sub-images");
  if (args.list.empty() == args.images.empty())
    throw ConfigError("give either --images (with --frame) or --list");
  if (!args.images.empty() && args.frame.empty()) throw ConfigError("--images needs --frame");
  if (args.lsm != "on" && args.lsm != "off") throw ConfigError("--lsm must be on or off");
  stitch::MatchOptions options;
  options.detector = stitch::ParseDetector(args.detector);
  options.use_lsm = args.lsm == "on";
  options.sigma_px = args.sigma_px;
  options.cell_px = args.cell_px;
  options.Validate();

  const FrameImages frames =
      args.list.empty() ? FromImagesOption(args.frame, args.images) : FromList(args.list, camera);
  std::vector<stitch::StitchObservation> rows;
  Progress progress("match", static_cast<long>(frames.size()));
  // The per-strip table is printed after the progress bar (stderr) so the two never interleave.
  std::string table = StringPrintf("%-6s %-10s %7s %7s %6s %6s %7s %7s %7s %6s %8s\n", "frame", "strip", "kp_a",
                             "kp_b", "ratio", "ransac", "lsm", "lsm_nc", "lsm_low", "points", "coverage");
  for (const auto& [frame, paths] : frames) {
    const stitch::FrameMatches m =
        stitch::MatchFrame(camera, LoadFrame(camera, frame, paths), frame, options);
    rows.insert(rows.end(), m.observations.begin(), m.observations.end());
    for (const stitch::StripReport& s : m.strips)
      table += StringPrintf("%-6s %-10s %7d %7d %6d %6d %7d %7d %7d %6d %8.2f\n", frame.c_str(), s.name.c_str(),
                      s.keypoints_a, s.keypoints_b, s.ratio_matches, s.ransac_inliers, s.lsm_tried,
                      s.lsm_not_converged, s.lsm_poor_precision, s.points, s.Coverage());
    progress.Advance();
  }
  progress.Finish();
  std::fputs(table.c_str(), stdout);
  std::printf("lsm: matches refined; lsm_nc: dropped, not converged; lsm_low: dropped, poor precision\n");
  stitch::WriteMatchedObservations(args.out, rows, args.append, args.sigma_px);
  return kExitOk;
}

CommandRun Setup(CLI::App& app) {
  auto args = std::make_shared<MatchArgs>();
  app.add_option("--camera", args->camera, "Camera file (YAML) with nominal sub-image mappings")
      ->required();
  app.add_option("--frame", args->frame, "Frame (exposure) id written to the file");
  app.add_option("--images", args->images, "Sub-image files of the frame: I=a.tif,II=b.tif,...");
  app.add_option("--list", args->list,
                 "Flight: CSV frame,subimage,image (paths relative to the list file)");
  app.add_option("--out", args->out, "Output file: the stitching observations (stitch_obs.csv)")->required();
  app.add_option("--detector", args->detector, "sift | foerstner (on Wallis-filtered strips)")
      ->capture_default_str();
  app.add_option("--lsm", args->lsm, "on | off: least-squares matching refinement")
      ->capture_default_str();
  app.add_option("--sigma-px", args->sigma_px,
                 "sigma_px (px) written without LSM, and for rows of an appended file lacking it")->check(PositiveUpTo(100))
      ->capture_default_str();
  app.add_option("--cell", args->cell_px, "Grid cell along the strips (virtual px): one tie each")->check(FiniteRange(1, 1e5))
      ->capture_default_str();
  app.add_flag("--append", args->append, "Add the frames to an existing --out file");
  return [args] { return RunMatch(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(match, "match",
                         "Tie points in the overlap strips of multi-CCD frames (stitch_obs.csv)",
                         Setup);

}  // namespace aerocal::tools
