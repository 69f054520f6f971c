// Calibration library (triangulation/calibration): closed-form resections and Zhang's principal
// distance recover a noise-free truth exactly; the group stability test and the GUM budget give
// the numbers of their formulas; a simulated 3-D test field of 3 image groups calibrates to the
// truth within 3 sigma, its groups agree, and they are flagged when one group's camera changes.
#include "triangulation/calibration/calibration.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "tests/support/interior_checks.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/calibration/resection.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

calib::Camera TestCamera() {
  calib::Camera c;
  c.name = "test";
  c.pixel_size_mm = 0.006;
  c.width_px = 4000;
  c.height_px = 3000;
  c.interior = {};
  c.interior[Model::kC] = 24.0;
  return c;
}

// Pose looking at the origin from `center` (camera -z towards the target), rolled by `roll`.
Exposure LookAt(const Eigen::Vector3d& center, double roll_rad) {
  const Eigen::Vector3d back = center.normalized();  // image-space +z points away from the target
  Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(back);
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = back.cross(x);
  Eigen::Matrix3d r;
  r.col(0) = std::cos(roll_rad) * x + std::sin(roll_rad) * y;
  r.col(1) = -std::sin(roll_rad) * x + std::cos(roll_rad) * y;
  r.col(2) = back;
  Exposure e;
  e.center_m = center;
  e.opk_rad = calib::OpkFromRotation(r);
  return e;
}

void ExpectSamePose(const Exposure& a, const Exposure& b, double tol_m, double tol_rad) {
  EXPECT_LE((a.center_m - b.center_m).norm(), tol_m);
  const Eigen::Matrix3d d =
      calib::RotationFromOpk(a.opk_rad).transpose() * calib::RotationFromOpk(b.opk_rad);
  EXPECT_LE(Eigen::AngleAxisd(d).angle(), tol_rad);
}

TEST(Resection, PlanarAndGeneralPointsGiveTheExactPose) {
  const calib::Camera camera = TestCamera();
  const Exposure truth = LookAt({1.5, -2.0, 6.0}, 0.3);
  for (bool planar : {true, false}) {
    SCOPED_TRACE(planar ? "planar: homography" : "general: DLT");
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 4; ++j) {
        const Eigen::Vector3d p(-1.0 + 0.5 * i, -0.8 + 0.5 * j, planar ? 0.0 : 0.3 * ((i + j) % 3));
        Eigen::Vector2d px;
        ASSERT_TRUE(camera.ProjectToPixel(truth.opk_rad, truth.center_m, p, &px));
        pixels.push_back(px);
        points.push_back(p);
      }
    std::string why;
    const auto start = ResectImage(camera, pixels, points, &why);
    ASSERT_TRUE(start) << why;
    EXPECT_EQ(start->method, planar ? "homography" : "dlt");
    // Noise-free, no distortion: closed form to rounding (1e-7 m on 6 m, 1e-8 rad).
    ExpectSamePose(start->exposure, truth, 1e-7, 1e-8);
    EXPECT_LT(start->rms_px, 1e-5);
  }
  std::string why;
  EXPECT_FALSE(
      ResectImage(camera, {{1, 1}, {2, 2}, {3, 3}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, &why));
  EXPECT_NE(why.find("needs 4"), std::string::npos) << why;
}

// A planar board seen from tilted positions: Zhang's closed form returns the true c.
TEST(Resection, ClosedFormPrincipalDistanceOfAPlanarTarget) {
  calib::Camera truth = TestCamera();
  Project project;
  calib::Camera nominal = truth;
  nominal.interior[Model::kC] = 30.0;  // the file's c is 25 % off
  project.cameras["test"] = nominal;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 8; ++c) {
      GroundPoint p;
      p.id = "p" + std::to_string(r) + "_" + std::to_string(c);
      p.xyz_m = Eigen::Vector3d(0.1 * c - 0.35, 0.1 * r - 0.25, 0.0);
      p.role = PointRole::kControl;
      project.points.push_back(p);
    }
  const std::vector<Eigen::Vector3d> centers = {
      {0.8, 0.1, 2.0}, {-0.7, 0.4, 1.9}, {0.2, -0.9, 2.1}, {0.1, 0.8, 1.7}};
  for (size_t i = 0; i < centers.size(); ++i) {
    const Exposure e = LookAt(centers[i], 0.2 * static_cast<double>(i));
    for (const auto& p : project.points) {
      ImageObservation o;
      o.image = "i" + std::to_string(i);
      o.point = p.id;
      ASSERT_TRUE(truth.ProjectToPixel(e.opk_rad, e.center_m, *p.xyz_m, &o.pixel));
      project.observations.push_back(o);
    }
  }
  const auto c = ClosedFormPrincipalDistance(project, "test");
  ASSERT_TRUE(c);
  EXPECT_NEAR(*c, 24.0, 1e-6);
  // Every image starts by resection with the file's c (the adjustment corrects it).
  EXPECT_EQ(StartFromResections(project, "test").size(), centers.size());
}

