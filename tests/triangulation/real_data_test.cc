// Real data sets from ../shared/data (skipped when absent), imported once with the project's
// importers and adjusted; published answers from each folder's PROVENANCE.md.
#include "tests/support/odm_uav_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/import/dbat_import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

TEST(RealData, DbatOlympusCalibrationMatchesThePublishedResult) {
  const std::string dir = testing::SharedDataDir("dbat_camcal_olympus_c4040z");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/dbat_camcal_olympus_c4040z is absent";
  DbatImportOptions in;
  in.camera_xml = dir + "/c4040z.xml";
  in.marks = dir + "/measurements/markpts.txt";
  in.images = dir + "/images/images.txt";
  // The published run holds the four control points fixed (camcal-fixed.txt): 1 um here.
  in.control = dir + "/reference/camcal-fixed.txt";
  in.control_sigma_m = 1e-6;
  in.photomodeler_export = dir + "/photomodeler/camcal-pmexport.txt";
  const Project project = ImportDbat(in);
  ASSERT_EQ(project.exposures.size(), 21u);
  ASSERT_EQ(project.observations.size(), 2074u);
  AdjustOptions options;
  // DBAT's model: c, principal point, K1..K3, P1, P2 and an aspect term (B1 here); no skew.
  options.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2,K3,P1,P2,B1");
  options.data_snooping = false;  // as DBAT: no observation removed
  const AdjustmentResult r = Adjust(project, options);
  std::printf("%s", FormatSummary(r).c_str());
  ASSERT_TRUE(r.converged()) << r.solve.message;
  ASSERT_TRUE(r.determinability.covariance_ok);
  const auto& c = r.cameras[0];
  // Published (DBAT 0.9.2.0): c 7.45700 (0.00105) mm, K1 4.58861e-3, K2 -4.51351e-5,
  // K3 -2.05253e-6, P1 -6.12803e-5, P2 -4.41171e-5, sigma0 0.16148 px.
  struct Published {
    int index;
    double value, sigma;
  };
  for (const Published& p : {Published{Model::kC, 7.45700, 0.00105},
                             {Model::kK1, 4.58861e-3, 2.21e-5},
                             {Model::kK2, -4.51351e-5, 2.65e-6},
                             {Model::kK3, -2.05253e-6, 1.01e-7},
                             {Model::kP1, -6.12803e-5, 3.52e-6},
                             {Model::kP2, -4.41171e-5, 3.94e-6}}) {
    SCOPED_TRACE(std::string(Model::kParams[p.index].name));
    EXPECT_LE(std::abs(c.estimated[p.index] - p.value), 3.0 * c.sigma[p.index])
        << "estimate " << c.estimated[p.index] << " sigma " << c.sigma[p.index];
  }
  EXPECT_NEAR(r.sigma0_px / 0.16148, 1.0, 0.10);
}

