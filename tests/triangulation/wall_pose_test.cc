// A frame camera at phi = 90 deg: a vertical wall photographed horizontally. Omega-phi-kappa are
// singular there (gimbal lock: only omega + kappa is defined), so an adjustment with angle blocks
// cannot move the pose; with the rotation-increment manifold (calib/problem/rotation_manifold.h)
// it converges like a nadir block. Oracles: noise-free, the pose and the points come back exactly
// (1e-9 rad, 1e-6 m); with 0.1 px noise sigma0 / injected sigma is within 1 +- 3/sqrt(2r) and
// every centre and phi lie within 3 reported sigmas of the truth.
#include "calib/camera/rotation.h"
#include "triangulation/adjustment/block_adjustment.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace aerocal::triangulation {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Wall {
  Project project;
  std::vector<Eigen::Vector3d> true_opk, true_center;
};

// Wall in the plane X = 0 (Y along it, Z up, +-1 m relief in X), five stations at X = 25 m
// looking along -X: R = Rx(omega) Ry(90 deg) (image x down the wall, y along +Y for omega = 0),
// two of them rolled about the viewing axis by omega = +-0.3 rad, i.e. exactly in gimbal lock.
Wall MakeWall(double noise_px, unsigned seed) {
  Wall w;
  calib::Camera camera;
  camera.pixel_size_mm = 0.005;
  camera.width_px = 6000;
  camera.height_px = 4000;
  camera.interior = {35.0, 0.01, -0.02, 0, 0, 0, 0, 0, 0, 0};
  w.project.path = "wall";
  w.project.cameras["cam"] = camera;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> along(-18.0, 18.0), up(0.0, 14.0), relief(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double ys[5] = {-9.0, -4.5, 0.0, 4.5, 9.0};
  const double omegas[5] = {0.0, 0.3, 0.0, -0.3, 0.0};
  for (int k = 0; k < 5; ++k) {
    w.true_opk.emplace_back(omegas[k], 90.0 * kDeg, 0.0);
    w.true_center.emplace_back(25.0, ys[k], 7.0 + 0.3 * k);
    Exposure e;
    e.image = "s" + std::to_string(k);
    e.camera = "cam";
    // Start 1-2 deg and 0.4 m off (phi below 90 deg: the start is not in gimbal lock).
    e.opk_rad = w.true_opk.back() + Eigen::Vector3d(0.02, -0.025, 0.015);
    e.center_m = w.true_center.back() + Eigen::Vector3d(0.3, -0.2, 0.25);
    w.project.exposures.push_back(e);
  }
  for (int p = 0; p < 120; ++p) {
    GroundPoint g;
    g.id = "p" + std::to_string(p);
    const Eigen::Vector3d xyz(relief(rng), along(rng), up(rng));
    g.role = p < 10 ? PointRole::kControl : PointRole::kTie;
    g.sigma_m = Eigen::Vector3d::Constant(0.002);
    if (g.role == PointRole::kControl) g.xyz_m = xyz;
    for (int k = 0; k < 5; ++k) {
      Eigen::Vector2d px;
      if (!camera.ProjectToPixel(w.true_opk[k], w.true_center[k], xyz, &px)) continue;
      if (px.x() < 0 || px.y() < 0 || px.x() > camera.width_px || px.y() > camera.height_px)
        continue;
      ImageObservation o;
      o.image = "s" + std::to_string(k);
      o.point = g.id;
      o.pixel = px + noise_px * Eigen::Vector2d(noise(rng), noise(rng));
      o.sigma_px = noise_px > 0 ? noise_px : 0.1;
      w.project.observations.push_back(o);
    }
    w.project.points.push_back(g);
  }
  return w;
}

// Angle of the rotation between two poses (rad), from |R_a - R_b|_F = 2 sqrt(2) sin(angle / 2):
// exact near zero (an acos of the trace loses half the digits, 1.5e-8 rad).
double AngleBetween(const Eigen::Vector3d& opk_a, const Eigen::Vector3d& opk_b) {
  const double f = (calib::RotationFromOpk(opk_a) - calib::RotationFromOpk(opk_b)).norm();
  return 2.0 * std::asin(std::min(1.0, f / (2.0 * std::sqrt(2.0))));
}

TEST(WallAtPhi90, NoiseFreePoseComesBackExactly) {
  const Wall w = MakeWall(0.0, 1);
  AdjustOptions options;
  options.data_snooping = false;
  const AdjustmentResult r = Adjust(w.project, options);
  ASSERT_TRUE(r.solve.converged) << r.solve.message;
  ASSERT_EQ(r.exposures.size(), 5u);
  for (size_t k = 0; k < r.exposures.size(); ++k) {
    SCOPED_TRACE(r.exposures[k].image);
    // 1e-9 rad and 1e-6 m: the solver's tolerances (1e-12 relative) on a 25 m geometry.
    EXPECT_LT(AngleBetween(r.exposures[k].opk_rad, w.true_opk[k]), 1e-9);
    EXPECT_LT((r.exposures[k].center_m - w.true_center[k]).norm(), 1e-6);
    EXPECT_NEAR(r.exposures[k].opk_rad.y(), 90.0 * kDeg, 1e-6);  // phi itself (rad)
  }
  EXPECT_LT(r.solve.sigma0, 1e-4);  // no noise: only rounding is left
}

TEST(WallAtPhi90, NoisyBlockIsConsistentWithItsSigmas) {
  const Wall w = MakeWall(0.1, 2);
  AdjustOptions options;
  const AdjustmentResult r = Adjust(w.project, options);
  ASSERT_TRUE(r.solve.converged) << r.solve.message;
  ASSERT_GT(r.solve.redundancy, 100);
  const double band = 3.0 / std::sqrt(2.0 * r.solve.redundancy);
  EXPECT_NEAR(r.solve.sigma0, 1.0, band);
  for (size_t k = 0; k < r.exposures.size(); ++k) {
    const ExposureEstimate& e = r.exposures[k];
    SCOPED_TRACE(e.image);
    ASSERT_TRUE(e.center_sigma_m.has_value() && e.opk_sigma_rad.has_value());
    for (int i = 0; i < 3; ++i)
      EXPECT_LE(std::abs(e.center_m(i) - w.true_center[k](i)), 3.0 * (*e.center_sigma_m)(i));
    // phi is defined at the singularity (its Jacobian has a finite limit); omega and kappa are
    // not separable there, so only the whole rotation is compared: within 3 sigma of phi, which
    // is the angular precision of the viewing direction (the stations are alike).
    const double sigma_phi = e.opk_sigma_rad->y();
    ASSERT_TRUE(std::isfinite(sigma_phi) && sigma_phi > 0);
    EXPECT_LE(std::abs(e.opk_rad.y() - w.true_opk[k].y()), 3.0 * sigma_phi);
    EXPECT_LT(AngleBetween(e.opk_rad, w.true_opk[k]), 10.0 * sigma_phi);
  }
}

}  // namespace
}  // namespace aerocal::triangulation
