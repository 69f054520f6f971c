// Gimbal angles (yaw clockwise from north, pitch -90 = nadir, roll) -> omega, phi, kappa of
// docs/conventions.md section 4 in east-north-up: checked against what the angles mean
// geometrically (where the camera looks, where the image's right and top point), not against the
// formula of gimbal_attitude.cc.
#include "triangulation/import/gimbal_attitude.h"

#include "calib/camera/rotation.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace aerocal::triangulation {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kTight = 1e-12;  // rotations of a few products of sines and cosines

TEST(GimbalAttitude, NadirWithYawZeroIsTheIdentity) {
  const Eigen::Vector3d opk = OpkOfGimbal(0, -90, 0);
  EXPECT_NEAR(opk.norm(), 0, kTight);
}

TEST(GimbalAttitude, NadirYawGivesKappaMinusYaw) {
  for (double yaw : {-179.0, -90.1, -30.0, 12.5, 90.0, 135.0}) {
    const Eigen::Vector3d opk = OpkOfGimbal(yaw, -90, 0);
    EXPECT_NEAR(opk.x(), 0, kTight) << yaw;
    EXPECT_NEAR(opk.y(), 0, kTight) << yaw;
    EXPECT_NEAR(opk.z(), -yaw * kDeg, 1e-12) << yaw;
    // The image's top (photo +y) points along the heading: (sin yaw, cos yaw) east, north.
    const Eigen::Vector3d top = calib::RotationFromOpk(opk) * Eigen::Vector3d::UnitY();
    EXPECT_NEAR(top.x(), std::sin(yaw * kDeg), kTight);
    EXPECT_NEAR(top.y(), std::cos(yaw * kDeg), kTight);
  }
}

TEST(GimbalAttitude, AnyAnglesLookWhereTheyPoint) {
  // The viewing direction -W of yaw y, pitch p is (sin y cos p, cos y cos p, sin p) in ENU; the
  // photo x axis (image right) is horizontal, to the right of the heading (cos y, -sin y, 0), for
  // any pitch when roll is 0; roll turns it about the viewing direction (clockwise as seen by the
  // camera for a positive roll: the right side goes down).
  std::mt19937 rng(34);
  std::uniform_real_distribution<double> yaw(-180, 180), pitch(-89, 30), roll(-20, 20);
  for (int k = 0; k < 200; ++k) {
    const double y = yaw(rng), p = pitch(rng), r = roll(rng);
    const Eigen::Matrix3d rot = calib::RotationFromOpk(OpkOfGimbal(y, p, r));
    const Eigen::Vector3d view = -rot.col(2);
    const Eigen::Vector3d expected_view(std::sin(y * kDeg) * std::cos(p * kDeg),
                                        std::cos(y * kDeg) * std::cos(p * kDeg),
                                        std::sin(p * kDeg));
    EXPECT_LT((view - expected_view).norm(), 1e-9) << y << " " << p << " " << r;
    const Eigen::Vector3d right0(std::cos(y * kDeg), -std::sin(y * kDeg), 0);
    const Eigen::Vector3d up0 = right0.cross(expected_view);  // y = W x x with W = -view
    const Eigen::Vector3d right = std::cos(r * kDeg) * right0 - std::sin(r * kDeg) * up0;
    EXPECT_LT((rot.col(0) - right).norm(), 1e-9) << y << " " << p << " " << r;
    EXPECT_NEAR(rot.determinant(), 1, 1e-12);
  }
}

TEST(GimbalAttitude, TenDegreesFromNadirTowardTheHeadingIsPhiOrOmega) {
  // Heading north, pitch -80: the view tilts 10 deg toward north (+Y): a rotation about X,
  // omega = +10 deg (R = Rx(omega): -W = (0, sin w, -cos w) looks toward +Y for w > 0).
  Eigen::Vector3d opk = OpkOfGimbal(0, -80, 0);
  EXPECT_NEAR(opk.x(), 10 * kDeg, kTight);
  EXPECT_NEAR(opk.y(), 0, kTight);
  EXPECT_NEAR(opk.z(), 0, kTight);
  // Heading east, pitch -80: the view tilts toward +X: phi = -10 deg (-W = (-sin phi, 0, -cos phi))
  // and kappa = -90 deg (image top to the east).
  opk = OpkOfGimbal(90, -80, 0);
  const Eigen::Vector3d view = -calib::RotationFromOpk(opk).col(2);
  EXPECT_GT(view.x(), 0.17);
  EXPECT_NEAR(opk.y(), -10 * kDeg, 1e-9);
  EXPECT_NEAR(opk.z(), -90 * kDeg, 1e-9);
}

}  // namespace
}  // namespace aerocal::triangulation
