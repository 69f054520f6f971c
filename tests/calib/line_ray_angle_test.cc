// The line camera's angular residual (calib/residuals/line_ray_angle.h, used by
// LineCollinearityResidual; issue 28): invariant under a rotation of the detector's ray, its line
// direction and the ray to the point together, and under a scale of c with the table; equal to the
// whitened focal-plane residual to first order at the nominal ray, and to that residual divided by
// c times the nominal c at the principal point.
#include "calib/residuals/line_ray_angle.h"

#include "calib/camera/rotation.h"
#include "calib/residuals/line_collinearity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace aerocal::calib {
namespace {

// Invariance is exact in the formula; what remains is rounding of O(1e-3) rad angles.
constexpr double kInvariance = 1e-12;

Eigen::Vector2d Angle(const Eigen::Vector3d& d,
                      const Eigen::Vector3d& l,
                      const Eigen::Vector3d& g) {
  Eigen::Vector2d a;
  EXPECT_TRUE(LineRayAngle(d.data(), l.data(), g.data(), a.data()));
  return a;
}

// A tilted detector (20 deg off nadir, a curved table: the line direction is not along x) and a
// ground point a few pixels off its ray.
struct Detector {
  Eigen::Vector3d d{9.83, 0.31, -27.0};                // (x, y, -c), mm
  Eigen::Vector3d l{0.0113, 0.0004, 0.0};              // dd/di, mm / detector
  Eigen::Vector3d g{9.83 + 0.03, 0.31 - 0.02, -27.0};  // 3 px and 2 px off in the focal plane
};

TEST(LineRayAngle, UnchangedWhenRayLineDirectionAndPointRotateTogether) {
  const Detector s;
  const Eigen::Vector2d a = Angle(s.d, s.l, s.g);
  EXPECT_GT(a.norm(), 1e-3);  // not a trivially zero residual
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> angle(-0.3, 0.3);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Matrix3d r = RotationFromOpk(Eigen::Vector3d(angle(rng), angle(rng), angle(rng)));
    const Eigen::Vector2d turned = Angle(r * s.d, r * s.l, r * s.g);
    EXPECT_NEAR(turned.x(), a.x(), kInvariance);
    EXPECT_NEAR(turned.y(), a.y(), kInvariance);
  }
  // Not so in a frame of the camera's fixed axes: the focal-plane difference of the turned rays
  // (projected at z = -c) changes by about 2 b x e / c, here far above the invariance.
  const Eigen::Matrix3d r = RotationFromOpk(Eigen::Vector3d(0.0, 0.01, 0.0));
  auto focal = [](const Eigen::Vector3d& d, const Eigen::Vector3d& g) -> Eigen::Vector2d {
    return (d.head<2>() * (-27.0 / d.z()) - g.head<2>() * (-27.0 / g.z()));
  };
  EXPECT_GT((focal(r * s.d, r * s.g) - focal(s.d, s.g)).norm(), 1e-6);
}

TEST(LineRayAngle, UnchangedWhenCAndTheTableScaleTogether) {
  const Detector s;
  const Eigen::Vector2d a = Angle(s.d, s.l, s.g);
  for (const double scale : {0.5, 0.97, 1.03, 4.0}) {
    const Eigen::Vector2d scaled = Angle(scale * s.d, scale * s.l, s.g);
    EXPECT_NEAR(scaled.x(), a.x(), kInvariance) << scale;
    EXPECT_NEAR(scaled.y(), a.y(), kInvariance) << scale;
    // Nor does the length of the ray to the point matter (the distance to the ground).
    const Eigen::Vector2d far = Angle(s.d, s.l, scale * s.g);
    EXPECT_NEAR(far.x(), a.x(), kInvariance) << scale;
    EXPECT_NEAR(far.y(), a.y(), kInvariance) << scale;
  }
}

