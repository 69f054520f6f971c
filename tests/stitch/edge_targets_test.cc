// Edge targets on the ground found in the image from the exposure's orientation: the projected
// edge, its slant and axis, the local GSD by hand (a nadir image, c 100 mm, 10 um pixels, 1000 m
// above ground: GSD 0.1 m), then the slanted edge rendered exactly along the projected line and
// measured in the region found: MTF50 within 2 % of the analytic value, the slant as projected.
#include "stitch/quality/edge_targets.h"

#include "tests/support/rendered_targets.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::stitch {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

calib::Camera NadirCamera() {
  calib::Camera camera = calib::Camera::OfModel(calib::CameraModelId::kBrownFraser10);
  camera.pixel_size_mm = 0.01;
  camera.width_px = 400;
  camera.height_px = 300;
  camera.interior[0] = 100.0;
  return camera;
}

const Eigen::Vector3d kCenter(0.0, 0.0, 1000.0);
const EdgeTarget kTarget{"E1", {-1.0, -6.0, 0.0}, {-0.3, 6.0, 0.0}};

// The image of the exposure: the edge rendered along the projected line (bright to its right).
GrayImage RenderAlong(const calib::Camera& camera, const EdgeTargetRegion& r, double s) {
  const Eigen::Vector2d d = (r.end_px - r.start_px).normalized();
  const Eigen::Vector2d n(d.y(), -d.x());
  const double centre = n.x() * 0.5 * (camera.width_px - 1) + n.y() * 0.5 * (camera.height_px - 1);
  return testing::RenderEdge(camera.width_px,
                             camera.height_px,
                             std::atan2(n.y(), n.x()),
                             s,
                             40.0,
                             200.0,
                             n.dot(r.start_px) - centre);
}

TEST(EdgeTargets, RegionSlantAndGsdOfANadirImage) {
  const calib::Camera camera = NadirCamera();
  const EdgeTargetRegion r = RegionOfEdgeTarget(camera, Eigen::Vector3d::Zero(), kCenter, kTarget);
  ASSERT_TRUE(r.usable) << r.reason;
  // col = 10 X + 199.5, row = -10 Y + 149.5.
  EXPECT_NEAR(r.start_px.x(), 189.5, 1e-6);
  EXPECT_NEAR(r.start_px.y(), 209.5, 1e-6);
  EXPECT_NEAR(r.end_px.x(), 196.5, 1e-6);
  EXPECT_NEAR(r.end_px.y(), 89.5, 1e-6);
  EXPECT_NEAR(r.gsd_m, 0.1, 1e-9);
  EXPECT_EQ(r.axis, MtfAxis::kX);
  EXPECT_NEAR(r.slant_deg, std::atan(7.0 / 120.0) / kDeg, 1e-9);
  // Central 80 %: rows 101.5 .. 197.5; cols 190.2 .. 195.8 widened by 32 px.
  EXPECT_EQ(r.region.row, 102);
  EXPECT_EQ(r.region.height, 96);
  EXPECT_EQ(r.region.col, 159);
  EXPECT_EQ(r.region.width, 69);
  // At most 64 px along the edge (max_length_px): rows 117.5 .. 181.5, cols 191.1 .. 194.9.
  EdgeTargetRegionOptions short_region;
  short_region.max_length_px = 64.0;
  const EdgeTargetRegion s =
      RegionOfEdgeTarget(camera, Eigen::Vector3d::Zero(), kCenter, kTarget, short_region);
  ASSERT_TRUE(s.usable) << s.reason;
  EXPECT_EQ(s.region.row, 118);
  EXPECT_EQ(s.region.height, 64);
  EXPECT_EQ(s.region.col, 160);
  EXPECT_EQ(s.region.width, 67);
  // A target outside the image is not usable, and says why.
  const EdgeTargetRegion far = RegionOfEdgeTarget(
      camera, Eigen::Vector3d::Zero(), kCenter, {"far", {30.0, -6.0, 0.0}, {30.7, 6.0, 0.0}});
  EXPECT_FALSE(far.usable);
  EXPECT_EQ(far.reason, "the region leaves the image");
}

TEST(EdgeTargets, MtfMeasuredInTheRegionFound) {
  const calib::Camera camera = NadirCamera();
  for (double kappa : {0.0, 80.0 * kDeg}) {  // turned by 80 deg the edge runs along the rows
    const Eigen::Vector3d opk(0.0, 0.0, kappa);
    const EdgeTargetRegion r = RegionOfEdgeTarget(camera, opk, kCenter, kTarget);
    ASSERT_TRUE(r.usable) << r.reason;
    for (double s : {0.6, 1.2}) {
      const SlantedEdgeResult m = MeasureSlantedEdge(RenderAlong(camera, r, s), r.region);
      const double truth = testing::FirstCrossing(
          [&](double f) { return testing::RenderedEdgeMtf(f, s, r.slant_deg * kDeg); }, 0.5);
      EXPECT_EQ(m.axis, r.axis) << "kappa " << kappa;
      EXPECT_NEAR(std::abs(m.angle_deg), r.slant_deg, 0.05) << "kappa " << kappa;
      EXPECT_LT(std::abs(m.mtf50_cy_px / truth - 1.0), 0.02) << "kappa " << kappa << " s " << s;
    }
  }
}

}  // namespace
}  // namespace aerocal::stitch