// The Wuhan textbook resection (4 control points, film camera c = 153.24 mm, photo coordinates
// in mm): the closed-form start, refined by the conventional adjustment, gives the published
// Xs, Ys, Zs and rotation (PROVENANCE.md).
TEST(Resection, WuhanTextbookAnswer) {
  const std::string dir = testing::SharedDataDir("textbook_resection_wuhan");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/textbook_resection_wuhan is absent";
  Project project;
  calib::Camera camera;
  camera.name = "film";
  camera.pixel_size_mm = 0.001;  // 1 um "pixels": photo mm are given
  camera.width_px = camera.height_px = 230001;
  camera.interior = {};
  camera.interior[Model::kC] = 153.24;
  project.cameras["film"] = camera;
  std::ifstream in(dir + "/points.txt");
  double x, y, X, Y, Z;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; in >> x >> y >> X >> Y >> Z; ++i) {
    GroundPoint p;
    p.id = "P" + std::to_string(i + 1);
    p.xyz_m = Eigen::Vector3d(X, Y, Z);
    p.sigma_m = Eigen::Vector3d::Constant(1e-4);  // the textbook holds them fixed
    p.role = PointRole::kControl;
    project.points.push_back(p);
    ImageObservation o;
    o.image = "photo";
    o.point = p.id;
    o.pixel = camera.PixelFromPhoto({x, y});
    o.sigma_px = 7.0;  // about the textbook's sigma0 of 0.0073 mm
    project.observations.push_back(o);
    pixels.push_back(o.pixel);
    points.push_back(*p.xyz_m);
  }
  ASSERT_EQ(points.size(), 4u);
  std::string why;
  const auto start = ResectImage(camera, pixels, points, &why);
  ASSERT_TRUE(start) << why;
  const Eigen::Vector3d published(39795.452, 27476.462, 7572.686);
  // Four points that are not coplanar (heights 729 .. 2387 m) through the plane homography:
  // a start within a few hundred metres at 7.5 km flying height.
  EXPECT_LT((start->exposure.center_m - published).norm(), 500.0);
  project.exposures = {start->exposure};
  project.exposures[0].image = "photo";
  project.exposures[0].camera = "film";
  AdjustOptions options;
  options.data_snooping = false;
  const AdjustmentResult r = Adjust(project, options);
  ASSERT_TRUE(r.converged());
  // The textbook's iteration stops at 1e-3 m / 1e-6 rad: agreement to 0.01 m and 1e-5.
  EXPECT_LT((r.exposures[0].center_m - published).norm(), 0.01)
      << r.exposures[0].center_m.transpose();
  const double phi = -0.003987, omega = 0.002114, kappa = -0.067578;
  Eigen::Matrix3d textbook;  // R = R_phi(Y) R_omega(X) R_kappa(Z) with the signs of PROVENANCE.md
  textbook << std::cos(phi) * std::cos(kappa) - std::sin(phi) * std::sin(omega) * std::sin(kappa),
      -std::cos(phi) * std::sin(kappa) - std::sin(phi) * std::sin(omega) * std::cos(kappa),
      -std::sin(phi) * std::cos(omega), std::cos(omega) * std::sin(kappa),
      std::cos(omega) * std::cos(kappa), -std::sin(omega),
      std::sin(phi) * std::cos(kappa) + std::cos(phi) * std::sin(omega) * std::sin(kappa),
      -std::sin(phi) * std::sin(kappa) + std::cos(phi) * std::sin(omega) * std::cos(kappa),
      std::cos(phi) * std::cos(omega);
  EXPECT_LT((calib::RotationFromOpk(r.exposures[0].opk_rad) - textbook).cwiseAbs().maxCoeff(), 1e-5)
      << calib::RotationFromOpk(r.exposures[0].opk_rad);
}

