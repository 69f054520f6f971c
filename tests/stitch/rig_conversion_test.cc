// Conversion between head pixels and the single-centre virtual image (stitch/rig/rig_conversion.h):
// noise-free round trips to 1e-9 px, the dual-lens example's reference head lying in the virtual
// image as a pure shift, the level virtual image, and the relief displacement formula of
// CONVENTIONS.md against the exact computation.
#include "stitch/rig/rig_conversion.h"

#include "calib/camera/rig_io.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::stitch {
namespace {

constexpr double kDeg = M_PI / 180.0;
// Round trips: the Newton inverse of the correction stops below 1e-10 px, the rest is rounding
// of metre-scale coordinates (1e-13 relative at 1200 m is ~1e-12 px).
constexpr double kRoundTripPx = 1e-9;

calib::Rig ExampleRig() {
  return calib::ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens.yaml");
}

// A tilted three-head rig with distortion in every head, non-zero increments, time offsets and
// velocity.
calib::Rig DistortedRig(calib::VirtualOrientation orientation) {
  calib::Rig rig;
  rig.name = "test";
  rig.reference_head = "N";
  for (int k = 0; k < 3; ++k) {
    calib::RigHead head;
    head.id = std::string(1, "NLR"[k]);
    head.camera.pixel_size_mm = 0.0046;
    head.camera.width_px = 8000;
    head.camera.height_px = 6000;
    head.camera.interior = {80.0 + k, 0.02 * k, -0.01, -2e-5, 3e-9, 0, 1e-6, -2e-6, 5e-5, -3e-5};
    head.mount_rad =
        Eigen::Vector3d(k == 0 ? 0.0 : (k == 1 ? 20 : -20) * kDeg, 0.5 * kDeg * k, 0.01 * k);
    head.lever_arm_m = Eigen::Vector3d(0.0, 0.08 * (k == 1) - 0.08 * (k == 2), 0.01 * k);
    rig.heads.push_back(head);
  }
  rig.virtual_camera =
      calib::VirtualCamera::Pinhole(orientation, 80.0, 0.0046, 30000, 9000, 0.1, -0.05, 800.0);
  return rig;
}

RigExposure TiltedExposure() {
  RigExposure exposure;
  exposure.rig_opk_rad = Eigen::Vector3d(0.03, -0.02, 0.7);
  exposure.rig_center_m = Eigen::Vector3d(4000.0, -2500.0, 950.0);
  exposure.velocity_mps = Eigen::Vector3d(55.0, 12.0, -0.4);
  exposure.increment_rad = {Eigen::Vector3d::Zero(),
                            Eigen::Vector3d(1e-4, -2e-4, 5e-5),
                            Eigen::Vector3d(-3e-4, 1e-4, 0.0)};
  exposure.dt_s = {0.0, 0.0012, -0.0007};
  return exposure;
}

TEST(RigConversion, HeadToVirtualAndBackReproducesTheHeadPixel) {
  for (const auto orientation :
       {calib::VirtualOrientation::kRig, calib::VirtualOrientation::kLevel}) {
    const calib::Rig rig = DistortedRig(orientation);
    const RigExposure exposure = TiltedExposure();
    const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, 800.0));
    double worst = 0.0;
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i <= 8; ++i)
        for (int j = 0; j <= 6; ++j) {
          const Eigen::Vector2d head_px(i * 999.875, j * 999.8333);
          const auto virtual_px = converter.VirtualFromHead(k, head_px);
          ASSERT_TRUE(virtual_px.has_value());
          const auto back = converter.HeadFromVirtual(k, *virtual_px);
          ASSERT_TRUE(back.has_value());
          worst = std::max(worst, (*back - head_px).norm());
        }
    EXPECT_LT(worst, kRoundTripPx) << "orientation " << calib::VirtualOrientationName(orientation);
  }
}

