// Tests of the 10-parameter model (CONVENTIONS.md): zero terms, the inverse to 1e-6 px over the
// whole format, derivatives against numeric differentiation, and a nadir projection by hand.
#include "calib/camera/brown_fraser10.h"

#include "calib/camera/camera.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

// A large-format camera with distortion of a few pixels at the corner (DMZ-like corrections).
InteriorParams TypicalInterior() {
  InteriorParams p{};
  p[Model::kC] = 170.038;
  p[Model::kX0] = -0.0024;
  p[Model::kY0] = 0.0015;
  p[Model::kK1] = 3e-8;
  p[Model::kK2] = -2e-12;
  p[Model::kK3] = 1e-16;
  p[Model::kP1] = 2e-7;
  p[Model::kP2] = -1.5e-7;
  p[Model::kB1] = 1e-5;
  p[Model::kB2] = -8e-6;
  return p;
}

TEST(BrownFraser10, ParameterTableMatchesConventions) {
  const char* names[] = {"c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2"};
  const char* units[] = {"mm", "mm", "mm", "mm^-2", "mm^-4", "mm^-6", "mm^-1", "mm^-1", "1", "1"};
  for (int i = 0; i < Model::kNumParams; ++i) {
    EXPECT_EQ(Model::kParams[i].name, names[i]);
    EXPECT_EQ(Model::kParams[i].unit, units[i]);
    EXPECT_EQ(Model::IndexOf(names[i]), i);
  }
  EXPECT_EQ(Model::IndexOf("K4"), -1);
}

TEST(BrownFraser10, ZeroCoefficientsGiveZeroCorrection) {
  InteriorParams p{};
  p[Model::kC] = 100;
  p[Model::kX0] = 0.5;
  p[Model::kY0] = -0.25;
  const double xy[2] = {10.0, -20.0};
  double ideal[2];
  Model::IdealFromMeasured(p.data(), xy, ideal);
  EXPECT_DOUBLE_EQ(ideal[0], 9.5);
  EXPECT_DOUBLE_EQ(ideal[1], -19.75);
}

TEST(BrownFraser10, CorrectionMatchesTheFormulaByHand) {
  const InteriorParams p = TypicalInterior();
  const double xy[2] = {40.0, -30.0};
  const double xb = 40.0 - p[Model::kX0], yb = -30.0 - p[Model::kY0];
  const double r2 = xb * xb + yb * yb;
  const double radial = p[Model::kK1] * r2 + p[Model::kK2] * r2 * r2 + p[Model::kK3] * r2 * r2 * r2;
  const double dx = xb * radial + p[Model::kP1] * (r2 + 2 * xb * xb) + 2 * p[Model::kP2] * xb * yb +
                    p[Model::kB1] * xb + p[Model::kB2] * yb;
  const double dy = yb * radial + 2 * p[Model::kP1] * xb * yb + p[Model::kP2] * (r2 + 2 * yb * yb);
  double ideal[2];
  Model::IdealFromMeasured(p.data(), xy, ideal);
  EXPECT_NEAR(ideal[0], xb + dx, 1e-13);
  EXPECT_NEAR(ideal[1], yb + dy, 1e-13);
}

TEST(BrownFraser10, InverseRoundTripBelowOneMicropixelOverTheWholeFormat) {
  const InteriorParams p = TypicalInterior();
  const double pixel_mm = 0.009;
  const double half_w = 0.5 * 14000 * pixel_mm, half_h = 0.5 * 12000 * pixel_mm;
  double worst_px = 0.0;
  for (int i = 0; i <= 40; ++i) {
    for (int k = 0; k <= 40; ++k) {
      const Eigen::Vector2d measured(-half_w + 2 * half_w * i / 40.0,
                                     -half_h + 2 * half_h * k / 40.0);
      Eigen::Vector2d ideal, back;
      Model::IdealFromMeasured(p.data(), measured.data(), ideal.data());
      ASSERT_TRUE(Model::MeasuredFromIdeal(p.data(), ideal, &back));
      worst_px = std::max(worst_px, (back - measured).norm() / pixel_mm);
    }
  }
  EXPECT_LT(worst_px, 1e-6);
}

