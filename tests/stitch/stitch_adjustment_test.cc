// Synthetic truth recovery of the per-frame sub-image adjustment (stitch_adjustment.h):
// simulated frames with 0.1 px matching noise on a 2x3 camera (base CCDs II and V) whose other
// CCDs are misplaced by shifts, rotations, scales and an affine part (shear 2e-4).
#include "stitch/adjustment/stitch_adjustment.h"

#include "calib/core/error.h"
#include "tests/stitch/simulated_camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {
namespace {

using calib::MappingModel;

constexpr double kNoisePx = 0.1;  // FrameSimulationOptions default

// Normalized errors (estimate - truth) / sigma of every free plain parameter.
std::vector<double> NormalizedErrors(const calib::Camera& truth, const FrameAdjustment& a) {
  std::vector<double> z;
  for (const SubimageEstimate& e : a.subimages) {
    if (e.base) continue;
    const auto& t = truth.subimages[truth.SubimageIndex(e.id)];
    const std::vector<double> true_params =
        calib::ParamsFromHomography(e.model, calib::HomographyFromParams(t.model, t.params.data()));
    for (size_t i = 0; i < e.params.size(); ++i)
      z.push_back((e.params[i] - true_params[i]) / e.sigma[i]);
  }
  return z;
}

TEST(AdjustFrame, RecoversTruthOverTwentyFramesWithRealisticSigmas) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 2e-4, 7);
  const auto frames = testing::SimulateFrames(camera, 20, 900, 11);
  StitchOptions options;
  options.base_ids = camera.base;
  double sum_z2 = 0;
  int n_z = 0, beyond3 = 0;
  for (const auto& frame : frames) {
    const FrameAdjustment a = AdjustFrame(camera.nominal, frame, MappingModel::kAffine, options);
    ASSERT_TRUE(a.converged) << frame.frame;
    ASSERT_TRUE(a.covariance_ok) << frame.frame;
    // Acceptance: sigma0 within 10 % of the injected 0.1 px (its own spread is 1/sqrt(2r) ~ 1.6 %).
    EXPECT_NEAR(a.sigma0_px, kNoisePx, 0.1 * kNoisePx) << frame.frame;
    EXPECT_GT(a.redundancy, 1500);
    for (double z : NormalizedErrors(camera.truth, a)) {
      sum_z2 += z * z;
      ++n_z;
      beyond3 += std::abs(z) > 3.0;
      EXPECT_LT(std::abs(z), 4.5) << frame.frame;  // 480 values: |z| > 4.5 has p ~ 0.3 %
    }
  }
  const double rms_z = std::sqrt(sum_z2 / n_z);
  std::printf("RMS of (estimate - truth) / sigma over %d parameters: %.3f, beyond 3 sigma: %d\n",
              n_z,
              rms_z,
              beyond3);
  // Acceptance: the reported sigmas agree with the actual spread within 25 % (pooled: its own
  // sampling error is 1/sqrt(2 n) ~ 3 %); at most 1 % beyond 3 sigma (expected 0.27 %).
  EXPECT_NEAR(rms_z, 1.0, 0.25);
  EXPECT_LE(beyond3, n_z / 100);
}

