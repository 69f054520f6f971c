// aerocal match: tie points in the overlap strips of multi-CCD frames, measured on the pixels of
// the sub-images (stitch/matching/), written as stitch_obs.csv (FORMATS.md) for `aerocal stitch`.
// One frame (--frame, --images I=a.tif,II=b.tif,...) or a flight (--list: CSV frame,subimage,image
// with paths relative to the list file).
#include "calib/core/atomic_file.h"
#include "stitch/matching/overlap_matcher.h"
#include "tools/command_registry.h"
#include "tools/match_frames.h"
#include "tools/option_ranges.h"

#include <cstdio>

namespace aerocal::tools {
namespace {

struct MatchArgs : MatchRequest {
  std::string out;
  bool append = false;
};

int RunMatch(const MatchArgs& args) {
  CheckOutputFile(args.out, "--out");
  const MatchRun run = RunMatching(args);
  // The per-strip table is printed after the progress bar (stderr) so the two never interleave.
  std::fputs(run.table.c_str(), stdout);
  std::printf(
      "lsm: matches refined; lsm_nc: dropped, not converged; lsm_low: dropped, poor precision\n");
  stitch::WriteMatchedObservations(args.out, run.rows, args.append, args.sigma_px);
  return kExitOk;
}

CommandRun Setup(CLI::App& app) {
  auto args = std::make_shared<MatchArgs>();
  app.add_option("--camera", args->camera, "Camera file (YAML) with nominal sub-image mappings")
      ->required();
  app.add_option("--frame", args->frame, "Frame (exposure) id written to the file");
  app.add_option("--images", args->images, "Sub-image files of the frame: I=a.tif,II=b.tif,...");
  app.add_option(
      "--list", args->list, "Flight: CSV frame,subimage,image (paths relative to the list file)");
  app.add_option("--out", args->out, "Output file: the stitching observations (stitch_obs.csv)")
      ->required();
  app.add_option("--search",
                 args->search,
                 "predicted: Foerstner points found by correlation at the nominal mappings' "
                 "prediction | descriptors: keypoints of both sub-images matched by descriptors")
      ->capture_default_str();
  app.add_option(
      "--detector",
      args->detector,
      "With --search descriptors: sift (default) | foerstner (on Wallis-filtered strips)");
  app.add_option("--lsm", args->lsm, "on | off: least-squares matching refinement")
      ->capture_default_str();
  app.add_option("--sigma-px",
                 args->sigma_px,
                 "sigma_px (px) written without LSM, and for rows of an appended file lacking it")
      ->check(PositiveUpTo(100))
      ->capture_default_str();
  app.add_option("--cell", args->cell_px, "Grid cell along the strips (virtual px): one tie each")
      ->check(FiniteRange(1, 1e5))
      ->capture_default_str();
  app.add_flag("--append", args->append, "Add the frames to an existing --out file");
  return [args] { return RunMatch(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(match,
                         "match",
                         "Tie points in the overlap strips of multi-CCD frames (stitch_obs.csv)",
                         Setup);

}  // namespace aerocal::tools