TEST(Statistics, QuantilesAndCoverageFactors) {
  EXPECT_NEAR(ChiSquareQuantile(0.95, 2), 5.9915, 1e-3);  // tables
  EXPECT_NEAR(ChiSquareQuantile(0.99, 10), 23.209, 1e-2);
  EXPECT_EQ(CoverageFactor(std::numeric_limits<double>::infinity()), 2.0);
  EXPECT_EQ(CoverageFactor(200), 2.0);
  EXPECT_NEAR(CoverageFactor(10), 2.28, 0.005);  // GUM table G.2: t_95.45(10) = 2.28
  EXPECT_NEAR(CoverageFactor(2), 4.53, 0.005);   // t_95.45(2) = 4.53
  EXPECT_EQ(CertificateStatement("c", 52.09171, 0.00304, 2, "mm"),
            "c = 52.0917 mm, U = 0.0030 mm (k = 2)");
}

GroupCalibration FakeGroup(const std::string& name, double c, double sigma) {
  GroupCalibration g;
  g.group = name;
  CameraEstimate e;
  e.estimated[Model::kC] = c;
  e.sigma[Model::kC] = sigma;
  e.free[Model::kC] = true;
  g.adjustment.result.cameras.push_back(e);
  return g;
}

TEST(GroupStability, ChiSquareOfTheGroupsAgainstTheirWeightedMean) {
  // 52.090 / 52.094 / 52.091 mm with sigma 2 um (the lab of the issue): weighted mean 52.09167,
  // chi2 = (1.667^2 + 2.333^2 + 0.667^2) / 4 = 2.167 < 5.99 (chi2_95 %(2)).
  const auto ok = GroupStability(
      {FakeGroup("1", 52.090, 0.002), FakeGroup("2", 52.094, 0.002), FakeGroup("3", 52.091, 0.002)},
      0.05);
  ASSERT_EQ(ok.rows.size(), 1u);
  EXPECT_NEAR(ok.rows[0].weighted_mean, 52.0916667, 1e-6);
  EXPECT_NEAR(ok.rows[0].chi2, 2.1667, 1e-3);
  EXPECT_NEAR(ok.rows[0].critical, 5.9915, 1e-3);
  EXPECT_NEAR(ok.rows[0].spread, 0.0020817, 1e-6);
  EXPECT_TRUE(ok.agree);
  const auto bad = GroupStability(
      {FakeGroup("1", 52.090, 0.001), FakeGroup("2", 52.094, 0.001), FakeGroup("3", 52.091, 0.001)},
      0.05);
  EXPECT_FALSE(bad.agree);  // chi2 = 8.67 > 5.99
  ASSERT_EQ(bad.flagged.size(), 1u);
  EXPECT_NE(bad.flagged[0].find("c: the groups disagree"), std::string::npos);
}

// A 3-D test field (targets on three depth layers), 24 images in 3 groups of 8 from several
// positions and roll angles, image noise 0.1 px, a camera with distortion.
struct TestField {
  Project project;
  calib::Camera truth;
  std::map<std::string, std::string> groups;
};

