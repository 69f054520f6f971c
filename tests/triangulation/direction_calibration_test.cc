// Laboratory calibration from directions (issue 36 item 6) on simulated instruments: a 9 x 9
// collimator array over the field of view (0.5 arc second direction sigma, 0.05 px image sigma) and
// a 9 x 9 goniometer sequence on one fixed target of unknown direction (0.5 arc second per
// setting). The oracle: c, x0, y0, the distortion and the rotation within 3 reported sigmas of the
// truth, sigma0 within 1 +- 3 / sqrt(2 r), the method named.
#include "triangulation/calibration/direction_calibration.h"

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "tests/support/simulated_directions.h"
#include "triangulation/calibration/direction_subimages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace aerocal::triangulation {
namespace {

constexpr double kArcSecond = 3.14159265358979323846 / 180.0 / 3600.0;
constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kSigmaPx = 0.05;
constexpr double kSigmaRad = 0.5 * kArcSecond;

calib::Camera Nominal() {
  calib::Camera camera = calib::Camera::OfModel(calib::CameraModelId::kBrownFraser10);
  camera.pixel_size_mm = 0.006;
  camera.width_px = 6000;
  camera.height_px = 4000;
  camera.interior[0] = 50.0;
  return camera;
}

calib::Camera Truth() {
  calib::Camera camera = Nominal();
  const double truth[10] = {50.012, 0.011, -0.007, -3e-5, 2e-8, -5e-12, 3e-6, -2e-6, 5e-5, -3e-5};
  std::copy(truth, truth + 10, camera.interior.begin());
  return camera;
}

const Eigen::Vector3d kTrueOpk(0.2 * kDeg, -0.3 * kDeg, 0.4 * kDeg);

Eigen::Vector3d Direction(double azimuth, double elevation) {
  return testing::InstrumentDirection(azimuth, elevation);
}

// The measured pixel of direction t (instrument frame) seen through G: exact, then image noise.
Eigen::Vector2d Observe(const calib::Camera& truth,
                        const Eigen::Matrix3d& g,
                        const Eigen::Vector3d& t,
                        std::mt19937_64* rng) {
  const Eigen::Vector2d px = testing::ObserveDirection(truth, kTrueOpk, g, t, kSigmaPx, rng);
  EXPECT_TRUE(px.allFinite());
  return px;
}

// A small random rotation of kSigmaRad per axis (a direction's or a setting's error).
Eigen::Matrix3d AngularError(std::mt19937_64* rng) {
  return testing::RandomSmallRotation(kSigmaRad, rng);
}

void ExpectInteriorWithinThreeSigma(const DirectionCalibration& r, const calib::Camera& truth) {
  const auto params = truth.Params();
  for (int i = 0; i < truth.interior.size(); ++i) {
    const double error = r.camera.interior[i] - truth.interior[i];
    std::printf("%-3s truth %+.6e estimated %+.6e sigma %.3e (%+.2f sigma)\n",
                std::string(params[i].name).c_str(),
                truth.interior[i],
                r.camera.interior[i],
                r.interior_sigma[i],
                error / r.interior_sigma[i]);
    EXPECT_GT(r.interior_sigma[i], 0.0) << params[i].name;
    EXPECT_LE(std::abs(error), 3.0 * r.interior_sigma[i]) << params[i].name;
  }
}

// Angles (omega, phi, kappa) within 3 sigmas of the truth.
void ExpectAnglesWithinThreeSigma(const Eigen::Vector3d& estimated,
                                  const Eigen::Vector3d& sigma,
                                  const Eigen::Vector3d& truth,
                                  const std::string& what) {
  for (int i = 0; i < 3; ++i) {
    const double error = estimated[i] - truth[i];
    std::printf("%s[%d] error %.3f arcsec sigma %.3f arcsec\n",
                what.c_str(),
                i,
                error / kArcSecond,
                sigma[i] / kArcSecond);
    EXPECT_GT(sigma[i], 0.0) << what << " " << i;
    EXPECT_LE(std::abs(error), 3.0 * sigma[i]) << what << " " << i;
  }
}

void ExpectWithinThreeSigma(const DirectionCalibration& r, const calib::Camera& truth) {
  ASSERT_TRUE(r.report.converged) << r.report.message;
  ASSERT_TRUE(r.covariance_ok);
  ExpectInteriorWithinThreeSigma(r, truth);
  ExpectAnglesWithinThreeSigma(r.opk_rad, r.opk_sigma_rad, kTrueOpk, "opk");
  const double redundancy = r.report.redundancy;
  std::printf("sigma0 %.3f, redundancy %d\n", r.report.sigma0, r.report.redundancy);
  EXPECT_NEAR(r.report.sigma0, 1.0, 3.0 / std::sqrt(2.0 * redundancy));
}

// Node (i, j) of the 9 x 9 grid over the field of view: azimuth -17..17 deg, elevation -11.5..11.5
// deg.
Eigen::Vector2d GridAngles(int i, int j) {
  return Eigen::Vector2d(-17.0 + 34.0 * i / 8.0, -11.5 + 23.0 * j / 8.0) * kDeg;
}

DirectionCalibration SimulateCollimatorArray(std::mt19937_64* rng) {
  const calib::Camera truth = Truth();
  std::vector<DirectionTarget> targets;
  std::vector<DirectionObservation> observations;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      const Eigen::Vector2d angles = GridAngles(i, j);
      const std::string id = "col" + std::to_string(i) + "_" + std::to_string(j);
      targets.push_back({id, angles, true});
      // The collimator's true direction differs from its calibrated one by its 0.5" error.
      const Eigen::Vector3d t = AngularError(rng) * Direction(angles.x(), angles.y());
      observations.push_back({id,
                              "",
                              Eigen::Matrix3d::Identity(),
                              Observe(truth, Eigen::Matrix3d::Identity(), t, rng),
                              kSigmaPx,
                              kSigmaRad,
                              ""});
    }
  return CalibrateFromDirections(Nominal(), Eigen::Vector3d::Zero(), targets, observations);
}

