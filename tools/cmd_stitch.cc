// aerocal stitch: sub-image mapping adjustment of one frame or a whole flight
// (stitch/adjustment/, result keys in stitch/io/stitch_result_json.h and stitch/README.md).
#include <sstream>

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "stitch/adjustment/flight_stability.h"
#include "stitch/io/stitch_result_json.h"
#include "tools/command_registry.h"

namespace aerocal::tools {
namespace {

struct StitchArgs {
  std::string camera, obs, model = "auto", base, out;
  double sigma_px = 0.1;
  double alpha = 0.05;
  bool no_snooping = false;
};

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

int RunStitch(const StitchArgs& args) {
  const calib::Camera camera = calib::ReadCamera(args.camera);
  if (camera.subimages.empty())
    throw InputError(args.camera + ": the camera has no sub-images to stitch");
  stitch::BatchOptions options;
  if (args.model != "auto") {
    options.model = calib::ParseMappingModel(args.model);
    if (!options.model)
      throw ConfigError("--model: unknown model '" + args.model +
                        "' (expected translation, conformal, affine, projective or auto)");
  }
  options.alpha = args.alpha;
  options.stitch.base_ids = SplitList(args.base);
  options.stitch.data_snooping = !args.no_snooping;
  options.stitch.Validate(camera);
  if (!(args.sigma_px > 0)) throw ConfigError("--sigma must be > 0 px");
  if (!(args.alpha > 0 && args.alpha < 1)) throw ConfigError("--alpha must be in (0, 1)");

  const auto rows = stitch::ReadStitchObservations(args.obs, args.sigma_px);
  const auto frames = stitch::GroupByFrame(camera, rows, args.obs);
  if (frames.empty()) throw InputError(args.obs + ": no measurements");
  Progress progress("stitch", static_cast<long>(frames.size()));
  const stitch::BatchResult result = stitch::RunStitchBatch(camera, frames, options, &progress);
  progress.Finish();
  const nlohmann::json doc = stitch::StitchResultToJson(result, options);
  WriteFileAtomically(args.out, doc.dump(2) + "\n");
  return doc.at("converged").get<bool>() ? kExitOk : kExitNotConverged;
}

CommandRun Setup(CLI::App& app) {
  auto args = std::make_shared<StitchArgs>();
  app.add_option("--camera", args->camera, "Camera file (YAML) with the sub-images")->required();
  app.add_option("--obs", args->obs, "stitch_obs.csv: one or many frames")->required();
  app.add_option("--model", args->model,
                 "translation | conformal | affine | projective | auto (F test at --alpha)")
      ->capture_default_str();
  app.add_option("--base", args->base,
                 "Comma-separated sub-images that keep the camera file's mapping (the datum)");
  app.add_option("--sigma", args->sigma_px, "A-priori sigma (px) of rows without sigma_px")
      ->capture_default_str();
  app.add_option("--alpha", args->alpha, "Level of the model-choice F test and stability flags")
      ->capture_default_str();
  app.add_flag("--no-snooping", args->no_snooping, "Do not search gross errors");
  app.add_option("--out", args->out, "Result JSON")->required();
  return [args] { return RunStitch(*args); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(stitch, "stitch",
                         "Adjust the sub-image mappings of a multi-CCD camera per frame", Setup);

}  // namespace aerocal::tools