TestField SimulateTestField(uint32_t seed, double group3_dc_mm) {
  TestField f;
  f.truth = TestCamera();
  f.truth.interior[Model::kX0] = 0.05;
  f.truth.interior[Model::kY0] = -0.03;
  f.truth.interior[Model::kK1] = -2e-4;
  f.truth.interior[Model::kK2] = 3e-7;
  f.truth.interior[Model::kP1] = 5e-6;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1), survey(0.0, 0.0005);
  calib::Camera nominal = f.truth;
  nominal.interior = {};
  nominal.interior[Model::kC] = 23.5;
  f.project.cameras["test"] = nominal;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 7; ++j) {
      GroundPoint p;
      p.id = "t" + std::to_string(i) + "_" + std::to_string(j);
      p.xyz_m = Eigen::Vector3d(-4.0 + 1.0 * i, -3.0 + 1.0 * j, ((i + 2 * j) % 3) * 0.8);
      p.sigma_m = Eigen::Vector3d::Constant(0.0005);
      p.role = (i + j) % 4 == 0 ? PointRole::kControl
                                : ((i * j) % 7 == 3 ? PointRole::kCheck : PointRole::kTie);
      if (p.role != PointRole::kTie)
        *p.xyz_m += Eigen::Vector3d(survey(rng), survey(rng), survey(rng));
      f.project.points.push_back(p);
    }
  for (int k = 0; k < 24; ++k) {
    const int group = k % 3;
    const double azimuth = 2 * M_PI * k / 24.0;
    const double tilt = 0.35 + 0.1 * (k % 2);
    const double distance = 14.0 + 2.0 * (k % 4);
    const Eigen::Vector3d center(distance * std::sin(tilt) * std::cos(azimuth),
                                 distance * std::sin(tilt) * std::sin(azimuth),
                                 distance * std::cos(tilt));
    const Exposure e = LookAt(center, (k % 4) * M_PI / 2);
    calib::Camera seen = f.truth;
    if (group == 2) seen.interior[Model::kC] += group3_dc_mm;
    const std::string image = "img" + std::to_string(k);
    f.groups[image] = "G" + std::to_string(group + 1);
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 7; ++j) {
        const Eigen::Vector3d x(-4.0 + 1.0 * i, -3.0 + 1.0 * j, ((i + 2 * j) % 3) * 0.8);
        ImageObservation o;
        o.image = image;
        o.point = "t" + std::to_string(i) + "_" + std::to_string(j);
        o.sigma_px = 0.1;
        if (!seen.ProjectToPixel(e.opk_rad, e.center_m, x, &o.pixel)) continue;
        if (o.pixel.x() < 0 || o.pixel.y() < 0 || o.pixel.x() > seen.width_px - 1 ||
            o.pixel.y() > seen.height_px - 1)
          continue;
        o.pixel += Eigen::Vector2d(noise(rng), noise(rng));
        f.project.observations.push_back(o);
      }
  }
  return f;
}

CalibrateOptions TestFieldOptions() {
  CalibrateOptions o;
  o.adjust.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2,P1,P2");
  o.adjust.data_snooping = false;
  return o;
}

TEST(Calibrate, SimulatedTestFieldRecoversTheTruthAndItsGroupsAgree) {
  const TestField f = SimulateTestField(7, 0.0);
  const CalibrationRun run = Calibrate(f.project, TestFieldOptions(), f.groups);
  const AdjustmentResult& r = run.all.result;
  ASSERT_TRUE(r.valid) << (r.invalid_reasons.empty() ? "" : r.invalid_reasons[0]);
  EXPECT_EQ(run.starts.size(), 24u);
  const CameraEstimate& c = r.cameras[0];
  testing::ExpectInteriorWithinThreeSigma(c, f.truth.interior);
  // sigma0 / injected sigma within 1 +- 3 / sqrt(2 r).
  EXPECT_NEAR(r.sigma0, 1.0, 3.0 / std::sqrt(2.0 * r.solve.redundancy));
  ASSERT_EQ(run.groups.size(), 3u);
  EXPECT_TRUE(run.stability.agree)
      << (run.stability.flagged.empty() ? "" : run.stability.flagged[0]);
  ASSERT_GT(run.all.control_cofactor.size(), 0);
  // The budget: c with its components, U = k u_c, and the check points' accuracy.
  const auto budget = UncertaintyBudget(run, run.project, {{10.0}, 5.0, {}, {}});
  const auto q =
      std::find_if(budget.begin(), budget.end(), [](const auto& b) { return b.name == "c"; });
  ASSERT_NE(q, budget.end());
  // image measurements, groups, control, eccentricity, pixel pitch (zero: no tolerance stated)
  ASSERT_EQ(q->components.size(), 5u);
  double sum = 0;
  for (const auto& comp : q->components) sum += comp.u * comp.u;
  EXPECT_NEAR(q->u_c, std::sqrt(sum), 1e-15);
  EXPECT_NEAR(q->expanded, q->k * q->u_c, 1e-15);
  EXPECT_GT(q->components[2].u, 0.0);  // 0.5 mm survey sigmas propagate
  EXPECT_TRUE(
      std::any_of(budget.begin(), budget.end(), [](const auto& b) { return b.name == "m_Z"; }));
  EXPECT_TRUE(
      std::any_of(budget.begin(), budget.end(), [](const auto& b) { return b.name == "dr@10"; }));
}

// The control coordinates' component by the GUM's law of propagation written out (JCGM 100
// 5.1.2, the sensitivities found numerically as 5.1.3 allows): u^2 = sum_j (dq/dX_j s_j)^2 over
// every control coordinate X_j with survey sigma s_j, dq/dX_j measured by moving X_j and adjusting
// again. This shares nothing with the budget's covariance split but the adjustment itself.
struct Propagated {
  double c = 0, x0 = 0, y0 = 0;  // u of the control coordinates, mm
};