const Eigen::Vector2d kTargetAngles(0.05 * kDeg, -0.03 * kDeg);  // the goniometer's fixed target

DirectionCalibration SimulateGoniometer(std::mt19937_64* rng) {
  const calib::Camera truth = Truth();
  std::vector<DirectionTarget> targets = {{"cross", Eigen::Vector2d::Zero(), false}};  // unknown
  std::vector<DirectionObservation> observations;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      // Setting G = Rx(e) Ry(a): the target sweeps the field (azimuth ~a, elevation ~-e).
      const Eigen::Vector2d ae = GridAngles(i, j);
      const Eigen::Matrix3d g = calib::RotationFromOpk(Eigen::Vector3d(ae.y(), ae.x(), 0.0));
      const Eigen::Matrix3d true_g = g * AngularError(rng);  // the setting's 0.5" error
      observations.push_back(
          {"cross",
           "a" + std::to_string(i) + "e" + std::to_string(j),
           g,
           Observe(truth, true_g, Direction(kTargetAngles.x(), kTargetAngles.y()), rng),
           kSigmaPx,
           kSigmaRad,
           ""});
    }
  return CalibrateFromDirections(Nominal(), Eigen::Vector3d::Zero(), targets, observations);
}

TEST(DirectionCalibration, CollimatorArrayRecoversTheInteriorWithinThreeSigma) {
  std::mt19937_64 rng(3601);
  const DirectionCalibration r = SimulateCollimatorArray(&rng);
  EXPECT_EQ(r.method, "collimator array");
  EXPECT_EQ(r.report.redundancy, 2 * 81 - 13);
  ExpectWithinThreeSigma(r, Truth());
}

TEST(DirectionCalibration, GoniometerSequenceRecoversTheInteriorAndTheTargetWithinThreeSigma) {
  std::mt19937_64 rng(3602);
  const DirectionCalibration r = SimulateGoniometer(&rng);
  EXPECT_EQ(r.method, "goniometer");
  EXPECT_EQ(r.report.redundancy, 2 * 81 - 15);
  ExpectWithinThreeSigma(r, Truth());
  const Eigen::Vector2d error = r.target_angles_rad.at("cross") - kTargetAngles;
  const Eigen::Vector2d sigma = r.target_sigma_rad.at("cross");
  std::printf("target error %.3f %.3f arcsec, sigma %.3f %.3f arcsec\n",
              error.x() / kArcSecond,
              error.y() / kArcSecond,
              sigma.x() / kArcSecond,
              sigma.y() / kArcSecond);
  EXPECT_LE(std::abs(error.x()), 3.0 * sigma.x());
  EXPECT_LE(std::abs(error.y()), 3.0 * sigma.y());
}