TEST(LineRayAngle, UndefinedBehindTheRayOrAlongIt) {
  const Detector s;
  Eigen::Vector2d a;
  const Eigen::Vector3d behind = -s.g;
  EXPECT_FALSE(LineRayAngle(s.d.data(), s.l.data(), behind.data(), a.data()));
  const Eigen::Vector3d along = 0.001 * s.d;
  EXPECT_FALSE(LineRayAngle(s.d.data(), along.data(), s.g.data(), a.data()));
}

// The whole residual on a level camera at 1000 m (no rotation, no corrections): the ground point on
// the detector's ray, moved by `shift` m, against the focal-plane residual by hand.
struct Scene {
  double nodes[4][6] = {};
  double detector[2 * kLineMaxTerms] = {};
  double mount[3] = {}, lever[3] = {}, time_offset = 0;
};
// The functor at the blocks of a level camera (no corrections), with these detector polynomials,
// mount, c and point.
Eigen::Vector2d EvaluateCost(const ceres::CostFunction& cost,
                             const double* detector,
                             const Eigen::Vector3d& mount_opk,
                             double c,
                             const Eigen::Vector3d& point) {
  Scene s;
  std::copy(detector, detector + 2 * kLineMaxTerms, s.detector);
  std::copy(mount_opk.data(), mount_opk.data() + 3, s.mount);
  const double* blocks[] = {s.nodes[0],
                            s.nodes[1],
                            s.nodes[2],
                            s.nodes[3],
                            s.detector,
                            &c,
                            s.mount,
                            s.lever,
                            &s.time_offset,
                            point.data()};
  Eigen::Vector2d r;
  EXPECT_TRUE(cost.Evaluate(blocks, r.data(), nullptr));
  return r;
}
Eigen::Vector2d Evaluate(const LineDetectorGeometry& geometry,
                         double c,
                         const Eigen::Vector2d& sigma_mm,
                         const Eigen::Vector3d& point,
                         Eigen::Vector2d* focal_plane) {
  const Eigen::Vector3d center(0, 0, 1000);
  auto cost = LineCollinearityResidual::Create(
      geometry, CubicBSplineWeights(0, 10), Eigen::Vector3d::Zero(), center, sigma_mm);
  const double zero[2 * kLineMaxTerms] = {};
  const Eigen::Vector2d r = EvaluateCost(*cost, zero, Eigen::Vector3d::Zero(), c, point);
  const Eigen::Vector3d g = point - center;
  const Eigen::Vector2d projected = -c * g.head<2>() / g.z();
  *focal_plane = (geometry.xy_mm - projected).cwiseQuotient(sigma_mm);
  return r;
}
Eigen::Vector3d OnTheRay(const LineDetectorGeometry& geometry, double c) {
  return Eigen::Vector3d(0, 0, 1000) +
         Eigen::Vector3d(geometry.xy_mm.x(), geometry.xy_mm.y(), -c) * (1000.0 / c);
}