Propagated PropagateControlBySensitivities(const CalibrationRun& run,
                                           const AdjustOptions& options) {
  Project base = run.project;  // started at the solution: each re-adjustment takes few steps
  base.cameras.begin()->second.interior = run.all.result.cameras[0].estimated;
  for (auto& e : base.exposures)
    for (const auto& a : run.all.result.exposures)
      if (a.image == e.image) {
        e.center_m = a.center_m;
        e.opk_rad = a.opk_rad;
      }
  const auto estimate = [&](const Project& p) {
    return RunCalibrationAdjustment(p, options).result.cameras[0].estimated;
  };
  const calib::InteriorParams at = estimate(base);
  // 2 mm, four survey sigmas: the response is linear to ~1e-4 (2 mm over 15 m) and far above
  // the solver's tolerances.
  constexpr double kStepM = 0.002;
  Propagated sum;
  for (size_t j = 0; j < base.points.size(); ++j) {
    if (base.points[j].role != PointRole::kControl) continue;
    for (int axis = 0; axis < 3; ++axis) {
      Project moved = base;
      (*moved.points[j].xyz_m)(axis) += kStepM;
      const calib::InteriorParams p = estimate(moved);
      const double s = base.points[j].sigma_m(axis) / kStepM;
      sum.c += std::pow((p[Model::kC] - at[Model::kC]) * s, 2);
      sum.x0 += std::pow((p[Model::kX0] - at[Model::kX0]) * s, 2);
      sum.y0 += std::pow((p[Model::kY0] - at[Model::kY0]) * s, 2);
    }
  }
  return {std::sqrt(sum.c), std::sqrt(sum.x0), std::sqrt(sum.y0)};
}

const UncertaintyComponent& ComponentOf(const BudgetQuantity& q, const std::string& source) {
  const auto it = std::find_if(
      q.components.begin(), q.components.end(), [&](const auto& c) { return c.source == source; });
  AEROCAL_CHECK(it != q.components.end()) << q.name << " has no component " << source;
  return *it;
}

TEST(UncertaintyBudget, ControlSigmasPropagateAsTheirSensitivitiesSayAndDoubledTheyGrowU) {
  const TestField f = SimulateTestField(7, 0.0);
  CalibrateOptions options = TestFieldOptions();
  options.adjust.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2");
  std::map<std::string, double> expanded_c;
  for (const double scale : {1.0, 2.0}) {
    SCOPED_TRACE(StringPrintf("control sigmas x %g", scale));
    Project project = f.project;
    for (auto& p : project.points)
      if (p.role == PointRole::kControl) p.sigma_m *= scale;
    const CalibrationRun run = Calibrate(project, options, {});
    ASSERT_TRUE(run.all.result.valid);
    ASSERT_GT(run.all.control_cofactor.size(), 0);
    const auto budget = UncertaintyBudget(run, run.project, {});
    const Propagated independent = PropagateControlBySensitivities(run, options.adjust);
    const AdjustmentResult& r = run.all.result;
    const double sigma0 = r.sigma0;
    const std::map<std::string, std::pair<int, double>> checked = {
        {"c", {Model::kC, independent.c}},
        {"x0", {Model::kX0, independent.x0}},
        {"y0", {Model::kY0, independent.y0}}};
    for (const auto& [name, index_and_u] : checked) {
      const auto q =
          std::find_if(budget.begin(), budget.end(), [&](const auto& b) { return b.name == name; });
      ASSERT_NE(q, budget.end());
      const double u_control = ComponentOf(*q, "control coordinates").u;
      // The budget's derivative of the covariance against the re-adjustments' sensitivities:
      // 2 % covers the finite steps of both (relative errors ~1e-3 and ~1e-4).
      EXPECT_NEAR(u_control, index_and_u.second, 0.02 * index_and_u.second) << name;
      EXPECT_GT(u_control, 0.0) << name;
      // u_c^2 = sigma0^2 g^T Q g (the adjustment's own sigma, image and control sigmas both
      // scaled by sigma0) + (1 - sigma0^2) u_control^2 (the control sigmas are taken as stated):
      // what the combined uncertainty must be, from the adjustment's reported sigma and the
      // independent control part; the pixel pitch (no tolerance) adds nothing.
      const double sigma = r.cameras[0].sigma[index_and_u.first];
      const double u_c =
          std::sqrt(sigma * sigma + (1 - sigma0 * sigma0) * std::pow(index_and_u.second, 2));
      EXPECT_NEAR(q->u_c, u_c, 0.01 * u_c) << name;
      EXPECT_NEAR(q->expanded, q->k * q->u_c, 1e-15) << name;
      EXPECT_EQ(ComponentOf(*q, "pixel pitch").u, 0.0);
      if (name == "c") expanded_c[StringPrintf("%g", scale)] = q->expanded;
    }
  }
  // Doubled survey sigmas weaken the control: U of c grows (by the amounts checked above).
  EXPECT_GT(expanded_c["2"], expanded_c["1"]);
}

