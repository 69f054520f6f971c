// The slanted-edge MTF on images we did not make: a synthetic
// edge rendered by another project's generator (point-sampled, Gaussian blur along the rows)
// against its analytic MTF50, and a real satellite image of the Baotou edge target against the
// MTF50 that project published for it.
#include "stitch/image_io/image_io.h"
#include "stitch/quality/slanted_edge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

namespace aerocal::stitch {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
// The two images of JorgeGIlG/MTF_Estimator (GPL-3.0; its data/ folder: the Baotou CAL/VAL edge,
// byte-identical, and the synthetic edge myedge_angle_16.776550_fwhm_2.101313.tif cropped to
// columns 150..349) are third-party files: they are not kept in this repository but expected as
// the shared data set ../shared/data/mtf_estimator_edges (with its PROVENANCE.md); the tests skip
// with this message when it is absent.
const std::string kData = std::string(AEROCAL_SHARED_DATA_DIR) + "/mtf_estimator_edges/";

bool Absent(const std::string& file) { return !std::ifstream(kData + file).good(); }

TEST(SlantedEdgeReal, ThirdPartySyntheticEdgeGivesItsAnalyticMtf50) {
  if (Absent("mtf_estimator_synthetic_edge_crop.tif"))
    GTEST_SKIP() << "../shared/data/mtf_estimator_edges is absent (third-party images, GPL-3.0)";
  const GrayImage image = ReadGrayImage(kData + "mtf_estimator_synthetic_edge_crop.tif");
  const SlantedEdgeResult r = MeasureSlantedEdge(image, {0, 0, 200, 100});
  // A Gaussian of FWHM 2.101313 px along the rows is one of sigma_h cos(t) along the normal.
  const double slant = 16.77655;
  const double sigma = 2.101313 / (2.0 * std::sqrt(2.0 * std::log(2.0))) * std::cos(slant * kDeg);
  const double truth = std::sqrt(std::log(2.0) / 2.0) / (3.14159265358979323846 * sigma);
  std::printf(
      "third-party edge: slant %.4f deg, MTF50 %.5f +- %.5f (k = 2), analytic %.5f (%+.2f %%)\n",
      std::abs(r.angle_deg),
      r.mtf50_cy_px,
      r.mtf50_expanded_cy_px,
      truth,
      100.0 * (r.mtf50_cy_px / truth - 1.0));
  EXPECT_NEAR(std::abs(r.angle_deg), slant, 0.02);
  EXPECT_LT(std::abs(r.mtf50_cy_px / truth - 1.0), 0.02);  // the acceptance bound of issue 36
  EXPECT_LE(std::abs(r.mtf50_cy_px - truth), r.mtf50_expanded_cy_px);
}

// The real image: the two halves of the target's near-vertical edge (dark | bright above the
// centre, bright | grey below), each a region free of the other edges and of the zeroed outside.
// The published MTF50 (0.171712, MTF_Estimator, frequencies along the rows) came from a Gaussian
// fitted to the LSF, with no stated uncertainty; ours along the rows is MTF50 cos(slant).
TEST(SlantedEdgeReal, BaotouSatelliteEdgeAgreesWithThePublishedMtf50) {
  if (Absent("baotou_calval_edge.tif"))
    GTEST_SKIP() << "../shared/data/mtf_estimator_edges is absent (third-party images, GPL-3.0)";
  const GrayImage image = ReadGrayImage(kData + "baotou_calval_edge.tif");
  std::vector<SlantedEdgeResult> halves;
  for (const PixelRegion& region : {PixelRegion{36, 20, 52, 20}, PixelRegion{24, 64, 60, 20}})
    halves.push_back(MeasureSlantedEdge(image, region));
  const EdgeMtfCombination c = CombineEdgeMeasurements(halves);
  double slant = 0.0;
  for (const auto& h : halves) {
    slant += std::abs(h.angle_deg) / halves.size();
    std::printf(
        "Baotou half: slant %.3f deg, MTF50 %.4f +- %.4f (k = 2) cycles/px along the normal\n",
        std::abs(h.angle_deg),
        h.mtf50_cy_px,
        h.mtf50_expanded_cy_px);
  }
  const double along_rows = c.mtf50_cy_px * std::cos(slant * kDeg);
  const double u_along_rows = c.mtf50_expanded_cy_px * std::cos(slant * kDeg);
  constexpr double kPublished = 0.171712;
  std::printf("Baotou: MTF50 %.4f +- %.4f (k = 2) along the rows, published %.4f (%+.2f %%)\n",
              along_rows,
              u_along_rows,
              kPublished,
              100.0 * (along_rows / kPublished - 1.0));
  // Both halves are one edge of one image: they agree within their U.
  EXPECT_LE(std::abs(halves[0].mtf50_cy_px - halves[1].mtf50_cy_px),
            std::hypot(halves[0].mtf50_expanded_cy_px, halves[1].mtf50_expanded_cy_px));
  EXPECT_NEAR(slant, 16.6, 0.3);  // published 16.796 deg over both halves together
  // Within 5 % of the published value: the methods differ (a Gaussian fitted to the LSF there, the
  // e-SFR here) and no accuracy is published, so this is an agreement check, not a calibration:
  // measured -2.7 %, outside our own U (k = 2) of 2 %.
  EXPECT_NEAR(along_rows / kPublished, 1.0, 0.05);
}

}  // namespace
}  // namespace aerocal::stitch
