// The direction residual (calib/residuals/direction.h): zero for a perfect observation computed
// independently (Eigen rotation, the model's MeasuredFromIdeal), whitening by hand, the focal-plane
// covariance of an angular sigma by hand, gradients against ceres::GradientChecker; the sub-image
// residual (mapping in front) against the frame residual at the mapped pixel.
#include "calib/camera/brown_fraser10.h"
#include "calib/residuals/direction.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::calib {
namespace {

struct DirectionScene {
  double interior[10] = {50.012, 0.011, -0.007, -3e-5, 2e-8, -5e-12, 3e-6, -2e-6, 5e-5, -3e-5};
  Eigen::Vector3d opk{0.004, -0.006, 0.008};
  Eigen::Vector4d rotation = QuaternionFromOpk(opk);
  Eigen::Matrix3d g = RotationFromOpk(Eigen::Vector3d(0.05, -0.12, 0.0));  // a goniometer setting
  double direction[2] = {0.21, -0.08};                                     // azimuth, elevation
  PixelFrame frame{0.006, 6000, 4000};

  // The measured pixel of the direction, computed with Eigen (independent of the functor).
  Eigen::Vector2d Pixel() const {
    const Eigen::Vector3d t(std::sin(direction[0]) * std::cos(direction[1]),
                            std::sin(direction[1]),
                            -std::cos(direction[0]) * std::cos(direction[1]));
    const Eigen::Vector3d uvw = RotationFromOpk(opk).transpose() * g.transpose() * t;
    const Eigen::Vector2d ideal(-interior[0] * uvw.x() / uvw.z(), -interior[0] * uvw.y() / uvw.z());
    Eigen::Vector2d measured;
    EXPECT_TRUE(BrownFraser10Model::MeasuredFromIdeal(interior, ideal, &measured));
    return frame.PixelFromPhoto(measured);
  }
};

TEST(DirectionResidual, ZeroForAPerfectObservationWhitenedAndGradientsMatch) {
  DirectionScene s;
  const Eigen::Vector2d pixel = s.Pixel();
  const double sigma_mm = 0.1 * s.frame.pixel_size_mm;  // 0.1 px, no angular part
  const Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * sigma_mm * sigma_mm;
  auto cost = ModelDirectionResidual<BrownFraser10Model>::Create(s.frame, s.g, pixel, covariance);
  double r[2];
  const double* blocks[] = {s.interior, s.rotation.data(), s.direction};
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-5);  // 1e-5 sigma = 1e-6 px
  EXPECT_NEAR(r[1], 0.0, 1e-5);
  // One pixel off in row: -1 px in y (photo y is up) -> about -10 sigma in y (the distortion's
  // derivative changes it by K1 r^2 order, < 2 % here).
  auto shifted = ModelDirectionResidual<BrownFraser10Model>::Create(
      s.frame, s.g, pixel + Eigen::Vector2d(0, 1), covariance);
  ASSERT_TRUE(shifted->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[1], -10.0, 0.2);
  EXPECT_NEAR(r[0], 0.0, 0.2);
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(cost.get(), no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  double* probe[] = {s.interior, s.rotation.data(), s.direction};
  EXPECT_TRUE(checker.Probe(probe, 1e-6, &results)) << results.error_log;
  // The factory by model id gives the same residual.
  auto by_id = MakeDirectionResidual(
      CameraModelId::kBrownFraser10, s.frame, s.g, pixel + Eigen::Vector2d(0, 1), covariance);
  double r2[2];
  ASSERT_TRUE(by_id->Evaluate(blocks, r2, nullptr));
  EXPECT_DOUBLE_EQ(r2[1], r[1]);
}

// The sub-image residual is the frame residual at the mapped virtual pixel: an affine mapping
// (conditioned parameters) from a sub-image pixel to the pixel the scene computes, the same
// whitened residual as ModelDirectionResidual there; gradients (mapping block included) against
// ceres::GradientChecker; the factory by ids gives the same value.
TEST(SubimageDirectionResidual, EqualsTheFrameResidualAtTheMappedPixelAndGradientsMatch) {
  DirectionScene s;
  const Eigen::Vector2d virtual_pixel = s.Pixel() + Eigen::Vector2d(0.3, -0.7);  // not exact
  SubimageMapping mapping{"II", 3000, 2000, MappingModel::kAffine, {}};
  // A near-unit affine map; the sub-image pixel that lands on virtual_pixel by its inverse.
  const double a1 = 1.0002, a2 = -0.0003, b1 = 0.0004, b2 = 0.9998, a0 = 2990.0, b0 = 1.5;
  mapping.params = {a1, a2, a0, b1, b2, b0};
  const Eigen::Vector2d uv = mapping.SubFromVirtual(virtual_pixel);
  ASSERT_NEAR((mapping.VirtualFromSub(uv) - virtual_pixel).norm(), 0.0, 1e-9);
  const MappingConditioning cond = mapping.Conditioning();
  std::vector<double> conditioned = ConditionedFromPlain(mapping.model, cond, mapping.params);
  const Eigen::Matrix2d covariance = DirectionCovarianceMm2(
      s.frame.PhotoFromPixel(virtual_pixel), s.interior[0], 0.1, s.frame.pixel_size_mm, 2e-6);
  auto sub = ModelSubimageDirectionResidual<BrownFraser10Model, AffineMapping>::Create(
      s.frame, cond, uv, s.g, covariance);
  auto frame =
      ModelDirectionResidual<BrownFraser10Model>::Create(s.frame, s.g, virtual_pixel, covariance);
  double r_sub[2], r_frame[2];
  const double* sub_blocks[] = {conditioned.data(), s.interior, s.rotation.data(), s.direction};
  const double* frame_blocks[] = {s.interior, s.rotation.data(), s.direction};
  ASSERT_TRUE(sub->Evaluate(sub_blocks, r_sub, nullptr));
  ASSERT_TRUE(frame->Evaluate(frame_blocks, r_frame, nullptr));
  EXPECT_GT(std::abs(r_frame[1]), 1.0);     // the 0.7 px offset shows
  EXPECT_NEAR(r_sub[0], r_frame[0], 1e-7);  // 1e-7 sigma: the mapping round trip's 1e-9 px
  EXPECT_NEAR(r_sub[1], r_frame[1], 1e-7);
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(sub.get(), no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  double* probe[] = {conditioned.data(), s.interior, s.rotation.data(), s.direction};
  EXPECT_TRUE(checker.Probe(probe, 1e-6, &results)) << results.error_log;
  auto by_id = MakeSubimageDirectionResidual(
      CameraModelId::kBrownFraser10, MappingModel::kAffine, s.frame, cond, uv, s.g, covariance);
  double r_id[2];
  ASSERT_TRUE(by_id->Evaluate(sub_blocks, r_id, nullptr));
  EXPECT_DOUBLE_EQ(r_id[0], r_sub[0]);
  EXPECT_DOUBLE_EQ(r_id[1], r_sub[1]);
}

TEST(DirectionResidual, DirectionBehindTheCameraIsRejected) {
  DirectionScene s;
  s.direction[0] = 3.0;  // nearly +z: behind the camera
  auto cost = ModelDirectionResidual<BrownFraser10Model>::Create(
      s.frame, s.g, Eigen::Vector2d(3000, 2000), Eigen::Matrix2d::Identity() * 1e-6);
  double r[2];
  const double* blocks[] = {s.interior, s.rotation.data(), s.direction};
  EXPECT_FALSE(cost->Evaluate(blocks, r, nullptr));
}

TEST(DirectionCovariance, AngularSigmaThroughThePrincipalDistance) {
  // On the axis: c sigma in both directions, plus the image part.
  const Eigen::Matrix2d axis = DirectionCovarianceMm2({0.0, 0.0}, 100.0, 0.0, 0.006, 1e-5);
  EXPECT_NEAR(axis(0, 0), 1e-6, 1e-18);  // (100 mm 1e-5)^2
  EXPECT_NEAR(axis(1, 1), 1e-6, 1e-18);
  // At 45 deg off axis along x (x = c): radial c sigma / cos^2 = 2 c sigma, tangential sqrt(2) c
  // sigma.
  const Eigen::Matrix2d off = DirectionCovarianceMm2({100.0, 0.0}, 100.0, 0.5, 0.006, 1e-5);
  const double image = 0.5 * 0.006;
  EXPECT_NEAR(off(0, 0), 4e-6 + image * image, 1e-15);
  EXPECT_NEAR(off(1, 1), 2e-6 + image * image, 1e-15);
  EXPECT_NEAR(off(0, 1), 0.0, 1e-18);
}

}  // namespace
}  // namespace aerocal::calib
