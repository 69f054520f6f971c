// Matching on real pixels: the Boruszyn scene (match_test_scene.h) matched with both detectors of
// the descriptor search and with the predicted search, LSM on and off; every tie's two rays mapped
// through the TRUE mappings must meet.
#include "stitch/matching/overlap_matcher.h"
#include "tests/stitch/match_test_scene.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace aerocal::stitch {
namespace {

using testing::AgreementThroughTruth;
using testing::BoruszynScene;

void PrintStrips(const FrameMatches& m) {
  for (const StripReport& s : m.strips)
    std::printf(
        "  %-8s kp %5d/%5d ratio %4d ransac %4d lsm %3d (nc %d, poor %d) points %3d coverage "
        "%.2f\n",
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
}

struct MatchRun {
  FrameMatches matches;
  testing::TieAgreement agreement;
};

struct Method {
  Search search;
  Detector detector;
  const char* name;
};

MatchRun MatchScene(const Method& method, bool lsm) {
  const auto& scene = *BoruszynScene();
  MatchOptions options;
  options.search = method.search;
  options.detector = method.detector;
  options.use_lsm = lsm;
  MatchRun run;
  run.matches = MatchFrame(scene.nominal, scene.images, "4880", options);
  run.agreement = AgreementThroughTruth(scene.truth, run.matches.observations);
  std::printf("%s, LSM %s: %d ties, RMS %.3f px per coordinate, max %.3f px\n",
              method.name,
              lsm ? "on" : "off",
              run.agreement.ties,
              run.agreement.rms_px,
              run.agreement.max_px);
  PrintStrips(run.matches);
  return run;
}

class MatchReal : public ::testing::TestWithParam<Method> {
 protected:
  void SetUp() override {
    if (!BoruszynScene()) GTEST_SKIP() << "shared data odm_boruszyn_kap_frames absent";
  }
};

TEST_P(MatchReal, LsmTiePointsMeetThroughTrueMappingsToATenthOfAPixel) {
  const MatchRun off = MatchScene(GetParam(), false);
  const MatchRun on = MatchScene(GetParam(), true);
  // The target: 0.1 px. Keypoint positions alone are not that good.
  EXPECT_LT(on.agreement.rms_px, 0.1);
  EXPECT_LT(on.agreement.max_px, 0.5);
  EXPECT_LT(on.agreement.rms_px, off.agreement.rms_px);
  for (const StripReport& s : on.matches.strips) {
    SCOPED_TRACE(s.name);
    EXPECT_GT(s.points, 0);
    // Long strips (not the small corner overlaps) are covered nearly everywhere.
    if (s.cells >= 10) {
      EXPECT_GE(s.Coverage(), 0.8);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Methods,
    MatchReal,
    ::testing::Values(Method{Search::kDescriptors, Detector::kSift, "SIFT"},
                      Method{Search::kDescriptors, Detector::kFoerstner, "Foerstner"},
                      Method{Search::kPredicted, Detector::kSift, "predicted (Foerstner + NCC)"}),
    [](const ::testing::TestParamInfo<Method>& info) {
      return std::string(info.param.search == Search::kPredicted  ? "Predicted"
                         : info.param.detector == Detector::kSift ? "Sift"
                                                                  : "Foerstner");
    });

}  // namespace
}  // namespace aerocal::stitch