TEST(RealData, OdmUavTargetsBlundersFoundAndCheckPointsCompared) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_br_uav_gcp_block is absent";
  // The author's control subset; the other targets are check points. Starting values from every
  // surveyed target (a similarity per near-nadir image).
  const Project project = testing::ImportOdmUavBlock(dir);
  ASSERT_EQ(project.observations.size(), 82u);
  ASSERT_EQ(project.points.size(), 19u);
  ASSERT_EQ(project.exposures.size(), 10u);
  AdjustOptions options;
  options.robust_start = true;  // gross errors of hundreds of pixels and rough starting values
  const AdjustmentResult r = Adjust(project, options);
  std::printf("%s", FormatSummary(r).c_str());
  ASSERT_TRUE(r.converged()) << r.solve.message;
  // PROVENANCE.md documents three bad observations. Two are gross errors of hundreds of pixels
  // and are rejected: IMG_5352/HV11 at (2801.6, 2108.7) and IMG_5358/HV14.
  auto find = [&](const std::string& image, const std::string& point, double col, double row) {
    for (const auto& o : r.rejected)
      if (o.image == image && o.point == point && std::abs(o.measured_px.x() - col) < 0.05 &&
          std::abs(o.measured_px.y() - row) < 0.05)
        return &o;
    return static_cast<const RejectedObservation*>(nullptr);
  };
  const auto* a = find("IMG_5352", "HV11", 2801.6, 2108.7);
  const auto* b = find("IMG_5358", "HV14", 3632.5, 2380.6);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_GT(a->residual_px.norm(), 100.0);
  EXPECT_GT(b->residual_px.norm(), 100.0);
  // The third, IMG_5358/HV11 at (2801.6, 2108.7), fits the adjusted block to a few pixels with
  // eight other targets in that image: the duplicate entry of IMG_5352 is the copy, this one is
  // the measurement. The adjustment keeps it and shows its residual.
  EXPECT_EQ(find("IMG_5358", "HV11", 2801.6, 2108.7), nullptr);
  for (const auto& v : r.residuals)
    if (v.image == "IMG_5358" && v.point == "HV11") {
      EXPECT_TRUE(v.used);
      EXPECT_LT(v.residual_px.norm(), 3.0 * r.sigma0_px);
    }
  // Every other rejection is a moderate outlier (a target mis-pointed by several pixels).
  for (const auto& o : r.rejected) {
    if (&o == a || &o == b) continue;
    EXPECT_LT(o.residual_px.norm(), 20.0) << o.image << " " << o.point;
  }
  // Control / check split: check errors of a few GSD (2.4 cm) per axis (measured X 0.061, Y 0.087,
  // Z 0.110 m over 12 points; a camera of 4.5 mm with no distortion model and targets pointed to
  // ~1 px: 6 GSD is the bound of a working adjustment).
  EXPECT_GE(r.check.n, 10);
  for (int k = 0; k < 3; ++k) EXPECT_LT(r.check.rmse_m(k), 0.15) << "axis " << k;
  std::printf("check RMSE X %.3f Y %.3f Z %.3f m over %d points\n",
              r.check.rmse_m.x(),
              r.check.rmse_m.y(),
              r.check.rmse_m.z(),
              r.check.n);
}

}  // namespace
}  // namespace aerocal::triangulation

namespace aerocal::triangulation {
namespace {

TEST(RealData, DbatRomaFreeNetworkSelfCalibrationMatchesThePublishedResult) {
  const std::string dir = testing::SharedDataDir("dbat_roma_canon_eos5d");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/dbat_roma_canon_eos5d is absent";
  DbatImportOptions in;
  in.camera_xml = dir + "/cameras/EOS5DMarkII.xml";
  in.marks = dir + "/measurements/markpts.txt";
  in.images = dir + "/images/images.txt";
  in.initial_eo = dir + "/prior/initial_eo.txt";
  in.default_sigma_px = 1.0;  // DBAT used sxy = 1 px
  const Project project = ImportDbat(in);
  ASSERT_EQ(project.observations.size(), 90561u);
  AdjustOptions options;
  options.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2");  // DBAT's 5 IO parameters
  options.data_snooping = false;                                  // as DBAT
  const AdjustmentResult r = Adjust(project, options);
  std::printf("%s", FormatSummary(r).c_str());
  ASSERT_TRUE(r.converged()) << r.solve.message;
  EXPECT_EQ(r.solve.redundancy, 101801);  // DBAT: 181,122 observations, 79,321 parameters
  EXPECT_NE(r.datum.find("free network"), std::string::npos);
  ASSERT_TRUE(r.determinability.covariance_ok) << r.determinability.message;
  const auto& c = r.cameras[0];
  // Published: c = 24.5425 mm (sigma 0.00254), sigma0 = 0.582769 px.
  EXPECT_LE(std::abs(c.estimated[Model::kC] - 24.5425), 3.0 * c.sigma[Model::kC]);
  EXPECT_NEAR(r.sigma0_px / 0.582769, 1.0, 0.05);
}

}  // namespace
}  // namespace aerocal::triangulation
