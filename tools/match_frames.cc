#include "tools/match_frames.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/string_printf.h"
#include "stitch/image_io/image_io.h"
#include "stitch/matching/overlap_matcher.h"

#include <filesystem>
#include <map>

namespace aerocal::tools {
namespace {

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
      ThrowInputError(table.Where(row),
                      "sub-image " + sub + " (frame " + frame + ") is not in the camera file");
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
      ThrowInputError(table.Where(row),
                      "sub-image " + sub + " of frame " + frame + " listed twice");
  }
  if (frames.empty()) throw InputError(list + ": no frames listed");
  for (const auto& [frame, paths] : frames)
    for (const calib::SubimageMapping& sub : camera.subimages)
      if (!paths.count(sub.id))
        throw InputError(list + ": frame " + frame + ": no image for sub-image " + sub.id);
  return frames;
}

std::vector<stitch::GrayImage> LoadFrame(const calib::Camera& camera,
                                         const std::string& frame,
                                         const std::map<std::string, std::string>& paths) {
  for (const auto& [id, path] : paths)
    if (camera.SubimageIndex(id) < 0)
      throw InputError(path + ": sub-image " + id + " (frame " + frame +
                       ") is not in the camera file");
  std::vector<stitch::GrayImage> images;
  for (const calib::SubimageMapping& sub : camera.subimages) {
    const auto it = paths.find(sub.id);
    if (it == paths.end())
      throw InputError("frame " + frame + ": no image for sub-image " + sub.id);
    images.push_back(stitch::ReadSubimage(it->second, sub));
  }
  return images;
}

}  // namespace

MatchRun RunMatching(const MatchRequest& args) {
  // Any registered model: matching works on the sub-images and their mappings (pixels) only.
  const calib::Camera camera = calib::ReadCamera(args.camera, calib::CameraModels::kAny);
  if (camera.subimages.size() < 2)
    throw InputError(args.camera + ": matching needs a camera with two or more sub-images");
  if (args.list.empty() == args.images.empty())
    throw ConfigError("give either --images (with --frame) or --list");
  if (!args.images.empty() && args.frame.empty()) throw ConfigError("--images needs --frame");
  if (args.lsm != "on" && args.lsm != "off") throw ConfigError("--lsm must be on or off");
  stitch::MatchOptions options;
  options.search = stitch::ParseSearch(args.search);
  if (!args.detector.empty()) {
    if (options.search == stitch::Search::kPredicted)
      throw ConfigError(
          "--detector applies to --search descriptors (the predicted search uses "
          "Foerstner points of the first sub-image of each strip)");
    options.detector = stitch::ParseDetector(args.detector);
  }
  options.use_lsm = args.lsm == "on";
  options.sigma_px = args.sigma_px;
  options.cell_px = args.cell_px;
  options.Validate();

  const FrameImages frames =
      args.list.empty() ? FromImagesOption(args.frame, args.images) : FromList(args.list, camera);
  MatchRun run;
  Progress progress("match", static_cast<long>(frames.size()));
  run.table = StringPrintf("%-6s %-10s %7s %7s %6s %6s %7s %7s %7s %6s %8s\n",
                           "frame",
                           "strip",
                           "kp_a",
                           "kp_b",
                           "ratio",
                           "ransac",
                           "lsm",
                           "lsm_nc",
                           "lsm_low",
                           "points",
                           "coverage");
  for (const auto& [frame, paths] : frames) {
    const stitch::FrameMatches m =
        stitch::MatchFrame(camera, LoadFrame(camera, frame, paths), frame, options);
    run.rows.insert(run.rows.end(), m.observations.begin(), m.observations.end());
    for (const stitch::StripReport& s : m.strips)
      run.table += StringPrintf("%-6s %-10s %7d %7d %6d %6d %7d %7d %7d %6d %8.2f\n",
                                frame.c_str(),
                                s.name.c_str(),
                                s.keypoints_a,
                                s.keypoints_b,
                                s.ratio_matches,
                                s.ransac_inliers,
                                s.lsm_tried,
                                s.lsm_not_converged,
                                s.lsm_poor_precision,
                                s.points,
                                s.Coverage());
    progress.Advance();
  }
  progress.Finish();
  return run;
}

}  // namespace aerocal::tools
