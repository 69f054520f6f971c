// The certificate's distortion samples (distortion_figure.h) in any camera model: the 10-parameter
// model gives its own dx, dy (CONVENTIONS.md) and the certified dr, dt terms; an OpenCV camera with
// k1 gives the radial correction of its forward model solved independently here (Newton on
// rho_n (1 + k1 rho_n^2) = rho_d), with no tangential part.
#include "triangulation/calibration/distortion_figure.h"

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/models/opencv.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;
using OpenCv = calib::OpenCvModel;

calib::PixelFrame Format() {
  calib::PixelFrame f;
  f.pixel_size_mm = 0.006;
  f.width_px = 4000;
  f.height_px = 3000;
  return f;
}

TEST(DistortionFigure, TenParameterGridIsTheModelsCorrection) {
  calib::ModelCamera camera;
  camera.model = Model::kId;
  camera.frame = Format();
  // c, x0, y0, K1, K2, K3, P1, P2, B1, B2 (mm units of the model)
  camera.params = {24.0, 0.12, -0.08, -2e-4, 3e-7, -1e-10, 2e-6, -3e-6, 1e-4, -5e-5};
  const auto& p = camera.params;
  const DistortionFigure figure = DistortionOverFormat(camera, 20, 5, 4);
  ASSERT_EQ(figure.grid.size(), 20u);
  EXPECT_EQ(figure.profile_kind, "10-parameter terms");
  for (const auto& g : figure.grid) {
    const double xb = g[0] - p[Model::kX0], yb = g[1] - p[Model::kY0], r2 = xb * xb + yb * yb;
    const double k = p[Model::kK1] * r2 + p[Model::kK2] * r2 * r2 + p[Model::kK3] * r2 * r2 * r2;
    const double dx = xb * k + p[Model::kP1] * (r2 + 2 * xb * xb) + 2 * p[Model::kP2] * xb * yb +
                      p[Model::kB1] * xb + p[Model::kB2] * yb;
    const double dy = yb * k + 2 * p[Model::kP1] * xb * yb + p[Model::kP2] * (r2 + 2 * yb * yb);
    EXPECT_NEAR(g[2], 1e3 * dx, 1e-6) << g[0] << " " << g[1];
    EXPECT_NEAR(g[3], 1e3 * dy, 1e-6) << g[0] << " " << g[1];
  }
  calib::InteriorParams interior{};
  for (int k = 0; k < Model::kNumParams; ++k) interior[k] = p[k];
  ASSERT_EQ(figure.profile.size(), 21u);
  const double r_max = std::hypot(12.0, 9.0);
  EXPECT_NEAR(figure.profile.back()[0], r_max, 1e-12);
  for (const auto& s : figure.profile) {
    EXPECT_DOUBLE_EQ(s[1], RadialDistortionUm(interior, s[0]));
    EXPECT_DOUBLE_EQ(s[2], DecentringDistortionUm(interior, s[0]));
  }
  EXPECT_NEAR(
      RadialDistortionUm(interior, 10.0), 1e4 * (-2e-4 * 100 + 3e-7 * 1e4 - 1e-10 * 1e6), 1e-9);
}

TEST(DistortionFigure, OpenCvRadialModelGivesItsForwardDistortionInverted) {
  calib::ModelCamera camera;
  camera.model = OpenCv::kId;
  camera.frame = Format();
  const double f = 4000, k1 = -0.12;
  camera.params.assign(OpenCv::kNumParams, 0.0);
  camera.params[OpenCv::kFx] = camera.params[OpenCv::kFy] = f;
  camera.params[OpenCv::kCx] = 2010.0;
  camera.params[OpenCv::kCy] = 1490.0;
  camera.params[OpenCv::kK1] = k1;
  const DistortionFigure figure = DistortionOverFormat(camera, 25);
  EXPECT_EQ(figure.profile_kind, "mean over directions");
  ASSERT_EQ(figure.profile.size(), 26u);
  const double c = f * camera.frame.pixel_size_mm;
  for (const auto& s : figure.profile) {
    const double rho_d = s[0] / c;
    double rho = rho_d;
    for (int i = 0; i < 50; ++i)
      rho -= (rho * (1 + k1 * rho * rho) - rho_d) / (1 + 3 * k1 * rho * rho);
    EXPECT_NEAR(s[1], 1e3 * c * (rho - rho_d), 1e-6) << s[0];
    EXPECT_NEAR(s[2], 0.0, 1e-6) << s[0];
  }
  EXPECT_GT(figure.profile.back()[1], 100.0);  // barrel: a visible outward correction (um)
  EXPECT_EQ(figure.grid.size(), 99u);
}

}  // namespace
}  // namespace aerocal::triangulation