// The whole functor: a finite rotation Q of the camera frame (the mount M -> M Q^T) with the table
// following it exactly (the detector's ray and line direction turned by Q and projected back onto
// z = -c, written as the polynomial's value and slope at u = 0) leaves the residual unchanged,
// with the weight still that of the start table.
TEST(LineCollinearityResidual, UnchangedWhenTheMountRotatesAndTheTableFollows) {
  LineDetectorGeometry geometry;
  geometry.xy_mm = Eigen::Vector2d(1.2, 0.05);
  geometry.slope_mm = Eigen::Vector2d(0.01, 0.0002);
  geometry.du_di = 2.0 / 119.0;
  geometry.nominal_c_mm = 3.24;
  geometry.nominal_range_m = 1000.0;  // the along residual follows the range (invariant too)
  const double c = 3.24;
  const Eigen::Vector3d center(0, 0, 1000), mount_opk(0.001, -0.002, 0.003);
  auto cost = LineCollinearityResidual::Create(geometry,
                                               CubicBSplineWeights(0, 10),
                                               Eigen::Vector3d::Zero(),
                                               center,
                                               Eigen::Vector2d(0.0025, 0.0025));
  const Eigen::Vector3d d(geometry.xy_mm.x(), geometry.xy_mm.y(), -c);
  const Eigen::Vector3d l(geometry.slope_mm.x(), geometry.slope_mm.y(), 0.0);
  // A point 2 px off the detector's ray.
  const Eigen::Vector3d point =
      center + RotationFromOpk(mount_opk) * (d + Eigen::Vector3d(0.02, -0.01, 0)) * (1000.0 / c);
  const double zero[2 * kLineMaxTerms] = {};
  const Eigen::Vector2d r0 = EvaluateCost(*cost, zero, mount_opk, c, point);
  EXPECT_GT(r0.norm(), 1.0);
  for (const Eigen::Vector3d& angles :
       {Eigen::Vector3d(0.01, -0.02, 0.015), Eigen::Vector3d(-0.1, 0.05, 0.2)}) {
    const Eigen::Matrix3d q = RotationFromOpk(angles);
    const Eigen::Vector3d qd = q * d, ql = q * l;
    // Projected onto z = -c: x' = -c (Q d)_xy / (Q d)_z, and its derivative along the line.
    const Eigen::Vector2d xy = -c * qd.head<2>() / qd.z();
    const Eigen::Vector2d slope =
        -c * (ql.head<2>() * qd.z() - qd.head<2>() * ql.z()) / (qd.z() * qd.z());
    double detector[2 * kLineMaxTerms] = {};
    detector[0] = xy.x() - d.x();
    detector[1] = (slope.x() - l.x()) / geometry.du_di;
    detector[kLineMaxTerms] = xy.y() - d.y();
    detector[kLineMaxTerms + 1] = (slope.y() - l.y()) / geometry.du_di;
    const Eigen::Matrix3d mount = RotationFromOpk(mount_opk) * q.transpose();
    const Eigen::Vector2d r = EvaluateCost(*cost, detector, OpkFromRotation(mount), c, point);
    EXPECT_NEAR(r.x(), r0.x(), 1e-9 * r0.norm()) << angles.transpose();
    EXPECT_NEAR(r.y(), r0.y(), 1e-9 * r0.norm()) << angles.transpose();
  }
}

TEST(LineCollinearityResidual, EqualsTheFocalPlaneResidualToFirstOrderAtTheNominalRay) {
  LineDetectorGeometry geometry;  // the tilted detector above, c = 27 mm, 10 um pitch
  geometry.xy_mm = Eigen::Vector2d(9.83, 0.31);
  geometry.slope_mm = Eigen::Vector2d(0.0113, 0.0004);
  geometry.nominal_c_mm = 27.0;
  const Eigen::Vector2d sigma_mm(0.0113 * 0.25, 0.010 * 0.25);  // 0.25 px
  const Eigen::Vector3d on_ray = OnTheRay(geometry, 27.0);
  double previous = 0;
  for (const double size : {0.4, 0.2, 0.1}) {  // m on the ground at 1000 m: 1.1 .. 0.27 px
    const Eigen::Vector3d shift = size * Eigen::Vector3d(1.0, -0.7, 0.2);
    Eigen::Vector2d fp;
    const Eigen::Vector2d r = Evaluate(geometry, 27.0, sigma_mm, on_ray + shift, &fp);
    const double difference = (r - fp).norm();
    std::printf("shift %.2f m: focal plane %.6f %.6f, angular %.6f %.6f, difference %.2e\n",
                size,
                fp.x(),
                fp.y(),
                r.x(),
                r.y(),
                difference);
    EXPECT_GT(fp.norm(), 1.0);
    // First order: the difference is second order in the residual (relative ~ |delta| / |d|).
    EXPECT_LT(difference, 1e-3 * fp.norm());
    if (previous > 0) {
      EXPECT_NEAR(difference / previous, 0.25, 0.02);  // halving the shift quarters it
    }
    previous = difference;
  }
}