TEST(AdjustFrame, ReportedSigmasMatchSpreadPerParameter) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 2e-4, 8);
  const auto frames = testing::SimulateFrames(camera, 20, 900, 12);
  StitchOptions options;
  options.base_ids = camera.base;
  std::vector<std::vector<double>> values;
  std::vector<double> mean_sigma;
  for (const auto& frame : frames) {
    const FrameAdjustment a = AdjustFrame(camera.nominal, frame, MappingModel::kAffine, options);
    std::vector<double> v;
    size_t j = 0;
    for (const auto& e : a.subimages) {
      if (e.base) continue;
      for (size_t i = 0; i < e.params.size(); ++i, ++j) {
        v.push_back(e.params[i]);
        if (mean_sigma.size() <= j) mean_sigma.push_back(0);
        mean_sigma[j] += e.sigma[i] / frames.size();
      }
    }
    values.push_back(v);
  }
  // Per parameter, the standard deviation over 20 frames has a sampling error of 1/sqrt(38) ~ 16 %;
  // the mean ratio over the 24 parameters is checked against the 25 % of the acceptance.
  double mean_ratio = 0;
  for (size_t j = 0; j < mean_sigma.size(); ++j) {
    double m = 0, s = 0;
    for (const auto& v : values) m += v[j] / values.size();
    for (const auto& v : values) s += (v[j] - m) * (v[j] - m);
    s = std::sqrt(s / (values.size() - 1));
    const double ratio = s / mean_sigma[j];
    EXPECT_GT(ratio, 0.5) << "parameter " << j;  // 3 sampling sigmas
    EXPECT_LT(ratio, 1.5) << "parameter " << j;
    mean_ratio += ratio / mean_sigma.size();
  }
  std::printf("spread over 20 frames / reported sigma, mean over parameters: %.3f\n", mean_ratio);
  EXPECT_NEAR(mean_ratio, 1.0, 0.25);
}

TEST(AdjustFrame, FindsAndListsAPlantedGrossError) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 2e-4, 9);
  auto frames = testing::SimulateFrames(camera, 1, 900, 13);
  TieMeasurement& tie = frames[0].ties[100];
  tie.rays[0].uv += Eigen::Vector2d(2.0, 0.0);  // planted 2 px gross error
  const std::string bad_subimage = camera.nominal.subimages[tie.rays[0].subimage].id;
  StitchOptions options;
  options.base_ids = camera.base;
  const FrameAdjustment a = AdjustFrame(camera.nominal, frames[0], MappingModel::kAffine, options);
  bool found = false;
  for (const auto& r : a.rejected) {
    std::printf("rejected %s in %s: w = %.1f, v = (%.2f, %.2f) px\n",
                r.point.c_str(),
                r.subimage.c_str(),
                r.w,
                r.v_px.x(),
                r.v_px.y());
    found = found || r.point == tie.point;
  }
  EXPECT_TRUE(found) << "the 2 px error on " << tie.point << " (" << bad_subimage
                     << ") was not listed";
  EXPECT_LE(a.rejected.size(), 3u);  // the family-wise false-alarm rate is 5 %
  EXPECT_NEAR(a.sigma0_px, kNoisePx, 0.1 * kNoisePx);
  // Rejected observations never appear among the residuals of the clean adjustment.
  ASSERT_FALSE(a.rejected.empty());
  for (const auto& r : a.residuals)
    EXPECT_FALSE(r.point == tie.point && r.subimage == a.rejected[0].subimage);
}

TEST(AdjustFrame, RefusesAnUnderdeterminedModelNamingTheSubimage) {
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 0.0, 10);
  auto frames = testing::SimulateFrames(camera, 1, 300, 14);
  // Three points on sub-image I: 6 equations, enough for affine (6), not projective (8).
  testing::KeepTiesTouching(camera.nominal, "I", 3, &frames[0]);
  StitchOptions options;
  options.base_ids = camera.base;
  EXPECT_EQ(FindUnderdetermined(camera.nominal, frames[0], MappingModel::kAffine, options), "");
  try {
    AdjustFrame(camera.nominal, frames[0], MappingModel::kProjective, options);
    FAIL() << "an under-determined projective model was adjusted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sub-image I:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("3 points give 6 equations for the 8 projective"),
              std::string::npos)
        << e.what();
  }
}

