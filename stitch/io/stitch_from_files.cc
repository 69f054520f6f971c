#include "stitch/io/stitch_from_files.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "stitch/simulation/stitch_simulator.h"

namespace aerocal::stitch {

BatchOptions BatchOptionsFromText(const calib::Camera& camera,
                                  const std::string& model,
                                  const std::string& base,
                                  double alpha,
                                  bool data_snooping,
                                  const char* model_option,
                                  const char* alpha_option) {
  BatchOptions options;
  if (model != "auto") {
    options.model = calib::ParseMappingModel(model);
    if (!options.model)
      throw ConfigError(std::string(model_option) + ": unknown model '" + model +
                        "' (expected translation, conformal, affine, projective or auto)");
  }
  if (!(alpha > 0 && alpha < 1))
    throw ConfigError(std::string(alpha_option) + " must be in (0, 1)");
  options.alpha = alpha;
  options.stitch.base_ids = SplitCommaList(base);
  options.stitch.data_snooping = data_snooping;
  options.stitch.Validate(camera);
  return options;
}

std::vector<FrameMeasurements> ReadStitchFrames(const calib::Camera& camera,
                                                const std::string& camera_path,
                                                const std::string& observations,
                                                double sigma_px) {
  if (camera.subimages.empty())
    throw InputError(camera_path + ": the camera has no sub-images to stitch");
  const auto rows = ReadStitchObservations(observations, sigma_px);
  auto frames = GroupByFrame(camera, rows, observations);
  if (frames.empty()) throw InputError(observations + ": no measurements");
  return frames;
}

}  // namespace aerocal::stitch