// The reported sigmas are right: over 50 seeds the rms of (error / sigma) of every interior
// parameter is 1 within 0.3 (3 standard deviations of an rms of 50 unit normals, sqrt(1/100)).
TEST(DirectionCalibration, ReportedSigmasMatchTheScatterOverSeeds) {
  constexpr int kSeeds = 50;
  for (bool goniometer : {false, true}) {
    std::vector<double> sum2(10, 0.0);
    std::mt19937_64 rng(goniometer ? 77 : 78);
    for (int seed = 0; seed < kSeeds; ++seed) {
      const DirectionCalibration r =
          goniometer ? SimulateGoniometer(&rng) : SimulateCollimatorArray(&rng);
      ASSERT_TRUE(r.report.converged && r.covariance_ok);
      for (int i = 0; i < 10; ++i)
        sum2[i] += std::pow((r.camera.interior[i] - Truth().interior[i]) / r.interior_sigma[i], 2);
    }
    for (int i = 0; i < 10; ++i) {
      const double rms = std::sqrt(sum2[i] / kSeeds);
      std::printf("%s %-3s rms(error / sigma) %.3f\n",
                  goniometer ? "goniometer" : "collimator",
                  std::string(Truth().Params()[i].name).c_str(),
                  rms);
      EXPECT_NEAR(rms, 1.0, 0.3) << (goniometer ? "goniometer " : "collimator ")
                                 << Truth().Params()[i].name;
    }
  }
}

TEST(DirectionCalibration, RefusesUnknownTargetsAndBadSigmas) {
  std::vector<DirectionTarget> targets = {{"a", Eigen::Vector2d::Zero(), true}};
  std::vector<DirectionObservation> observations = {
      {"b", "", Eigen::Matrix3d::Identity(), {3000, 2000}, 0.1, 0, ""}};
  EXPECT_THROW(CalibrateFromDirections(Nominal(), Eigen::Vector3d::Zero(), targets, observations),
               InputError);
  observations[0].target = "a";
  observations[0].sigma_px = 0.0;
  EXPECT_THROW(CalibrateFromDirections(Nominal(), Eigen::Vector3d::Zero(), targets, observations),
               InputError);
  DirectionCalibrationOptions options;
  options.free_interior = {"c", "K9"};
  observations[0].sigma_px = 0.1;
  EXPECT_THROW(
      CalibrateFromDirections(Nominal(), Eigen::Vector3d::Zero(), targets, observations, options),
      InputError);
}

// Several units of one instrument in ONE adjustment (CalibrateUnitsFromDirections): per unit its
// true interior and mount M_k (reference_from_unit), the instrument rotation R shared; each unit
// sees what falls into its format. The oracle: every unit's interior, R and every mount within 3
// reported sigmas, sigma0 within 1 +- 3 / sqrt(2 r).
struct SimulatedUnit {
  std::string id;
  calib::Camera truth, start;
  Eigen::Vector3d mount_opk = Eigen::Vector3d::Zero();  // true M_k
};

// The unit's pixel of direction t through g (its true rotation R M_k), or false when it falls
// outside its format (20 px margin).
bool ObserveInUnit(const SimulatedUnit& u,
                   const Eigen::Matrix3d& g,
                   const Eigen::Vector3d& t,
                   std::mt19937_64* rng,
                   Eigen::Vector2d* pixel) {
  const Eigen::Matrix3d r = calib::RotationFromOpk(kTrueOpk) * calib::RotationFromOpk(u.mount_opk);
  const Eigen::Vector3d uvw = r.transpose() * g.transpose() * t;
  if (uvw.z() > -0.5) return false;  // behind or far off the axis
  *pixel = testing::ObserveDirection(u.truth, calib::OpkFromRotation(r), g, t, kSigmaPx, rng);
  constexpr double kMarginPx = 20.0;
  return pixel->allFinite() && pixel->minCoeff() >= kMarginPx &&
         pixel->x() <= u.truth.width_px - 1 - kMarginPx &&
         pixel->y() <= u.truth.height_px - 1 - kMarginPx;
}

