// Rotations inside the solver (calib/camera/rotation.h, calib/problem/rotation_manifold.h): the
// quaternion <-> omega-phi-kappa conversions round-trip, the increment manifold's Plus, Minus and
// Jacobians agree with each other and with numeric derivatives, and the covariance Jacobian
// d(omega, phi, kappa)/dq matches central differences away from phi = 90 deg and gives NaN
// (not separable) for omega and kappa at it.
#include "calib/camera/rotation.h"

#include "calib/problem/rotation_manifold.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace aerocal::calib {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(Rotation, QuaternionAndOpkRoundTrip) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> any(-M_PI, M_PI), tilt(-89.0 * kDeg, 89.0 * kDeg);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d opk(any(rng), tilt(rng), any(rng));
    const Eigen::Vector4d q = QuaternionFromOpk(opk);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT((OpkFromQuaternion(q) - opk).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((RotationFromQuaternion(q) - RotationFromOpk(opk)).cwiseAbs().maxCoeff(), 1e-15);
  }
  // Whole turns come back on the branch of the file's angles.
  const Eigen::Vector3d file(0.1, 0.2, 3.2);  // kappa beyond pi
  EXPECT_LT((OpkFromQuaternionNear(QuaternionFromOpk(file), file) - file).norm(), 1e-12);
}

TEST(Rotation, GimbalLockKeepsTheRotation) {
  // phi = +-90 deg: omega and kappa are not separable; OpkFromRotation puts the defined
  // combination into omega (kappa = 0) and the rotation itself is kept exactly.
  for (double phi : {90.0 * kDeg, -90.0 * kDeg}) {
    const Eigen::Matrix3d r = RotationFromOpk(Eigen::Vector3d(0.3, phi, -0.1));
    const Eigen::Vector3d opk = OpkFromRotation(r);
    EXPECT_EQ(opk.z(), 0.0);
    EXPECT_LT((RotationFromOpk(opk) - r).cwiseAbs().maxCoeff(), 1e-15);
    const Eigen::Matrix3d j = OpkJacobianOfIncrement(r);
    EXPECT_TRUE(std::isnan(j(0, 0)) && std::isnan(j(2, 2)));
    EXPECT_TRUE(j.row(1).allFinite());
  }
}

TEST(RotationManifold, PlusMinusAndJacobiansAgree) {
  const ScaledRotationManifold manifold({0.5, 2.0, 1.5});
  const Eigen::Vector4d q = QuaternionFromOpk(Eigen::Vector3d(0.2, -0.4, 1.1));
  const Eigen::Vector3d delta(0.03, -0.02, 0.05);
  Eigen::Vector4d moved;
  ASSERT_TRUE(manifold.Plus(q.data(), delta.data(), moved.data()));
  EXPECT_NEAR(moved.norm(), 1.0, 1e-15);
  // R' = Exp(s delta) R: delta is a rotation vector in object axes.
  const Eigen::Vector3d v(0.5 * delta(0), 2.0 * delta(1), 1.5 * delta(2));
  const Eigen::Matrix3d expected =
      Eigen::AngleAxisd(v.norm(), v.normalized()).toRotationMatrix() * RotationFromQuaternion(q);
  EXPECT_LT((RotationFromQuaternion(moved) - expected).cwiseAbs().maxCoeff(), 1e-15);
  Eigen::Vector3d back;
  ASSERT_TRUE(manifold.Minus(moved.data(), q.data(), back.data()));
  EXPECT_LT((back - delta).norm(), 1e-14);
  // PlusJacobian against central differences of Plus at 0; MinusJacobian is its left inverse.
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus_j;
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> minus_j;
  ASSERT_TRUE(manifold.PlusJacobian(q.data(), plus_j.data()));
  ASSERT_TRUE(manifold.MinusJacobian(q.data(), minus_j.data()));
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    Eigen::Vector4d a, b;
    d(k) = h;
    manifold.Plus(q.data(), d.data(), a.data());
    d(k) = -h;
    manifold.Plus(q.data(), d.data(), b.data());
    EXPECT_LT(((a - b) / (2 * h) - plus_j.col(k)).norm(), 1e-9);
  }
  EXPECT_LT((minus_j * plus_j - Eigen::Matrix3d::Identity()).norm(), 1e-14);
}

TEST(Rotation, OpkJacobianOfQuaternionMatchesCentralDifferences) {
  for (const Eigen::Vector3d& opk : {Eigen::Vector3d(0.01, -0.02, 0.3),
                                     Eigen::Vector3d(0.4, 1.2, -2.0),
                                     Eigen::Vector3d(-0.2, 80.0 * kDeg, 3.0)}) {
    const Eigen::Vector4d q = QuaternionFromOpk(opk);
    const Eigen::Matrix<double, 3, 4> j = OpkJacobianOfQuaternion(q);
    const double h = 1e-7;
    for (int i = 0; i < 4; ++i) {
      Eigen::Vector4d a = q, b = q;
      a(i) += h;
      b(i) -= h;
      const Eigen::Vector3d numeric = (OpkFromQuaternion(a) - OpkFromQuaternion(b)) / (2 * h);
      EXPECT_LT((numeric - j.col(i)).norm(), 1e-6 * (1.0 + j.col(i).norm())) << opk.transpose();
    }
  }
}

}  // namespace
}  // namespace aerocal::calib
