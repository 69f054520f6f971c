// `simulate --test-field` (triangulation/simulation/test_field_simulator.h): the simulated test
// field calibrates to its truth through `Calibrate` (aerocal's own resections, no approximate
// exterior orientation), its three groups agree and are flagged when one group's camera changes;
// the planar variant starts from Zhang's closed form. The Monte-Carlo coverage study of the budget
// is tests/triangulation/test_field_study_test.cc (label `long`).
#include "tests/support/interior_checks.h"
#include "triangulation/calibration/calibration.h"
#include "triangulation/simulation/test_field_simulator.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

CalibrationRun CalibrateField(const SimulatedTestField& f, bool groups = true) {
  CalibrateOptions o;  // the distortion terms the truth has (K3, B1, B2 are 0 there)
  o.adjust.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2,P1,P2");
  o.adjust.data_snooping = false;
  return Calibrate(
      TestFieldProject(f), o, groups ? f.group_of_image : std::map<std::string, std::string>{});
}

TEST(TestFieldSimulator, ThreeGroupsOf24CalibrateToTheTruthAndAgree) {
  TestFieldOptions o;
  o.seed = 11;
  const SimulatedTestField f = SimulateTestField(o);
  EXPECT_EQ(f.exposures_truth.size(), 72u);
  EXPECT_EQ(f.group_of_image.size(), 72u);
  const CalibrationRun run = CalibrateField(f);
  const AdjustmentResult& r = run.all.result;
  ASSERT_TRUE(r.valid) << (r.invalid_reasons.empty() ? "" : r.invalid_reasons[0]);
  EXPECT_EQ(run.starts.size(), 72u);  // every image started by resection
  const CameraEstimate& c = r.cameras[0];
  testing::ExpectInteriorWithinThreeSigma(c, f.truth.interior);
  // Injected 0.1 px with sigma 0.1 px: sigma0 within 1 +- 3 / sqrt(2 r).
  EXPECT_NEAR(r.sigma0, 1.0, 3.0 / std::sqrt(2.0 * r.solve.redundancy));
  ASSERT_EQ(run.groups.size(), 3u);
  EXPECT_TRUE(run.stability.agree)
      << (run.stability.flagged.empty() ? "" : run.stability.flagged[0]);
  std::printf("test field: c %.5f +- %.5f mm (truth %.5f), sigma0 %.3f, redundancy %d\n",
              c.estimated[Model::kC],
              c.sigma[Model::kC],
              f.truth.interior[Model::kC],
              r.sigma0,
              static_cast<int>(r.solve.redundancy));
}

TEST(TestFieldSimulator, OneGroupsCameraChangedByTenSigmaIsFlagged) {
  TestFieldOptions o;
  o.seed = 11;
  o.images_per_group = 12;
  // c of group B 20 um longer: about ten of a group's sigmas of c (2 um at 12 images).
  o.changed_group = 1;
  o.group_camera_change[Model::kC] = 0.02;
  const SimulatedTestField f = SimulateTestField(o);
  const CalibrationRun run = CalibrateField(f);
  EXPECT_FALSE(run.stability.agree);
  ASSERT_FALSE(run.stability.flagged.empty());
  EXPECT_NE(run.stability.flagged[0].find("c:"), std::string::npos) << run.stability.flagged[0];
}

TEST(TestFieldSimulator, PlanarFieldStartsFromZhangsClosedForm) {
  TestFieldOptions o;
  o.seed = 5;
  o.planar = true;
  o.groups = 1;
  o.images_per_group = 16;
  const SimulatedTestField f = SimulateTestField(o);
  for (const auto& p : f.points_truth) ASSERT_EQ(p.xyz_m->y(), 0.0);
  const CalibrationRun run = CalibrateField(f, false);
  ASSERT_TRUE(run.closed_form_c_mm);
  // Zhang's c from the homographies (distortion of up to 12 px left in): within 1 % of the truth.
  EXPECT_NEAR(*run.closed_form_c_mm / f.truth.interior[Model::kC], 1.0, 0.01);
  const CameraEstimate& c = run.all.result.cameras[0];
  ASSERT_TRUE(run.all.result.valid);
  EXPECT_LE(std::abs(c.estimated[Model::kC] - f.truth.interior[Model::kC]),
            3.0 * c.sigma[Model::kC]);
}

}  // namespace
}  // namespace aerocal::triangulation