void ExpectUnitsWithinThreeSigma(const DirectionUnitsCalibration& r,
                                 const std::vector<SimulatedUnit>& units) {
  ASSERT_TRUE(r.report.converged) << r.report.message;
  ASSERT_TRUE(r.covariance_ok);
  ASSERT_EQ(r.units.size(), units.size());
  ExpectAnglesWithinThreeSigma(
      r.units[0].opk_rad, r.units[0].opk_sigma_rad, kTrueOpk, "instrument rotation");
  for (size_t k = 0; k < units.size(); ++k) {
    std::printf("unit %s\n", units[k].id.c_str());
    ExpectInteriorWithinThreeSigma(r.units[k], units[k].truth);
    if (k > 0)
      ExpectAnglesWithinThreeSigma(
          r.mount_opk_rad[k], r.mount_sigma_rad[k], units[k].mount_opk, "mount " + units[k].id);
  }
  std::printf("sigma0 %.3f, redundancy %d\n", r.report.sigma0, r.report.redundancy);
  EXPECT_NEAR(r.report.sigma0, 1.0, 3.0 / std::sqrt(2.0 * r.report.redundancy));
}

// A rig of three heads (6000 x 4000 px, c = 50 mm), the side heads turned by -+20 deg about y, in
// front of a collimator array over -37..37 deg azimuth: 41 x 9 collimators, each head measuring
// those in its format (about 180). Start rotations from Wahba's problem per head.
std::vector<SimulatedUnit> RigHeads() {
  std::vector<SimulatedUnit> heads = {
      {"N", Truth(), Nominal(), Eigen::Vector3d::Zero()},
      {"L", Truth(), Nominal(), Eigen::Vector3d(0.1, 20.0, 0.3) * kDeg},
      {"R", Truth(), Nominal(), Eigen::Vector3d(-0.2, -20.0, -0.1) * kDeg}};
  heads[1].truth.interior[0] += 0.02, heads[1].truth.interior[1] -= 0.015;
  heads[2].truth.interior[0] -= 0.03, heads[2].truth.interior[2] += 0.01;
  heads[2].truth.interior[3] = -4e-5;
  return heads;
}

DirectionUnitsCalibration SimulateRigCollimatorArray(const std::vector<SimulatedUnit>& heads,
                                                     std::mt19937_64* rng,
                                                     size_t* observations) {
  std::vector<DirectionTarget> targets;
  std::vector<DirectionUnit> units;
  for (const SimulatedUnit& h : heads)
    units.push_back({h.id, h.start, Eigen::Vector3d::Zero(), {}});
  for (int i = 0; i < 41; ++i)
    for (int j = 0; j < 9; ++j) {
      const Eigen::Vector2d angles = Eigen::Vector2d(-37.0 + 1.85 * i, -11.0 + 2.75 * j) * kDeg;
      const std::string id = "col" + std::to_string(i) + "_" + std::to_string(j);
      targets.push_back({id, angles, true});
      const Eigen::Vector3d t = AngularError(rng) * Direction(angles.x(), angles.y());
      for (size_t k = 0; k < heads.size(); ++k) {
        Eigen::Vector2d pixel;
        if (ObserveInUnit(heads[k], Eigen::Matrix3d::Identity(), t, rng, &pixel))
          units[k].observations.push_back(
              {id, "", Eigen::Matrix3d::Identity(), pixel, kSigmaPx, kSigmaRad, ""});
      }
    }
  *observations = 0;
  for (DirectionUnit& u : units) {
    EXPECT_GE(u.observations.size(), 120u) << u.id;
    *observations += u.observations.size();
    u.start_opk_rad = StartRotationFromDirections(u.start, targets, u.observations);
  }
  return CalibrateUnitsFromDirections(units, targets);
}

TEST(DirectionCalibration, RigHeadsInOneAdjustmentRecoverInteriorsAndMounts) {
  std::mt19937_64 rng(3603);
  const std::vector<SimulatedUnit> heads = RigHeads();
  size_t observations = 0;
  const DirectionUnitsCalibration r = SimulateRigCollimatorArray(heads, &rng, &observations);
  EXPECT_EQ(r.method, "collimator array");
  EXPECT_EQ(r.report.redundancy, static_cast<int>(2 * observations - 3 * 13));
  ExpectUnitsWithinThreeSigma(r, heads);
}