TEST(BrownFraser10, AutodiffDerivativesMatchNumericDifferentiation) {
  using Jet = ceres::Jet<double, 12>;
  const InteriorParams p = TypicalInterior();
  const double xy[2] = {55.0, -41.0};
  Jet pj[10], xj[2], out[2];
  for (int i = 0; i < 10; ++i) pj[i] = Jet(p[i], i);
  xj[0] = Jet(xy[0], 10);
  xj[1] = Jet(xy[1], 11);
  Model::IdealFromMeasured(pj, xj, out);
  for (int v = 0; v < 12; ++v) {
    double pp[10], pm[10], xp[2] = {xy[0], xy[1]}, xm[2] = {xy[0], xy[1]};
    std::copy(p.begin(), p.end(), pp);
    std::copy(p.begin(), p.end(), pm);
    // Step with an effect of ~1e-3 mm on the output: small against curvature, large against
    // round-off (the terms span 20 orders of magnitude, K3 in mm^-6).
    const double slope = std::max(std::abs(out[0].v[v]), std::abs(out[1].v[v]));
    const double h = 1e-3 / std::max(slope, 1e-30);
    if (v < 10) {
      pp[v] += h;
      pm[v] -= h;
    } else {
      xp[v - 10] += h;
      xm[v - 10] -= h;
    }
    double a[2], b[2];
    Model::IdealFromMeasured(pp, xp, a);
    Model::IdealFromMeasured(pm, xm, b);
    for (int k = 0; k < 2; ++k) {
      const double numeric = (a[k] - b[k]) / (2 * h);
      EXPECT_NEAR(out[k].v[v], numeric, 1e-6 * std::max(1.0, std::abs(numeric)))
          << "variable " << v;
    }
  }
}

TEST(Camera, NadirProjectionOfAKnownPointIsMinusCUOverW) {
  Camera camera;
  camera.pixel_size_mm = 0.01;
  camera.width_px = 1001;
  camera.height_px = 801;
  camera.interior[Model::kC] = 100.0;
  // Camera 1000 m above the origin, looking down; a point 50 m east, 20 m north on the ground:
  // U = 50, V = 20, W = -1000 -> x = 5 mm, y = 2 mm -> col 500 + 500, row 400 - 200.
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera.ProjectToPixel({0, 0, 0}, {0, 0, 1000}, {50, 20, 0}, &pixel));
  EXPECT_NEAR(pixel.x(), 1000.0, 1e-9);
  EXPECT_NEAR(pixel.y(), 200.0, 1e-9);
  EXPECT_FALSE(camera.ProjectToPixel({0, 0, 0}, {0, 0, 1000}, {50, 20, 2000}, &pixel))
      << "a point above the camera is behind it";
}

TEST(Camera, PixelAndPhotoFramesFollowConventions) {
  Camera camera;
  camera.pixel_size_mm = 0.009;
  camera.width_px = 14000;
  camera.height_px = 12000;
  const Eigen::Vector2d centre = camera.PhotoFromPixel({6999.5, 5999.5});
  EXPECT_NEAR(centre.norm(), 0.0, 1e-12);
  const Eigen::Vector2d top_left = camera.PhotoFromPixel({0, 0});
  EXPECT_NEAR(top_left.x(), -6999.5 * 0.009, 1e-12);
  EXPECT_NEAR(top_left.y(), 5999.5 * 0.009, 1e-12);  // y up
  EXPECT_NEAR((camera.PixelFromPhoto(top_left) - Eigen::Vector2d(0, 0)).norm(), 0.0, 1e-9);
}

}  // namespace
}  // namespace aerocal::calib
