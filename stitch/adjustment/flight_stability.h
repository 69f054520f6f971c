// Batch stitching over a flight: every frame adjusted (one model, or the model chosen by the F test
// of model_selection.h), then the flight's stability per model:
// - mean and standard deviation over frames of sigma0 and sigma0_px;
// - mean and standard deviation over frames of every mapping parameter, next to the mean of the
//   per-frame reported sigmas (agreement of the two says the reported precision is realistic);
// - frames out of line: a frame is flagged when its sigma0_px, or any of its mapping parameters,
//   lies further than k robust standard deviations (1.4826 * MAD over frames) from the flight's
//   median, with k = max(3, z(alpha / n_tests)) (Bonferroni over the n_tests values of the
//   model, so that a stable flight flags a frame with probability about alpha).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "stitch/adjustment/model_selection.h"

namespace aerocal {
class Progress;
}

namespace aerocal::stitch {

struct ParameterStability {
  std::string subimage, name;
  double mean = 0, std = 0;     // over frames
  double mean_sigma = 0;        // mean of the per-frame reported sigmas
};

struct FlaggedFrame {
  std::string frame;
  std::vector<std::string> reasons;
};

struct ModelStability {
  calib::MappingModel model = calib::MappingModel::kAffine;
  int n_frames = 0;
  double mean_sigma0 = 0, std_sigma0 = 0;
  double mean_sigma0_px = 0, std_sigma0_px = 0;
  std::vector<ParameterStability> parameters;  // free sub-images only
  std::vector<FlaggedFrame> flagged;
};

/// Stability of one model over `frames` (all adjusted with that model); alpha as above.
ModelStability ComputeStability(calib::MappingModel model,
                                const std::vector<const FrameAdjustment*>& frames,
                                double alpha = 0.05);

struct BatchOptions {
  std::optional<calib::MappingModel> model;  // nullopt: choose per frame (--model auto)
  StitchOptions stitch;
  double alpha = 0.05;  // level of the model-choice F test and of the out-of-line flags
};

struct FrameRun {
  FrameAdjustment adjustment;          // the requested or chosen model
  std::optional<ModelChoice> choice;   // --model auto only
};

struct BatchResult {
  std::vector<FrameRun> frames;
  std::vector<ModelStability> stability;  // per model adjusted in every frame, simplest first
};

/// Adjusts every frame (InputError when a requested model is under-determined in a frame);
/// `progress` (may be null) advances by one per frame.
BatchResult RunStitchBatch(const calib::Camera& camera, const std::vector<FrameMeasurements>& frames,
                           const BatchOptions& options, Progress* progress);

}  // namespace aerocal::stitch