// The plane and the virtual projection by hand: a head pixel's plane point lies on the plane,
// on the head's ray, and the virtual camera sees it at its collinearity pixel.
TEST(RigConversion, FollowsTheConventionsChain) {
  const calib::Rig rig = DistortedRig(calib::VirtualOrientation::kLevel);
  const RigExposure exposure = TiltedExposure();
  const RigConverter converter(rig, exposure, MakeRectificationPlane(rig, exposure, 800.0));
  const Eigen::Vector2d head_px(1234.5, 4321.25);
  const auto ground = converter.PlanePointOfHeadPixel(1, head_px);
  ASSERT_TRUE(ground.has_value());
  EXPECT_NEAR(ground->z(), 950.0 - 800.0, 1e-9) << "level: the plane Z = O_Z - H";
  Eigen::Vector2d reprojected;
  ASSERT_TRUE(
      rig.heads[1].camera.ProjectToPixel(calib::OpkFromRotation(converter.ObjectFromHead(1)),
                                         converter.HeadCenter(1),
                                         *ground,
                                         &reprojected));
  EXPECT_LT((reprojected - head_px).norm(), kRoundTripPx);
  // Level virtual camera: R_v = Rz(kappa of the rig), looking straight down from O.
  const Eigen::Matrix3d rv = converter.ObjectFromVirtual();
  EXPECT_NEAR(
      (rv - calib::RotationFromOpk(Eigen::Vector3d(
                0, 0, calib::OpkFromRotation(calib::RotationFromOpk(exposure.rig_opk_rad))[2])))
          .norm(),
      0.0,
      1e-15);
  const Eigen::Vector3d in_virtual = rv.transpose() * (*ground - exposure.rig_center_m);
  const calib::Camera& v = rig.virtual_camera.camera;
  const double c = v.c_mm();
  const Eigen::Vector2d expected = v.PixelFromPhoto(
      v.PrincipalPointMm() +
      Eigen::Vector2d(-c * in_virtual.x() / in_virtual.z(), -c * in_virtual.y() / in_virtual.z()));
  EXPECT_LT((*converter.VirtualFromHead(1, head_px) - expected).norm(), 1e-9);
  // Rig orientation: the plane is perpendicular to the rig's axis, H below O along it.
  const calib::Rig tilted = DistortedRig(calib::VirtualOrientation::kRig);
  const RectificationPlane plane = MakeRectificationPlane(tilted, exposure, 800.0);
  const Eigen::Matrix3d r = calib::RotationFromOpk(exposure.rig_opk_rad);
  EXPECT_NEAR((plane.normal - r.col(2)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(plane.normal.dot(exposure.rig_center_m - 800.0 * r.col(2)) - plane.offset, 0.0, 1e-9);
}

// In the example the reference head sits at the virtual centre with the virtual camera's c and
// rays: its image lies in the virtual image shifted by (459, 21) px, whatever the height; head B's
// footprint lies inside the virtual format.
TEST(RigConversion, DualLensExampleReferenceHeadIsAShiftOfTheVirtualImage) {
  const calib::Rig rig = ExampleRig();
  const RigExposure nadir;
  for (const double height : {300.0, 1200.0, 5000.0}) {
    const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, height));
    for (const Eigen::Vector2d& a :
         {Eigen::Vector2d(0, 0), Eigen::Vector2d(4999.5, 4999.5), Eigen::Vector2d(9999, 1234.25)}) {
      const auto v = converter.VirtualFromHead(0, a);
      ASSERT_TRUE(v.has_value());
      EXPECT_LT((*v - a - Eigen::Vector2d(459, 21)).norm(), 1e-8);
    }
  }
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, 1200.0));
  for (const Eigen::Vector2d& b : {Eigen::Vector2d(0, 0),
                                   Eigen::Vector2d(9999, 0),
                                   Eigen::Vector2d(0, 9999),
                                   Eigen::Vector2d(9999, 9999)}) {
    const auto v = converter.VirtualFromHead(1, b);
    ASSERT_TRUE(v.has_value());
    EXPECT_GE(v->x(), 0.0);
    EXPECT_GE(v->y(), 0.0);
    EXPECT_LE(v->x(), rig.virtual_camera.camera.width_px - 1.0);
    EXPECT_LE(v->y(), rig.virtual_camera.camera.height_px - 1.0);
  }
  // Converging by 1 deg: B's image sits c tan(1 deg) / p = 436 px left of A's in the virtual
  // image, less the 3 px parallax of the 0.15 m baseline at 1200 m (c 0.15 / H / p).
  const auto va = converter.VirtualFromHead(0, {5499.5, 4499.5});  // A's principal point
  const auto vb = converter.VirtualFromHead(1, {5499.5, 4499.5});  // B's principal point
  EXPECT_NEAR(
      va->x() - vb->x(), 150.0 * std::tan(kDeg) / 0.006 - 150.0 * 0.15 / 1200.0 / 0.006, 0.5);
}

// Exact displacement between the virtual pixels two heads give for a point dh off the plane.
double ExactDisplacement(const RigConverter& converter,
                         int j,
                         int k,
                         const Eigen::Vector3d& point) {
  const auto pj = converter.HeadPixelOfPoint(j, point);
  const auto pk = converter.HeadPixelOfPoint(k, point);
  const auto vj = converter.VirtualFromHead(j, *pj);
  const auto vk = converter.VirtualFromHead(k, *pk);
  return (*vj - *vk).norm();
}

TEST(RigConversion, ReliefDisplacementFormulaAgainstTheExactComputation) {
  // Parallel heads, baseline across the axis: the formula is exact.
  calib::Rig rig = ExampleRig();
  rig.heads[1].mount_rad.setZero();
  rig.heads[1].lever_arm_m = Eigen::Vector3d(0.15, 0.02, 0.0);
  const RigExposure nadir;
  const double height = 1200.0;
  const RigConverter parallel(rig, nadir, MakeRectificationPlane(rig, nadir, height));
  for (const double dh : {10.0, 100.0, 400.0, -150.0}) {
    const Eigen::Vector3d point(35.0, -80.0, -(height - dh));
    const double formula = ReliefDisplacementPx(rig, 0, 1, height, dh);
    EXPECT_NEAR(ExactDisplacement(parallel, 0, 1, point),
                std::abs(formula),
                1e-9 * std::abs(formula) + 1e-9)
        << "dh " << dh;
  }
  // By hand for dh = 100 m: (150 / 0.006) * 0.1513 * 100 / (1200 * 1100) = 0.2866 px.
  EXPECT_NEAR(ReliefDisplacementPx(rig, 0, 1, 1200.0, 100.0),
              25000.0 * std::hypot(0.15, 0.02) * 100.0 / (1200.0 * 1100.0),
              1e-12);
  // The example (converging 1 deg, 0.01 m along the axis): the formula is an estimate, within 2 %.
  const calib::Rig example = ExampleRig();
  const RigConverter converter(example, nadir, MakeRectificationPlane(example, nadir, height));
  for (const double dh : {50.0, 200.0}) {
    const Eigen::Vector3d point(10.0, 20.0, -(height - dh));
    const double formula = ReliefDisplacementPx(example, 0, 1, height, dh);
    EXPECT_NEAR(ExactDisplacement(converter, 0, 1, point), formula, 0.02 * formula) << "dh " << dh;
  }
}

}  // namespace
}  // namespace aerocal::stitch
