// The line camera (calib/camera/line_camera.h), its file (line_camera_io.h) and its residual
// (calib/residuals/line_collinearity.h): design positions by hand, the combination of tilted
// cameras, table / polynomial calibration, file round trip and FILE:LINE errors, the B-spline
// weights, a perfect observation's zero residual and the autodiff Jacobian against numeric
// differentiation (ceres::GradientChecker).
#include "calib/camera/line_camera.h"

#include "calib/camera/line_camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/residuals/line_collinearity.h"
#include "tests/support/test_support.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace aerocal::calib {
namespace {

constexpr double kDeg = M_PI / 180.0;

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

LineCamera ThreeTilted() {
  std::vector<LineSubcamera> subs(3);
  const char* ids[] = {"L", "N", "R"};
  const double tilt[] = {-20, 0, 20};
  for (int k = 0; k < 3; ++k) {
    subs[k].id = ids[k];
    subs[k].last = 99;  // 100 detectors each
    subs[k].c_mm = 8.5;
    subs[k].pitch_mm = 0.01;
    subs[k].mount_rad = Eigen::Vector3d(0, tilt[k] * kDeg, 0);
  }
  return CombineLineCameras("three", subs, 8.5, 0.01);
}

TEST(LineCamera, StraightLineIsTheConventionsFormula) {
  LineCamera cam;
  cam.detectors = 11;
  cam.pitch_mm = 0.01;
  cam.c_mm = 50;
  EXPECT_NEAR(cam.DesignPosition(0).x(), -0.05, 1e-15);
  EXPECT_NEAR(cam.DesignPosition(10).x(), 0.05, 1e-15);
  EXPECT_EQ(cam.DesignPosition(3).y(), 0.0);
  cam.dx_mm.assign(11, 0.0);
  cam.dy_mm.assign(11, 0.0);
  cam.dx_mm[4] = 0.002;
  cam.dy_mm[5] = -0.004;
  // Table: exact at detectors, linear in between.
  EXPECT_NEAR(cam.DetectorPosition(4).x(), -0.01 + 0.002, 1e-15);
  EXPECT_NEAR(cam.DetectorPosition(4.5).y(), -0.002, 1e-15);
  EXPECT_NEAR(cam.DetectorPosition(4.5).x(), -0.005 + 0.001, 1e-15);
}

TEST(LineCamera, CombinedTiltedCamerasProjectOntoTheVirtualPlane) {
  const LineCamera cam = ThreeTilted();
  EXPECT_EQ(cam.detectors, 300);
  EXPECT_EQ(cam.subcameras[1].first, 100);
  EXPECT_EQ(cam.subcameras[2].last, 299);
  EXPECT_EQ(cam.SubcameraOf(150), 1);
  EXPECT_EQ(cam.SubcameraOf(299.4), 2);
  EXPECT_EQ(cam.SubcameraOf(300), -1);
  // The centre of the right camera looks 20 deg off nadir: x = c tan(20 deg) in the virtual plane
  // (the ray [0, 0, -c] turned by Ry(20 deg) has x = -c sin, z = -c cos: x_v = -c tan... sign by
  // the rotation: Ry(+20) takes -z towards -x).
  const double mid = 200 + 49.5;
  EXPECT_NEAR(cam.DesignPosition(mid).x(), -8.5 * std::tan(20 * kDeg), 1e-12);
  EXPECT_NEAR(cam.DesignPosition(mid).y(), 0.0, 1e-15);
  // A detector j of the left camera: angle atan(x_j / c) + tilt.
  const double xj = (10 - 49.5) * 0.01;
  EXPECT_NEAR(
      cam.DesignPosition(10).x(), -8.5 * std::tan(std::atan(-xj / 8.5) - 20 * kDeg) * 1.0, 1e-12);
  // The nadir camera is the straight line of its own detectors.
  EXPECT_NEAR(cam.DesignPosition(100).x(), -49.5 * 0.01, 1e-12);
}

TEST(LineCamera, PolynomialCalibrationInTheNormalisedIndex) {
  LineCamera cam = ThreeTilted();
  cam.calibration = {
      {0, 99, {0.001, 0.002}, {}}, {100, 199, {}, {0.0, 0.0, 0.003}}, {200, 299, {0.004}, {0.005}}};
  cam.Validate("x");
  EXPECT_NEAR(cam.Correction(0).x(), 0.001 - 0.002, 1e-15);
  EXPECT_NEAR(cam.Correction(99).x(), 0.003, 1e-15);
  EXPECT_NEAR(cam.Correction(100).y(), 0.003, 1e-15);  // u = -1, u^2 = 1
  EXPECT_NEAR(cam.Correction(149.5).y(), 0.0, 1e-15);
  EXPECT_NEAR(cam.Correction(250).y(), 0.005, 1e-15);
  // Jumps at the seams are allowed: detector 99 and 100 differ by the polynomials.
  EXPECT_NEAR(cam.Correction(100).x(), 0.0, 1e-15);
}

TEST(LineCameraFile, RoundTripIsExact) {
  testing::TempDir dir;
  LineCamera cam = ThreeTilted();
  cam.mount_rad = Eigen::Vector3d(0.1, -0.2, 0.3) * kDeg;
  cam.lever_arm_m = {0.1, 0.2, -0.3};
  cam.calibration = {{0, 99, {1e-3, 2e-4, 3.3e-5}, {-1e-4}},
                     {100, 199, {0.0}, {0.0}},
                     {200, 299, {4e-3}, {5e-3, 1e-7}}};
  WriteLineCamera(dir.File("line.yaml"), cam);
  const LineCamera back = ReadLineCamera(dir.File("line.yaml"));
  EXPECT_EQ(back.detectors, 300);
  ASSERT_EQ(back.subcameras.size(), 3u);
  EXPECT_EQ(back.subcameras[2].id, "R");
  for (double i : {0.0, 57.3, 100.0, 199.0, 250.5, 299.0}) {
    EXPECT_NEAR((back.DetectorPosition(i) - cam.DetectorPosition(i)).norm(), 0.0, 1e-15) << i;
  }
  EXPECT_NEAR((back.mount_rad - cam.mount_rad).norm(), 0.0, 1e-16);
  // A table camera too.
  LineCamera table;
  table.name = "t";
  table.detectors = 4;
  table.pitch_mm = 0.007;
  table.c_mm = 35;
  table.dx_mm = {0.1, 0.2, 0.3, 0.4};
  table.dy_mm = {-0.1, 0, 0, 1e-9};
  WriteLineCamera(dir.File("t.yaml"), table);
  const LineCamera t = ReadLineCamera(dir.File("t.yaml"));
  EXPECT_EQ(t.dx_mm, table.dx_mm);
  EXPECT_EQ(t.dy_mm, table.dy_mm);
}

TEST(LineCameraFile, BadFilesNameTheLine) {
  testing::TempDir dir;
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"line:\n  detectors: 3\n  pitch_mm: 0.01\n  c: 8\n  dx_mm: [0, 0]\n  dy_mm: [0, 0, 0]\n",
       ":5: line.dx_mm must hold line.detectors (3) values (got 2)"},
      {"line:\n  detectors: 3\n  pitch_mm: -0.01\n  c: 8\n", ":3: line.pitch_mm must be within"},
      {"line:\n  detectors: 0\n  pitch_mm: 0.01\n  c: 8\n", ":2: line.detectors must be within 1"},
      {"line:\n  detectors: 3\n  pitch_mm: 0.01\n  c: 8\n  colour: red\n", ":5:"},
      {"line:\n  detectors: 4\n  pitch_mm: 0.01\n  c: 8\n  calibration:\n    - {first: 0, last: "
       "1}\n"
       "    - {first: 3, last: 3}\n",
       ":7: calibration ranges must be contiguous"},
      {"line:\n  detectors: 4\n  pitch_mm: 0.01\n  c: 8\n  subcameras:\n"
       "    - {id: A, detectors: 2, c: 8, pitch_mm: 0.01}\n    - {id: B, detectors: 3, c: 8, "
       "pitch_mm: 0.01}\n",
       ":7: sub-camera B: detectors must be within 1 .. 2"},
      {"line:\n  detectors: 4\n  pitch_mm: 0.01\n  c: 8\n  subcameras:\n"
       "    - {id: A, detectors: 2, c: 8, pitch_mm: 0.01}\n    - {id: B, detectors: 2, c: 8, "
       "pitch_mm: 0.01}\n"
       "  calibration:\n    - {first: 0, last: 2, dx: [1]}\n    - {first: 3, last: 3}\n",
       ":9: calibration range [0, 2] spans a sub-camera seam"},
      {"line:\n  detectors: 4\n  pitch_mm: 0.01\n  c: 8\n  calibration:\n"
       "    - {first: 0, last: 3, dx: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]}\n",
       ":6: calibration dx holds at most 10 values"},
      {"line:\n  detectors: 2\n  pitch_mm: 0.01\n  c: 8\n  subcameras:\n"
       "    - {id: A, detectors: 2, c: 8, pitch_mm: 0.01, mount_deg: [0, 95, 0]}\n",
       "looks sideways or backwards"},
  };
  for (const auto& c : cases) {
    WriteText(dir.File("bad.yaml"), c.text);
    try {
      ReadLineCamera(dir.File("bad.yaml"));
      ADD_FAILURE() << "no error for:\n" << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos)
          << e.what() << "\nexpected: " << c.expected;
    }
  }
}