TEST(LineCollinearityResidual, IsInDetectorsOfTheCurrentTableAtThePrincipalPoint) {
  LineDetectorGeometry geometry;  // the detector at the principal point
  geometry.slope_mm = Eigen::Vector2d(0.01, 0.0);
  geometry.nominal_c_mm = 27.0;
  const Eigen::Vector2d sigma_mm(0.0025, 0.0025);
  for (const double c : {27.0, 25.0, 30.0}) {
    const Eigen::Vector3d point = OnTheRay(geometry, c) + Eigen::Vector3d(0.05, -0.03, 0.0);
    Eigen::Vector2d fp;
    const Eigen::Vector2d r = Evaluate(geometry, c, sigma_mm, point, &fp);
    // Across: in detector indices of the CURRENT table (the angle per detector follows c): the
    // focal-plane residual itself. Along: in lines, an angle (no range given: not rescaled), so
    // the focal-plane residual over c times the nominal c.
    const Eigen::Vector2d expected(fp.x(), fp.y() * (27.0 / c));
    // Exact for a point on the level plane (W = -H): tan = shift / H at the principal point.
    EXPECT_NEAR(r.x(), expected.x(), 1e-9 * expected.norm()) << c;
    EXPECT_NEAR(r.y(), expected.y(), 1e-9 * expected.norm()) << c;
  }
}

// A raised camera (dz) with the table shrunk by k = H / (H + dz) sees a ground point through the
// same ray; a point off the ray by (dx, dy) m on the ground is then off by the same number of
// detectors and lines, i.e. the same measurement residual (exactly, for a linear table on flat
// ground). The angles shrink by k: with the weights fixed at the start's angles the residual shrank
// by k too (the free lever arm's bias; line_collinearity.h); rescaled to the current angle per
// detector and per line it stays (measured: to 3.3e-5 of the residual at x = 1.2 mm, below 1e-6 at
// the principal point, against 1 - k = 4.8 % before).
TEST(LineCollinearityResidual, UnchangedWhenTheCameraRisesAndTheTableShrinks) {
  const double c = 3.24, height = 1000.0, dz = 50.0, k = height / (height + dz);
  const Eigen::Vector3d center(0, 0, 1000);
  for (const double x : {0.0, 1.2}) {
    LineDetectorGeometry geometry;
    geometry.xy_mm = Eigen::Vector2d(x, 0.0);
    geometry.slope_mm = Eigen::Vector2d(0.01, 0.0);
    geometry.du_di = 2.0 / 119.0;
    geometry.nominal_c_mm = c;
    const Eigen::Vector3d ground(x / c * height + 1.5, -1.0, 0.0);  // 1.9 and 1.3 sigma off
    const Eigen::Vector3d start = center + ground - Eigen::Vector3d(0, 0, height);
    geometry.nominal_range_m = (start - center).norm();
    auto cost = LineCollinearityResidual::Create(geometry,
                                                 CubicBSplineWeights(0, 10),
                                                 Eigen::Vector3d::Zero(),
                                                 center,
                                                 Eigen::Vector2d(0.0025, 0.0025));
    const double zero[2 * kLineMaxTerms] = {};
    const Eigen::Vector2d r0 = EvaluateCost(*cost, zero, Eigen::Vector3d::Zero(), c, start);
    // Raising the camera by dz = the point dz deeper below it.
    double shrunk[2 * kLineMaxTerms] = {};
    shrunk[0] = (k - 1.0) * x;
    shrunk[1] = (k - 1.0) * geometry.slope_mm.x() / geometry.du_di;
    const Eigen::Vector3d raised = start - Eigen::Vector3d(0, 0, dz);
    const Eigen::Vector2d r = EvaluateCost(*cost, shrunk, Eigen::Vector3d::Zero(), c, raised);
    std::printf("x %.1f mm: start %.6f %.6f, raised %.6f %.6f (k %.4f)\n",
                x,
                r0.x(),
                r0.y(),
                r.x(),
                r.y(),
                k);
    EXPECT_GT(r0.norm(), 1.0);
    EXPECT_NEAR(r.x(), r0.x(), 1e-4 * r0.norm());
    EXPECT_NEAR(r.y(), r0.y(), 1e-4 * r0.norm());
  }
}

}  // namespace
}  // namespace aerocal::calib
