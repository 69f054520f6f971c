// Laboratory calibration from directions (issue 36 item 6) on simulated instruments: a 9 x 9
// collimator array over the field of view (0.5 arc second direction sigma, 0.05 px image sigma) and
// a 9 x 9 goniometer sequence on one fixed target of unknown direction (0.5 arc second per
// setting). The oracle: c, x0, y0, the distortion and the rotation within 3 reported sigmas of the
// truth, sigma0 within 1 +- 3 / sqrt(2 r), the method named.
#include "triangulation/calibration/direction_calibration.h"

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "tests/support/simulated_directions.h"

#include <gtest/gtest.h>

#include <cmath>
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

void ExpectWithinThreeSigma(const DirectionCalibration& r, const calib::Camera& truth) {
  ASSERT_TRUE(r.report.converged) << r.report.message;
  ASSERT_TRUE(r.covariance_ok);
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
  for (int i = 0; i < 3; ++i) {
    const double error = r.opk_rad[i] - kTrueOpk[i];
    std::printf("opk[%d] error %.3f arcsec sigma %.3f arcsec\n",
                i,
                error / kArcSecond,
                r.opk_sigma_rad[i] / kArcSecond);
    EXPECT_LE(std::abs(error), 3.0 * r.opk_sigma_rad[i]) << "opk " << i;
  }
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

}  // namespace
}  // namespace aerocal::triangulation