TEST(CubicBSpline, WeightsSumToOneAndReproduceLinearMotion) {
  for (double t : {0.0, 3.7, 99.99, 100.0, 250.5}) {
    const SplineSpan s = CubicBSplineWeights(t, 100);
    EXPECT_NEAR(s.weights[0] + s.weights[1] + s.weights[2] + s.weights[3], 1.0, 1e-15);
    // Node j centred on line (j - 1) * 100: node values (j - 1) * 100 reproduce t.
    double value = 0;
    for (int m = 0; m < 4; ++m) value += s.weights[m] * (s.first_node + m - 1) * 100.0;
    EXPECT_NEAR(value, t, 1e-12);
  }
  EXPECT_EQ(SplineNodeCount(999, 100), 13);
}

struct Scene {
  double nodes[4][6] = {{0.1, -0.2, 0.05, 1e-4, -2e-4, 3e-5},
                        {0.12, -0.1, 0.0, 2e-4, -1e-4, 0},
                        {0.0, 0.02, -0.03, -1e-4, 0, 1e-5},
                        {-0.1, 0.1, 0.1, 0, 1e-4, -2e-5}};
  double detector[2 * kLineMaxTerms] = {1e-3, -2e-3, 5e-4, 1e-4, 0, 0, 0, 3e-4, -1e-4, 0, 0, 0};
  double c = 8.5;
  double mount[3] = {0.002, -0.001, 0.01};
  double lever[3] = {0.1, -0.2, 0.3};
  double point[3] = {0, 0, 0};
};

