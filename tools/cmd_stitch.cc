// aerocal stitch: sub-image mapping adjustment of one frame or a whole flight
// (stitch/adjustment/, result keys in stitch/io/stitch_result_json.h and stitch/README.md).
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/result_file.h"
#include "stitch/adjustment/flight_stability.h"
#include "stitch/io/stitch_from_files.h"
#include "stitch/io/stitch_result_json.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"

#include <cstdio>
#include <sstream>

namespace aerocal::tools {
namespace {

struct StitchArgs {
  std::string camera, obs, model = "auto", base, out;
  double sigma_px = 0.1;
  double alpha = 0.05;
  bool no_snooping = false;
};

// What a user must see without opening the JSON: the fit, the gross errors and, above all, the
// predicted precision of the sub-image corners (a small sigma0 says nothing about a weakly tied
// outer CCD).
void PrintSummary(const stitch::BatchResult& result, const std::string& out) {
  double worst_corner = 0.0;
  std::string worst_where;
  int rejected = 0, single = 0, no_precision = 0;
  for (const auto& run : result.frames) {
    const auto& a = run.adjustment;
    rejected += static_cast<int>(a.rejected.size());
    single += a.n_single_ray_points;
    if (!a.covariance_ok) ++no_precision;
    for (const auto& s : a.subimages)
      if (!s.base && s.max_corner_sigma_px > worst_corner) {
        worst_corner = s.max_corner_sigma_px;
        worst_where = "frame " + a.frame + ", sub-image " + s.id;
      }
    if (result.frames.size() <= 10)
      std::printf(
          "frame %s: %s, sigma0 %.3f px, redundancy %d, %d tie points, %zu rejected, "
          "largest corner sigma %.2f px%s\n",
          a.frame.c_str(),
          std::string(calib::MappingModelName(a.model)).c_str(),
          a.sigma0_px,
          a.redundancy,
          a.n_ties,
          a.rejected.size(),
          a.max_corner_sigma_px,
          a.converged ? "" : " (NOT converged)");
  }
  if (result.frames.size() > 10)
    std::printf(
        "%zu frames, %d observations rejected as gross errors\n", result.frames.size(), rejected);
  if (!worst_where.empty())
    std::printf("largest predicted corner sigma: %.2f px (%s)%s\n",
                worst_corner,
                worst_where.c_str(),
                worst_corner > 1.0
                    ? ": weakly determined, whatever sigma0 says; add reference points or "
                      "ties on the outer sub-images"
                    : "");
  if (no_precision > 0)
    std::printf("warning: %d frame(s) without a precision estimate (see diagnostics)\n",
                no_precision);
  if (single > 0)
    std::printf("%d point(s) measured in one sub-image only carry no equation and were not used\n",
                single);
  std::printf("result: %s\n", out.c_str());
}

int RunStitch(const StitchArgs& args) {
  CheckOutputFile(args.out, "--out");
  // Any registered model: the stitching adjusts the sub-image mappings in pixels and reads no
  // interior term.
  const calib::Camera camera = calib::ReadCamera(args.camera, calib::CameraModels::kAny);
  const stitch::BatchOptions options =
      stitch::BatchOptionsFromText(camera, args.model, args.base, args.alpha, !args.no_snooping);
  const auto frames = stitch::ReadStitchFrames(camera, args.camera, args.obs, args.sigma_px);
  Progress progress("stitch", static_cast<long>(frames.size()));
  const stitch::BatchResult result = stitch::RunStitchBatch(camera, frames, options, &progress);
  progress.Finish();
  const nlohmann::json doc = stitch::StitchResultToJson(result, options);
  WriteResult(args.out, "stitch", doc);
  PrintSummary(result, args.out);
  return doc.at("converged").get<bool>() ? kExitOk : kExitNotConverged;
}

CommandRun Setup(CLI::App& app) {
  auto args = std::make_shared<StitchArgs>();
  app.add_option("--camera", args->camera, "Camera file (YAML) with the sub-images")->required();
  app.add_option("--obs", args->obs, "stitch_obs.csv: one or many frames")->required();
  app.add_option("--model",
                 args->model,
                 "translation | conformal | affine | projective | auto (F test at --alpha)")
      ->capture_default_str();
  app.add_option("--base",
                 args->base,
                 "Comma-separated sub-images that keep the camera file's mapping (the datum)");
  app.add_option("--sigma-px", args->sigma_px, "A-priori sigma (px) of rows without sigma_px")
      ->check(PositiveUpTo(100))
      ->capture_default_str();
  app.add_option("--alpha", args->alpha, "Level of the model-choice F test and stability flags")
      ->check(FiniteRange(0, 1, true))
      ->capture_default_str();
  app.add_flag("--no-snooping", args->no_snooping, "Do not search gross errors");
  app.add_option("--out", args->out, "Output file: the result JSON")->required();
  return [args] { return RunStitch(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(stitch,
                         "stitch",
                         "Adjust the sub-image mappings of a multi-CCD camera per frame",
                         Setup);

}  // namespace aerocal::tools
