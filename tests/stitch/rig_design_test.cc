// Design figures of a rig (stitch/rig/rig_design.h) on the four-head uav4 example of configs/:
// GSD change ratios against the closed form of the tilted head, the coverage of one nadir head
// against its format, the overlap zones and the twelve standard tie positions.
#include "stitch/rig/rig_design.h"

#include "calib/camera/rig_io.h"
#include "stitch/rig/rig_conversion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace aerocal::stitch {
namespace {

calib::Rig Uav4() { return calib::ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_uav4.yaml"); }

TEST(RigDesign, GsdRatiosOfTheTiltedHeadsAgreeWithTheClosedForm) {
  const RigDesign d = DesignRig(Uav4(), 300.0, 100);
  ASSERT_EQ(d.heads.size(), 4u);
  // Hand figures: at the principal point of a head tilted 24 deg, 1 / cos^2 24 and 1 / cos 24.
  EXPECT_NEAR(ClosedFormGsdRatio(24 * M_PI / 180, 0).x(),
              1.0 / std::pow(std::cos(24 * M_PI / 180), 2),
              1e-15);
  EXPECT_NEAR(ClosedFormGsdRatio(24 * M_PI / 180, 0).x(), 1.198229, 1e-6);
  EXPECT_NEAR(ClosedFormGsdRatio(37 * M_PI / 180, 0).y(), 1.252136, 1e-6);
  constexpr double kTolerance = 0.005;  // the 0.5 %
  int compared = 0;
  for (const HeadDesign& head : d.heads) {
    EXPECT_NEAR(head.tilt_deg, head.id == "A" || head.id == "C" ? 24.0 : 37.0, 1e-9) << head.id;
    EXPECT_NEAR(head.nadir_gsd_m, 0.0082 * 300 / 24.5, 1e-12);
    ASSERT_EQ(head.samples.size(), 9u);
    for (const GsdSample& s : head.samples) {
      if (!s.on_tilt_line) continue;
      ++compared;
      for (int axis = 0; axis < 2; ++axis)
        EXPECT_NEAR(s.ratio[axis] / s.closed_form[axis], 1.0, kTolerance)
            << head.id << " " << s.where;
    }
    // The principal point and the two edge midpoints along the tilt lie on the principal line.
    EXPECT_TRUE(head.samples[0].on_tilt_line);
    EXPECT_NEAR(
        head.samples[0].ratio.x(), ClosedFormGsdRatio(head.tilt_deg * M_PI / 180, 0).x(), 1e-6);
  }
  EXPECT_EQ(compared, 12);
}

TEST(RigDesign, OneNadirHeadCoversItsFormat) {
  calib::Camera camera;
  camera.name = "nadir";
  camera.pixel_size_mm = 0.01;
  camera.width_px = 2000;
  camera.height_px = 1000;
  camera.interior[calib::Camera::Model::kC] = 50.0;
  const calib::Rig rig = calib::RigFromCamera(camera);
  const RigDesign d = DesignRig(rig, 500.0, 200);
  const double gsd = 0.01 * 500 / 50.0;
  // Cell resolution: 10 px cells; the area of a band of one cell around the outline at most.
  const double cell_m = d.coverage.cell_px * gsd;
  EXPECT_NEAR(d.covered_area_m2, 2000 * 1000 * gsd * gsd, (2000 + 1000) * 2 * gsd * cell_m);
  EXPECT_NEAR(d.effective_px.Width(), 1999, 2 * d.coverage.cell_px);
  EXPECT_NEAR(d.effective_px.Height(), 999, 2 * d.coverage.cell_px);
  EXPECT_TRUE(d.zone_area_m2.empty());
  EXPECT_TRUE(d.standard_positions.empty());
  EXPECT_NEAR(d.heads[0].samples[0].ratio.x(), 1.0, 1e-9);
}

TEST(RigDesign, Uav4HasFiveTwoFoldZonesTwoTripleZonesAndTwelveStandardPositions) {
  const calib::Rig rig = Uav4();
  const RigDesign d = DesignRig(rig, 300.0, 200);
  std::set<std::string> zones;
  for (const auto& [zone, area] : d.zone_area_m2) {
    zones.insert(zone);
    EXPECT_GT(area, 0.0) << zone;
  }
  EXPECT_EQ(zones, (std::set<std::string>{"AB", "AC", "AD", "BC", "CD", "ABC", "ACD"}));
  ASSERT_EQ(d.standard_positions.size(), 12u);
  const std::vector<std::string> names = {
      "AB-1", "AB-2", "AC-1", "AC-2", "AD-1", "AD-2", "BC-1", "BC-2", "CD-1", "CD-2", "ABC", "ACD"};
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, 300.0));
  for (size_t i = 0; i < names.size(); ++i) {
    const StandardPosition& s = d.standard_positions[i];
    EXPECT_EQ(s.name, names[i]);
    // Exactly the zone's heads see the position.
    std::string seen;
    for (int k = 0; k < 4; ++k) {
      const auto p = converter.HeadFromVirtual(k, s.virtual_px);
      if (p && converter.InHeadFormat(k, *p)) seen += rig.heads[k].id;
    }
    EXPECT_EQ(seen, s.zone) << s.name;
  }
  // The effective format lies inside the covered box, which the file's format holds.
  EXPECT_GE(d.effective_px.min_px.minCoeff(), d.covered_box_px.min_px.minCoeff());
  EXPECT_LE(d.covered_box_px.Width(), rig.virtual_camera.camera.width_px);
  EXPECT_LE(d.covered_box_px.Height(), rig.virtual_camera.camera.height_px);
  EXPECT_GT(d.effective_area_m2, 0.5 * d.covered_area_m2);
  EXPECT_LT(d.effective_area_m2, d.covered_area_m2);
}

}  // namespace
}  // namespace aerocal::stitch