TEST(LineCollinearityResidual, ZeroForAPerfectObservationAndGradientsMatch) {
  Scene s;
  const LineCamera cam = ThreeTilted();
  const double i = 37.25;
  const double u = (2 * i - 0 - 99) / 99.0;
  const SplineSpan span = CubicBSplineWeights(412.5, 100);
  const Eigen::Vector3d pos_opk(0.01, -0.02, 0.03), pos_center(100, 2000, 1000);
  // Build the ground point on the ray of detector i at this line: same formula, by hand.
  Eigen::Vector3d opk = pos_opk, center = pos_center;
  for (int m = 0; m < 4; ++m)
    for (int a = 0; a < 3; ++a) {
      center[a] += span.weights[m] * s.nodes[m][a];
      opk[a] += span.weights[m] * s.nodes[m][3 + a];
    }
  const Eigen::Matrix3d body = RotationFromOpk(opk);
  const Eigen::Matrix3d mount = RotationFromOpk(Eigen::Vector3d(s.mount));
  const Eigen::Vector2d design = cam.DesignPosition(i);
  const double x = design.x() + EvaluatePolynomial(s.detector, kLineMaxTerms, u);
  const double y = design.y() + EvaluatePolynomial(s.detector + kLineMaxTerms, kLineMaxTerms, u);
  const Eigen::Vector3d ray = body * mount * Eigen::Vector3d(x, y, -s.c);
  const Eigen::Vector3d cam_center = center + body * Eigen::Vector3d(s.lever);
  const Eigen::Vector3d point = cam_center + ray * (1000.0 / -ray.z());  // 1000 m below
  std::copy(point.data(), point.data() + 3, s.point);

  // A time offset (here 0) moves the pose along the POS velocity and attitude rate.
  LineDetectorGeometry geometry;
  geometry.xy_mm = design;
  geometry.slope_mm = (cam.DesignPosition(i + 0.01) - cam.DesignPosition(i - 0.01)) / 0.02;
  geometry.u = u;
  geometry.du_di = 2.0 / 99.0;
  geometry.nominal_c_mm = 8.5;
  auto cost = LineCollinearityResidual::Create(geometry,
                                               span,
                                               pos_opk,
                                               pos_center,
                                               Eigen::Vector2d(0.003, 0.003),
                                               Eigen::Vector3d(1, 60, -0.5),
                                               Eigen::Vector3d(0.01, -0.02, 0.005));
  double time_offset = 0.0;
  const double* blocks[] = {s.nodes[0],
                            s.nodes[1],
                            s.nodes[2],
                            s.nodes[3],
                            s.detector,
                            &s.c,
                            s.mount,
                            s.lever,
                            &time_offset,
                            s.point};
  double r[2];
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  // Whitening: moving the point 1 m across track changes r by about (c / H) 1000 mm / sigma.
  s.point[0] += 1.0;
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_GT(std::hypot(r[0], r[1]), 0.5 * 8.5 / 1000 / 0.003);
  EXPECT_LT(std::hypot(r[0], r[1]), 2.0 * 8.5 / 1000 / 0.003);

  ceres::NumericDiffOptions options;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(cost.get(), no_manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  time_offset = 0.003;
  std::vector<double*> mutable_blocks = {s.nodes[0],
                                         s.nodes[1],
                                         s.nodes[2],
                                         s.nodes[3],
                                         s.detector,
                                         &s.c,
                                         s.mount,
                                         s.lever,
                                         &time_offset,
                                         s.point};
  EXPECT_TRUE(checker.Probe(mutable_blocks.data(), 1e-6, &results)) << results.error_log;
}

TEST(LineCollinearityResidual, RefusesAPointBehindTheCamera) {
  Scene s;
  s.point[2] = 3000;  // above the camera at 1000 m
  LineDetectorGeometry geometry;
  geometry.slope_mm = Eigen::Vector2d(0.01, 0);
  geometry.nominal_c_mm = 8.5;
  auto cost = LineCollinearityResidual::Create(geometry,
                                               CubicBSplineWeights(0, 10),
                                               Eigen::Vector3d::Zero(),
                                               Eigen::Vector3d(0, 0, 1000),
                                               Eigen::Vector2d(0.003, 0.003));
  double time_offset = 0.0;
  const double* blocks[] = {s.nodes[0],
                            s.nodes[1],
                            s.nodes[2],
                            s.nodes[3],
                            s.detector,
                            &s.c,
                            s.mount,
                            s.lever,
                            &time_offset,
                            s.point};
  double r[2];
  EXPECT_FALSE(cost->Evaluate(blocks, r, nullptr));
}

}  // namespace
}  // namespace aerocal::calib