// The mounts' sigmas (propagated from the joint covariance of the two rotations) are right: over
// 40 seeds the rms of (error / sigma) of every mount angle is 1 within 0.34 (3 standard deviations
// of an rms of 40 unit normals, sqrt(1/80)).
TEST(DirectionCalibration, MountSigmasMatchTheScatterOverSeeds) {
  constexpr int kSeeds = 40;
  const std::vector<SimulatedUnit> heads = RigHeads();
  std::mt19937_64 rng(79);
  Eigen::Matrix<double, 3, 3> sum2 = Eigen::Matrix3d::Zero();  // head (1, 2) x angle
  for (int seed = 0; seed < kSeeds; ++seed) {
    size_t observations = 0;
    const DirectionUnitsCalibration r = SimulateRigCollimatorArray(heads, &rng, &observations);
    ASSERT_TRUE(r.report.converged && r.covariance_ok);
    for (int k = 1; k < 3; ++k)
      sum2.row(k) +=
          ((r.mount_opk_rad[k] - heads[k].mount_opk).array() / r.mount_sigma_rad[k].array())
              .square()
              .matrix()
              .transpose();
  }
  for (int k = 1; k < 3; ++k)
    for (int i = 0; i < 3; ++i) {
      const double rms = std::sqrt(sum2(k, i) / kSeeds);
      std::printf("mount %s[%d] rms(error / sigma) %.3f\n", heads[k].id.c_str(), i, rms);
      EXPECT_NEAR(rms, 1.0, 0.34) << heads[k].id << " " << i;
    }
}

// A four-CCD camera behind one lens (c = 50 mm): CCDs of 3000 x 2000 px of 6 um in a 2 x 2 layout,
// the lens axis at their common corner (principal points +-9.1, +-6.1 mm in each CCD's photo
// frame), each CCD misplaced by a small mount rotation. A goniometer turns it over -22..22 deg x
// -15..15 deg in steps of 1.5 deg; the one fixed target (direction unknown, shared by all CCDs)
// lands in one CCD per setting or in a gap.
TEST(DirectionCalibration, MultiCcdSubImagesInOneGoniometerAdjustment) {
  std::mt19937_64 rng(3604);
  std::vector<SimulatedUnit> ccds;
  const char* kCcdIds[4] = {"I", "II", "III", "IV"};
  const double x0[4] = {9.1, -9.1, 9.1, -9.1}, y0[4] = {-6.1, -6.1, 6.1, 6.1};
  const Eigen::Vector3d mounts[4] = {Eigen::Vector3d::Zero(),
                                     Eigen::Vector3d(2e-4, -1e-4, 1e-3),
                                     Eigen::Vector3d(-1e-4, 3e-4, -8e-4),
                                     Eigen::Vector3d(1.5e-4, 2e-4, 5e-4)};
  for (int k = 0; k < 4; ++k) {
    SimulatedUnit u{kCcdIds[k], Truth(), Nominal(), mounts[k]};
    for (calib::Camera* camera : {&u.truth, &u.start}) {
      camera->width_px = 3000, camera->height_px = 2000;
      camera->interior[1] += x0[k], camera->interior[2] += y0[k];
    }
    u.start.interior[1] = x0[k], u.start.interior[2] = y0[k];
    ccds.push_back(u);
  }
  std::vector<DirectionTarget> targets = {{"cross", Eigen::Vector2d::Zero(), false}};
  std::vector<DirectionUnit> units;
  for (const SimulatedUnit& c : ccds) units.push_back({c.id, c.start, Eigen::Vector3d::Zero(), {}});
  const Eigen::Vector3d t = Direction(kTargetAngles.x(), kTargetAngles.y());
  for (int i = 0; i <= 29; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Eigen::Vector2d ae = Eigen::Vector2d(-22.0 + 1.5 * i, -15.0 + 1.5 * j) * kDeg;
      const Eigen::Matrix3d g = calib::RotationFromOpk(Eigen::Vector3d(ae.y(), ae.x(), 0.0));
      const Eigen::Matrix3d true_g = g * AngularError(&rng);
      for (size_t k = 0; k < ccds.size(); ++k) {
        Eigen::Vector2d pixel;
        if (ObserveInUnit(ccds[k], true_g, t, &rng, &pixel))
          units[k].observations.push_back({"cross",
                                           "a" + std::to_string(i) + "e" + std::to_string(j),
                                           g,
                                           pixel,
                                           kSigmaPx,
                                           kSigmaRad,
                                           ""});
      }
    }
  for (const DirectionUnit& u : units) {
    std::printf("CCD %s: %zu settings\n", u.id.c_str(), u.observations.size());
    ASSERT_GE(u.observations.size(), 80u) << u.id;
  }
  const DirectionUnitsCalibration r = CalibrateUnitsFromDirections(units, targets);
  EXPECT_EQ(r.method, "goniometer");
  ExpectUnitsWithinThreeSigma(r, ccds);
  const Eigen::Vector2d error = r.target_angles_rad.at("cross") - kTargetAngles;
  const Eigen::Vector2d sigma = r.target_sigma_rad.at("cross");
  EXPECT_LE(std::abs(error.x()), 3.0 * sigma.x());
  EXPECT_LE(std::abs(error.y()), 3.0 * sigma.y());
}

