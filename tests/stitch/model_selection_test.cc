// Model choice by the F test (model_selection.h, f_distribution.h).
#include "stitch/adjustment/model_selection.h"

#include "stitch/adjustment/f_distribution.h"
#include "tests/stitch/simulated_camera.h"

#include <gtest/gtest.h>

namespace aerocal::stitch {
namespace {

using calib::MappingModel;

TEST(FDistribution, MatchesTabulatedQuantiles) {
  // Tables (e.g. NIST/SEMATECH e-Handbook 1.3.6.7.3): upper 5 % points.
  EXPECT_NEAR(FDistributionQuantile(0.95, 1, 10), 4.965, 1e-3);
  EXPECT_NEAR(FDistributionQuantile(0.95, 5, 5), 5.050, 1e-3);
  EXPECT_NEAR(FDistributionQuantile(0.95, 8, 100), 2.032, 1e-3);
  EXPECT_NEAR(FDistributionQuantile(0.99, 2, 20), 5.849, 1e-3);
  // F(1, d2) is t(d2)^2: P(t_10 <= 2.228) = 0.975 -> P(F(1,10) <= 2.228^2) = 0.95.
  EXPECT_NEAR(FDistributionCdf(2.228 * 2.228, 1, 10), 0.95, 1e-4);
  EXPECT_DOUBLE_EQ(FDistributionCdf(0.0, 3, 7), 0.0);
}

// Chooses the model in 20 simulated frames and counts the choices.
std::map<MappingModel, int> CountChoices(double shear, std::uint64_t seed) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, shear, seed);
  const auto frames = testing::SimulateFrames(camera, 20, 900, seed + 100);
  StitchOptions options;
  options.base_ids = camera.base;
  std::map<MappingModel, int> counts;
  for (const auto& frame : frames) {
    const ModelChoice choice = ChooseModel(camera.nominal, frame, options);
    ++counts[choice.chosen];
    EXPECT_EQ(choice.candidates.size(), 4u);
    EXPECT_FALSE(choice.reason.empty());
    // Never the lowest sigma0 alone: the richest model always has the smallest v^T P v.
    EXPECT_LE(choice.candidates[3].adjustment.vtpv, choice.candidates[2].adjustment.vtpv);
  }
  for (const auto& [model, n] : counts)
    std::printf("shear %.0e: %s chosen in %d of 20 frames\n",
                shear,
                std::string(calib::MappingModelName(model)).c_str(),
                n);
  return counts;
}

// Non-centrality of the conformal model: v^T P v of a noise-free frame (the misfit of the
// affine part in units of the noise). The affine part is "well above the noise" when it is large
// against the 8 extra parameters of the test; in the 2x3 layout the outer columns hang on 200 px
// strips, so how much of a shear of 2e-4 shows depends on its direction in each sub-image.
double ConformalNonCentrality(double shear, std::uint64_t seed) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, shear, seed);
  const auto frames = testing::SimulateFrames(camera, 1, 900, seed + 100, 0.0);
  StitchOptions options;
  options.base_ids = camera.base;
  options.data_snooping = false;
  return AdjustFrame(camera.nominal, frames[0], MappingModel::kConformal, options).vtpv;
}

TEST(ChooseModel, PicksAffineWhenTheAffinePartIsWellAboveTheNoise) {
  const double lambda = ConformalNonCentrality(2e-4, 21);
  std::printf("non-centrality of the conformal model: %.1f\n", lambda);
  // Power of the F test at 5 % with lambda >= 80 and 8 extra parameters: > 99.9 %.
  ASSERT_GT(lambda, 80.0) << "the simulated affine part is not well above the noise";
  EXPECT_GE(CountChoices(2e-4, 21)[MappingModel::kAffine], 19);
}

TEST(ChooseModel, PicksConformalWhenTheTruthIsConformal) {
  EXPECT_GE(CountChoices(0.0, 22)[MappingModel::kConformal], 19);
}

TEST(ChooseModel, TableListsRefusedModelsWithTheReason) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 0.0, 23);
  auto frames = testing::SimulateFrames(camera, 1, 300, 24);
  // Three points on sub-image I: 6 equations, enough for affine (6), not projective (8).
  testing::KeepTiesTouching(camera.nominal, "I", 3, &frames[0]);
  StitchOptions options;
  options.base_ids = camera.base;
  const ModelChoice choice = ChooseModel(camera.nominal, frames[0], options);
  EXPECT_FALSE(choice.candidates[3].determinable);
  EXPECT_NE(choice.candidates[3].refusal.find("sub-image I"), std::string::npos);
  EXPECT_TRUE(choice.candidates[2].determinable);
  EXPECT_NE(choice.chosen, MappingModel::kProjective);
}

}  // namespace
}  // namespace aerocal::stitch