TEST(AdjustFrame, RefusesSubimagesThatNoTieChainConnectsToTheDatum) {
  // 2x3 CCDs, base II and V (centre column): keep the ties between I and IV (the left column),
  // drop every tie linking them to the rest. I and IV have equations enough but no datum.
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 0.0, 17);
  auto frames = testing::SimulateFrames(camera, 1, 600, 18);
  const int i = camera.nominal.SubimageIndex("I"), iv = camera.nominal.SubimageIndex("IV");
  auto& ties = frames[0].ties;
  ties.erase(std::remove_if(ties.begin(),
                            ties.end(),
                            [&](const TieMeasurement& t) {
                              bool left = false, other = false;
                              for (const auto& r : t.rays)
                                (r.subimage == i || r.subimage == iv ? left : other) = true;
                              return left && other;
                            }),
             ties.end());
  StitchOptions options;
  options.base_ids = camera.base;
  const std::string refusal =
      FindUnderdetermined(camera.nominal, frames[0], MappingModel::kConformal, options);
  EXPECT_NE(refusal.find("sub-image I"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("no chain of tie points"), std::string::npos) << refusal;
  EXPECT_THROW(AdjustFrame(camera.nominal, frames[0], MappingModel::kAffine, options), InputError);
  // With a reference point on I the island has its datum again.
  frames[0].references.push_back({"R1",
                                  i,
                                  Eigen::Vector2d(10, 10),
                                  camera.truth.subimages[i].VirtualFromSub(Eigen::Vector2d(10, 10)),
                                  0.05});
  frames[0].references.push_back(
      {"R2",
       iv,
       Eigen::Vector2d(10, 3000),
       camera.truth.subimages[iv].VirtualFromSub(Eigen::Vector2d(10, 3000)),
       0.05});
  EXPECT_EQ(FindUnderdetermined(camera.nominal, frames[0], MappingModel::kConformal, options), "");
}

TEST(AdjustFrame, PredictsCornerPrecisionOfATwelveCcdLayout) {
  // 3x4 CCDs, 200 px overlaps, reference points on the two base CCDs only (VI, VII): the outer
  // CCDs hang on chains of 200 px strips, their scale is weakly determined.
  const auto camera = testing::MakeSimulatedCamera(3, 4, {"VI", "VII"}, 2e-4, 15);
  const auto frames = testing::SimulateFrames(camera, 20, 900, 16);
  StitchOptions options;
  options.base_ids = camera.base;
  // Predicted corner sigma against the actual corner errors over 20 frames.
  double predicted2 = 0, actual2 = 0;
  int n = 0;
  double max_predicted = 0, sigma0_px = 0;
  for (const auto& frame : frames) {
    const FrameAdjustment a = AdjustFrame(camera.nominal, frame, MappingModel::kAffine, options);
    ASSERT_TRUE(a.covariance_ok);
    sigma0_px += a.sigma0_px / frames.size();
    max_predicted = std::max(max_predicted, a.max_corner_sigma_px);
    for (const auto& e : a.subimages) {
      if (e.base) continue;
      const auto& t = camera.truth.subimages[camera.truth.SubimageIndex(e.id)];
      for (const auto& c : e.corners) {
        const Eigen::Vector2d error = c.virtual_px - t.VirtualFromSub(c.uv);
        actual2 += error.squaredNorm();
        predicted2 += c.sigma_px() * c.sigma_px();
        ++n;
      }
    }
  }
  std::printf(
      "12 CCDs: sigma0_px %.4f, largest predicted corner sigma %.2f px, RMS predicted %.2f px, "
      "RMS actual corner error %.2f px\n",
      sigma0_px,
      max_predicted,
      std::sqrt(predicted2 / n),
      std::sqrt(actual2 / n));
  // The small sigma0 hides corner uncertainties of px size; the prediction says so.
  EXPECT_NEAR(sigma0_px, kNoisePx, 0.1 * kNoisePx);
  EXPECT_GT(max_predicted, 1.0);
  EXPECT_LT(max_predicted, 3.0);
  // The prediction is realistic: RMS actual / RMS predicted near 1 (800 corners, correlated).
  EXPECT_NEAR(std::sqrt(actual2 / predicted2), 1.0, 0.3);
}

}  // namespace
}  // namespace aerocal::stitch
