// Batch stitching over a flight: every frame adjusted (one model, or the model chosen by the F test
// of model_selection.h), then the flight's stability per model:
// - mean and standard deviation over frames of sigma0 and sigma0_px;
// - mean and standard deviation over frames of every mapping parameter, next to the mean of the
//   per-frame reported sigmas (agreement of the two says the reported precision is realistic);
// - frames out of line, with tests whose false-alarm rate over the whole flight is about alpha
//   (Bonferroni over frames and sub-images):
//   * sigma0: F = sigma0_f^2 / sigma0_pooled^2 ~ F(r_f, sum r) for a frame like the others;
//     flagged when F > F(1 - alpha / n_frames; r_f, sum r);
//   * mapping of a free sub-image: d^2 = dp^T (c C_f)^-1 dp ~ chi^2(n_params), with dp the frame's
//     plain parameters minus the mean of the other frames, C_f the frame's reported covariance
//     and c = 1 + 1 / n_others for the mean's own noise; flagged when d^2 exceeds
//     the chi^2 quantile at 1 - alpha / (n_frames * n_free_subimages). Frames found out of line
//     in a first pass are left out of the means of a second. The mean, not the per-parameter
//     median, keeps the centre consistent with strongly correlated parameters. The joint test uses
//     the correlations: a corner parameter (a0, b0) may have a px-size sigma while a shift of the
//     sub-image centre by a fraction of that is clearly out of line.
#pragma once

#include "stitch/adjustment/model_selection.h"

#include <optional>
#include <string>
#include <vector>

namespace aerocal {
class Progress;
}

namespace aerocal::stitch {

struct ParameterStability {
  std::string subimage, name;
  double mean = 0, std = 0;  // over frames
  double mean_sigma = 0;     // mean of the per-frame reported sigmas
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
  FrameAdjustment adjustment;         // the requested or chosen model
  std::optional<ModelChoice> choice;  // --model auto only
};

struct BatchResult {
  std::vector<FrameRun> frames;
  std::vector<ModelStability> stability;  // per model adjusted in every frame, simplest first
};

/// One frame of a batch: adjusted with the requested model, or with the model its F test chooses.
/// A unit of `aerocal batch`: frames are independent until CollectBatch.
FrameRun StitchFrame(const calib::Camera& camera,
                     const FrameMeasurements& frame,
                     const BatchOptions& options);

/// The batch of already adjusted `frames` (in flight order) with the stability of every model
/// adjusted in all of them; RunStitchBatch = StitchFrame per frame, then this.
BatchResult CollectBatch(std::vector<FrameRun> frames, const BatchOptions& options);

/// Adjusts every frame (InputError when a requested model is under-determined in a frame);
/// `progress` (may be null) advances by one per frame.
BatchResult RunStitchBatch(const calib::Camera& camera,
                           const std::vector<FrameMeasurements>& frames,
                           const BatchOptions& options,
                           Progress* progress);

/// The flight's model: the requested one, or with --model auto the one chosen in most frames
/// (the simpler on a tie). `result` must hold at least one frame.
calib::MappingModel FlightModel(const BatchResult& result, const BatchOptions& options);

/// `camera` with every free sub-image mapped by the flight mean of its `model` parameters (the
/// stability of `model`); base sub-images keep the camera's mapping. nullopt when `model` was not
/// adjusted in every frame.
std::optional<calib::Camera> FlightMeanCamera(const calib::Camera& camera,
                                              const BatchResult& result,
                                              calib::MappingModel model);

}  // namespace aerocal::stitch