// A 2 x 3-CCD camera (issue 36 item 6): one lens (the virtual camera of Truth(): 6000 x 4000 px of
// 6 um, c = 50 mm, the 10-parameter distortion), six CCDs of 2100 x 2100 px, each on the virtual
// image by an affine mapping (truth: the nominal layout turned by up to 3e-4 rad, scaled by up
// to 2e-4, sheared, shifted by up to 2 px), CCD "A" the reference (its mapping the nominal one,
// which the gauge holds). A collimator array of 25 x 17 directions (0.5 arc second each), each
// cross measured in every CCD it falls on (0.05 px).
struct MultiCcdScene {
  calib::Camera truth,
      start;  // truth: estimated values; start: the nominal mappings, no distortion
  std::vector<DirectionTarget> targets;
  std::vector<DirectionObservation> observations;
  std::vector<std::string> subimage_of;
};

MultiCcdScene SimulateMultiCcd(std::mt19937_64* rng) {
  MultiCcdScene s{Truth(), Nominal(), {}, {}, {}};
  s.truth.subimages = testing::TrueMultiCcdMappings();
  for (int k = 0; k < 6; ++k) s.start.subimages.push_back(testing::MultiCcdMapping(k));
  for (int i = 0; i < 25; ++i)
    for (int j = 0; j < 17; ++j) {
      const Eigen::Vector2d angles = Eigen::Vector2d(-19.0 + 1.55 * i, -13.0 + 1.6 * j) * kDeg;
      const std::string id = "c" + std::to_string(i) + "_" + std::to_string(j);
      s.targets.push_back({id, angles, true});
      const Eigen::Vector3d t = AngularError(rng) * Direction(angles.x(), angles.y());
      for (const auto& [sub, uv] :
           testing::ObserveInSubimages(s.truth, kTrueOpk, t, kSigmaPx, rng)) {
        s.observations.push_back(
            {id, "", Eigen::Matrix3d::Identity(), uv, kSigmaPx, kSigmaRad, ""});
        s.subimage_of.push_back(sub);
      }
    }
  return s;
}

SubimageDirectionsCalibration CalibrateScene(const MultiCcdScene& s,
                                             const DirectionCalibrationOptions& options = {}) {
  const Eigen::Vector3d start_opk = StartRotationFromDirections(
      s.start, s.targets, VirtualObservations(s.start, s.observations, s.subimage_of));
  return CalibrateSubimagesFromDirections(
      s.start, start_opk, s.targets, s.observations, s.subimage_of, "", options);
}

