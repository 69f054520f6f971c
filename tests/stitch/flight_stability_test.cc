// Batch over a simulated flight of 37 frames and its stability table (flight_stability.h),
// checked against the simulation's truth.
#include "stitch/adjustment/flight_stability.h"

#include "stitch/adjustment/model_selection.h"
#include "tests/stitch/simulated_camera.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::stitch {
namespace {

using calib::MappingModel;

TEST(FlightStability, TableOfThirtySevenFramesMatchesTheTruth) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 2e-4, 31);
  auto frames = testing::SimulateFrames(camera, 37, 900, 32);
  // Frame 0020 is out of line: sub-image I moved by 1.5 px during the flight.
  {
    testing::SimulatedCamera moved = camera;
    auto& s = moved.truth.subimages[moved.truth.SubimageIndex("I")];
    s.params[2] += 1.5;  // affine a0
    auto moved_frames = testing::SimulateFrames(moved, 20, 900, 33);
    frames[19] = moved_frames[19];
  }
  BatchOptions options;
  options.stitch.base_ids = camera.base;
  const BatchResult result = RunStitchBatch(camera.nominal, frames, options, nullptr);
  ASSERT_EQ(result.frames.size(), 37u);
  ASSERT_EQ(result.stability.size(), 4u);  // every model determinable in every frame

  // Truth of the table: a model that misses part of the truth leaves, in a noise-free frame, the
  // non-centrality lambda = v^T P v; with noise E[v^T P v] = r + lambda, so the expected sigma0_px
  // is 0.1 sqrt((r + lambda) / r). Its spread over frames is about 0.1 / sqrt(2 r) (r ~ 2000); the
  // std of 37 values has a sampling error of 1 / sqrt(72) ~ 12 %.
  // lambda varies with the random tie positions of a frame: averaged over 10 noise-free frames.
  const auto clean = testing::SimulateFrames(camera, 10, 900, 34, 0.0);
  StitchOptions no_snooping = options.stitch;  // noise-free: sigma0 ~ 0, nothing to test
  no_snooping.data_snooping = false;
  std::vector<std::vector<double>> lambdas;  // per clean frame, per model
  for (const auto& frame : clean) {
    std::vector<double> l;
    for (MappingModel model : calib::kAllMappingModels)
      l.push_back(AdjustFrame(camera.nominal, frame, model, no_snooping).vtpv);
    lambdas.push_back(l);
  }
  const double noise = 0.1;
  for (size_t i = 0; i < result.stability.size(); ++i) {
    const ModelStability& s = result.stability[i];
    const double r = result.frames[0].choice->candidates[i].adjustment.redundancy;
    double expected_mean = 0, expected_mean2 = 0, lambda = 0;
    for (const auto& per_model : lambdas) {
      const double l = per_model[i];
      const double m = noise * std::sqrt((r + l) / r);
      lambda += l / lambdas.size();
      expected_mean += m / lambdas.size();
      expected_mean2 += m * m / lambdas.size();
    }
    const double lambda_spread =
        std::sqrt(std::max(0.0, expected_mean2 - expected_mean * expected_mean));
    const double expected_std = std::hypot(noise / std::sqrt(2.0 * r), lambda_spread);
    std::printf("%-11s mean sigma0_px %.4f (truth %.4f), std %.4f (truth %.4f), %zu flagged\n",
                std::string(calib::MappingModelName(s.model)).c_str(),
                s.mean_sigma0_px,
                expected_mean,
                s.std_sigma0_px,
                expected_std,
                s.flagged.size());
    EXPECT_EQ(s.n_frames, 37);
    for (const auto& f : s.flagged)
      std::printf("  %s: %s\n", f.frame.c_str(), f.reasons.front().c_str());
    // The mean: 4 standard errors, plus the moved frame's share (<= 2 % of one frame's sigma0).
    EXPECT_NEAR(s.mean_sigma0_px, expected_mean, 4 * expected_std / std::sqrt(37.0) + 0.001);
    if (lambda < r) {  // with a large lambda the spread also grows with the misfit
      EXPECT_GT(s.std_sigma0_px, 0.6 * expected_std);
      EXPECT_LT(s.std_sigma0_px, 1.6 * expected_std);
    }
  }
  // Translation cannot absorb the rotations and scales of the misplacement.
  EXPECT_GT(result.stability[0].mean_sigma0_px, 1.5 * noise);

  // Affine parameters: flight mean within 4 standard errors of the truth; spread over frames
  // agrees with the reported sigmas (pooled over the 24 parameters).
  const ModelStability& affine = result.stability[2];
  double ratio = 0;
  for (const ParameterStability& p : affine.parameters) {
    const auto& t = camera.truth.subimages[camera.truth.SubimageIndex(p.subimage)];
    int index = 0;
    const char* names[] = {"a1", "a2", "a0", "b1", "b2", "b0"};
    while (p.name != names[index]) ++index;
    if (p.subimage == "I") continue;  // I moved in one frame
    EXPECT_NEAR(p.mean, t.params[index], 4 * p.mean_sigma / std::sqrt(37.0) + 1e-12)
        << p.subimage << " " << p.name;
    ratio += p.std / p.mean_sigma / 18.0;
  }
  std::printf("affine: spread over frames / reported sigma, mean over 18 parameters: %.3f\n",
              ratio);
  EXPECT_NEAR(ratio, 1.0, 0.25);
  // The moved frame is flagged; the flags' false-alarm rate over the flight is 5 %.
  bool moved_flagged = false;
  for (const FlaggedFrame& f : affine.flagged) {
    std::printf("flagged %s: %s\n", f.frame.c_str(), f.reasons.front().c_str());
    moved_flagged = moved_flagged || f.frame == "0020";
  }
  EXPECT_TRUE(moved_flagged);
  EXPECT_LE(affine.flagged.size(), 2u);
}

}  // namespace
}  // namespace aerocal::stitch