TEST(UncertaintyBudget, APixelPitchToleranceScalesTheLengthsAndTheBudgetFileReplacesIt) {
  const TestField f = SimulateTestField(7, 0.0);
  CalibrateOptions options = TestFieldOptions();
  options.adjust.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2");
  options.control_propagation = false;
  Project project = f.project;
  project.cameras.begin()->second.pixel_size_tolerance_mm = 6e-6;  // 0.1 % of 0.006 mm
  const CalibrationRun run = Calibrate(project, options, {});
  BudgetOptions with_radius;
  with_radius.radii_mm = {10.0};
  const auto budget = UncertaintyBudget(run, run.project, with_radius);
  const calib::InteriorParams& p = run.all.result.cameras[0].estimated;
  const auto u_of = [&](const std::string& name) {
    const auto q =
        std::find_if(budget.begin(), budget.end(), [&](const auto& b) { return b.name == name; });
    AEROCAL_CHECK(q != budget.end()) << name;
    return ComponentOf(*q, "pixel pitch").u;
  };
  // A pitch 0.1 % off scales every photo length by 0.1 %: u = |length| 1e-3 / sqrt(3).
  const double rel = 1e-3 / std::sqrt(3.0);
  EXPECT_NEAR(u_of("c"), p[Model::kC] * rel, 1e-9);
  EXPECT_NEAR(u_of("x0"), std::abs(p[Model::kX0]) * rel, 1e-9);
  // K1 [mm^-2] scales by s^-2; dr(10 mm) = 10 (K1 100 + K2 1e4) mm with K1' = K1 / s^2,
  // K2' = K2 / s^4 at the fixed radius: d dr / ds = -2 K1 1e3 - 4 K2 1e5 (mm), in um.
  EXPECT_NEAR(u_of("K1"), 2 * std::abs(p[Model::kK1]) * rel, 1e-12);
  const double ddr_ds_um = 1e3 * (-2 * p[Model::kK1] * 1e3 - 4 * p[Model::kK2] * 1e5);
  EXPECT_NEAR(u_of("dr@10"), std::abs(ddr_ds_um) * rel, 1e-6 * std::abs(ddr_ds_um));
  // The budget file's component of the same name replaces aerocal's.
  BudgetOptions user = with_radius;
  UserComponent pitch;
  pitch.quantity = "c";
  pitch.source = "Pixel Pitch";
  pitch.value = 0.004;
  pitch.where = "budget.yaml:3";
  user.user.push_back(pitch);
  const auto replaced = UncertaintyBudget(run, run.project, user);
  const auto c =
      std::find_if(replaced.begin(), replaced.end(), [](const auto& b) { return b.name == "c"; });
  ASSERT_NE(c, replaced.end());
  int named = 0;
  for (const auto& comp : c->components)
    named += comp.source == "pixel pitch" || comp.source == "Pixel Pitch";
  EXPECT_EQ(named, 1);
  EXPECT_NEAR(ComponentOf(*c, "Pixel Pitch").u, 0.004, 1e-15);
}

TEST(Calibrate, AGroupWhoseCameraChangedIsFlagged) {
  // Group 3 sees a camera whose c is 20 um longer: far beyond the groups' sigmas of c.
  const TestField f = SimulateTestField(7, 0.02);
  const CalibrationRun run = Calibrate(f.project, TestFieldOptions(), f.groups);
  EXPECT_FALSE(run.stability.agree);
  ASSERT_FALSE(run.stability.flagged.empty());
  EXPECT_NE(run.stability.flagged[0].find("c:"), std::string::npos) << run.stability.flagged[0];
}

}  // namespace
}  // namespace aerocal::triangulation