TEST(DirectionCalibration, MultiCcdCameraSubImagesRecoverInteriorAndMappingsWithinThreeSigma) {
  std::mt19937_64 rng(3605);
  const MultiCcdScene s = SimulateMultiCcd(&rng);
  const SubimageDirectionsCalibration r = CalibrateScene(s);
  const DirectionCalibration& f = r.frame;
  ASSERT_TRUE(r.gauge.ok) << r.gauge.message;
  EXPECT_EQ(r.gauge.reference, "A");
  ASSERT_EQ(r.subimages.size(), 6u);
  // Unknowns: 10 interior + 3 rotation + 5 x 6 mapping entries (the reference's held).
  EXPECT_EQ(f.report.redundancy, static_cast<int>(2 * s.observations.size()) - 43);
  ExpectWithinThreeSigma(f, s.truth);
  for (size_t k = 0; k < r.subimages.size(); ++k) {
    const SubimageDirectionMapping& m = r.subimages[k];
    const calib::SubimageMapping& truth = s.truth.subimages[s.truth.SubimageIndex(m.id)];
    std::printf("CCD %s: %d directions\n", m.id.c_str(), m.observations);
    EXPECT_GE(m.observations, 40) << m.id;
    for (size_t e = 0; e < truth.params.size(); ++e) {
      const double error = m.mapping.params[e] - truth.params[e];
      if (k == 0) {  // the reference: held at the camera file's (= the true) values
        EXPECT_TRUE(m.held[e]);
        EXPECT_FALSE(m.sigma[e].has_value());
        EXPECT_DOUBLE_EQ(m.mapping.params[e], truth.params[e]);
        continue;
      }
      ASSERT_TRUE(m.sigma[e].has_value()) << m.id << " " << e;
      std::printf("  %zu error %+.3e sigma %.3e\n", e, error, *m.sigma[e]);
      EXPECT_LE(std::abs(error), 3.0 * *m.sigma[e]) << m.id << " " << e;
    }
  }
  // The camera file's own format: written and read back with the estimated mappings.
  const std::string path =
      (std::filesystem::temp_directory_path() / "aerocal_multi_ccd_directions.yaml").string();
  calib::WriteCamera(path, f.camera);
  const calib::Camera back = calib::ReadCamera(path, calib::CameraModels::kAny);
  std::filesystem::remove(path);
  ASSERT_EQ(back.subimages.size(), 6u);
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(back.interior[i], f.camera.interior[i], 1e-12);
  for (size_t k = 0; k < 6; ++k)
    for (size_t e = 0; e < 6; ++e)
      EXPECT_NEAR(back.subimages[k].params[e], f.camera.subimages[k].params[e], 1e-9);
}

// The datum is derived from the rank of the normal matrix: with every mapping free the design's
// normal matrix (distortion-free, exact observations) has a rank defect of 6 with all 10 interior
// terms free (an affine map of the whole virtual plane), of 4 with B1, B2 held (a similarity);
// holding the reference entries that span it leaves full rank (no eigenvalue below the
// threshold).
TEST(DirectionCalibration, MultiCcdGaugeFromTheRankOfTheNormalMatrix) {
  std::mt19937_64 rng(3606);
  const MultiCcdScene s = SimulateMultiCcd(&rng);
  DirectionCalibrationOptions no_affinity;
  no_affinity.free_interior = {"c", "x0", "y0", "K1", "K2", "K3", "P1", "P2"};
  for (const auto& [options, defect] :
       {std::make_pair(DirectionCalibrationOptions{}, 6), std::make_pair(no_affinity, 4)}) {
    const SubimageDirectionsCalibration r = CalibrateScene(s, options);
    const SubimageDirectionGauge& g = r.gauge;
    std::printf("free %zu: rank defect %d without the gauge, %d with; held:",
                options.free_interior.size(),
                g.rank_defect,
                g.rank_defect_with_gauge);
    for (const auto& h : g.held) std::printf(" %s", h.c_str());
    std::printf("\n  smallest relative eigenvalues without:");
    for (double e : g.smallest_relative_eigenvalues) std::printf(" %.1e", e);
    std::printf("\n  with:");
    for (double e : g.smallest_relative_eigenvalues_with_gauge) std::printf(" %.1e", e);
    std::printf("\n");
    ASSERT_TRUE(g.ok) << g.message;
    EXPECT_EQ(g.rank_defect, defect);
    EXPECT_EQ(static_cast<int>(g.held.size()), defect);
    EXPECT_EQ(g.rank_defect_with_gauge, 0);
    ASSERT_FALSE(g.smallest_relative_eigenvalues_with_gauge.empty());
    EXPECT_GT(g.smallest_relative_eigenvalues_with_gauge.front(), g.threshold);
    ASSERT_GT(g.smallest_relative_eigenvalues.size(), static_cast<size_t>(defect));
    EXPECT_LT(g.smallest_relative_eigenvalues[defect - 1], g.threshold);
    EXPECT_TRUE(r.frame.report.converged);
    EXPECT_TRUE(r.frame.covariance_ok);
    EXPECT_TRUE(r.frame.undetermined.empty());
  }
}

}  // namespace
}  // namespace aerocal::triangulation
