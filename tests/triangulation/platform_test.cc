// GNSS/IMU priors on the platform (triangulation/README.md "GNSS/IMU priors on the platform"): a
// simulated block whose GNSS centres carry a lever arm and a time offset (and whose IMU angles a
// boresight misalignment) gives them back within 3 reported sigmas when they are free; a block
// that cannot separate them says so by name.
#include "calib/core/error.h"
#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/block_io.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace aerocal::triangulation {
namespace {

constexpr double kDeg = M_PI / 180.0;

FlightSimulationOptions PlantedPlatform() {
  FlightSimulationOptions o;
  o.gnss_sigma_m = 0.05;
  o.imu_sigma_deg = 0.003;
  o.speed_mps = 70.0;
  o.lever_arm_m = Eigen::Vector3d(0.15, -0.25, 1.3);
  o.gnss_time_offset_s = 0.02;  // 1.4 m along track at 70 m/s
  o.boresight_rad = Eigen::Vector3d(0.02, -0.015, 0.03) * kDeg;
  return o;
}

TEST(PlatformPriors, LeverArmTimeOffsetAndBoresightComeBackWithinThreeSigma) {
  const FlightSimulationOptions o = PlantedPlatform();
  const SimulatedFlight flight = SimulateFlight(o);
  Project project = testing::ProjectFromFlight(flight);
  project.cameras["cam1"] = flight.truth;  // the interior is not the question here
  project.platform.lever_arm = PlatformParamMode::kFree;
  project.platform.time_offset = PlatformParamMode::kFree;
  project.platform.boresight = PlatformParamMode::kFree;
  AdjustOptions options;
  const AdjustmentResult r = Adjust(project, options);
  ASSERT_TRUE(r.solve.converged) << r.solve.message;
  ASSERT_TRUE(r.platform.gnss && r.platform.imu);
  ASSERT_TRUE(r.platform.lever_arm_sigma_m && r.platform.time_offset_sigma_s &&
              r.platform.boresight_sigma_rad);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_LE(std::abs(r.platform.lever_arm_m(i) - o.lever_arm_m(i)),
              3.0 * (*r.platform.lever_arm_sigma_m)(i));
    EXPECT_LE(std::abs(r.platform.boresight_rad(i) - o.boresight_rad(i)),
              3.0 * (*r.platform.boresight_sigma_rad)(i));
  }
  EXPECT_LE(std::abs(r.platform.time_offset_s - o.gnss_time_offset_s),
            3.0 * *r.platform.time_offset_sigma_s);
  const double band = 3.0 / std::sqrt(2.0 * r.solve.redundancy);
  EXPECT_NEAR(r.sigma0, 1.0, band + 0.05);  // + the survey noise the simulation adds
  // Strips flown both ways: R a_x and v dt both flip sign with the direction of flight, so the
  // lever arm's x and the time offset are hardly separable (only the attitude noise tells them
  // apart): the block says so by name, and their sigmas are large (15 ms, 1 m measured).
  bool named = false;
  for (const auto& w : r.determinability.warnings)
    named |= w.find("platform lever_arm.x") != std::string::npos &&
             w.find("platform time_offset.dt") != std::string::npos;
  EXPECT_TRUE(named);
}

TEST(PlatformPriors, SurveyedLeverArmDeterminesTheTimeOffset) {
  // The lever arm surveyed on the aircraft (1 cm off, weighted with 2 cm): now the time offset
  // is determined, to a few ms, and within 3 sigma of the truth.
  const FlightSimulationOptions o = PlantedPlatform();
  const SimulatedFlight flight = SimulateFlight(o);
  Project project = testing::ProjectFromFlight(flight);
  project.cameras["cam1"] = flight.truth;
  project.platform.lever_arm = PlatformParamMode::kWeighted;
  project.platform.lever_arm_m = o.lever_arm_m + Eigen::Vector3d(0.01, -0.01, 0.01);
  project.platform.lever_arm_sigma_m = 0.02;
  project.platform.time_offset = PlatformParamMode::kFree;
  // The planted boresight (0.02-0.03 deg, 7-10 IMU sigmas) must be free too: held at zero it
  // tilts every attitude and biases the lever arm by 0.3 m (measured).
  project.platform.boresight = PlatformParamMode::kFree;
  const AdjustmentResult r = Adjust(project, AdjustOptions{});
  ASSERT_TRUE(r.solve.converged) << r.solve.message;
  ASSERT_TRUE(r.platform.time_offset_sigma_s && r.platform.lever_arm_sigma_m);
  EXPECT_LT(*r.platform.time_offset_sigma_s, 0.005);  // 5 ms: 0.35 m at 70 m/s
  EXPECT_LE(std::abs(r.platform.time_offset_s - o.gnss_time_offset_s),
            3.0 * *r.platform.time_offset_sigma_s);
  for (int i = 0; i < 3; ++i)
    EXPECT_LE(std::abs(r.platform.lever_arm_m(i) - o.lever_arm_m(i)),
              3.0 * (*r.platform.lever_arm_sigma_m)(i));
}

TEST(PlatformPriors, FixedAtZeroTheyBiasTheBlock) {
  // The same block with the platform ignored: the GNSS priors pull 1.4 m along track and 1.3 m
  // in height against the control, which sigma0 shows (negative control of the test above).
  const FlightSimulationOptions o = PlantedPlatform();
  const SimulatedFlight flight = SimulateFlight(o);
  Project project = testing::ProjectFromFlight(flight);
  project.cameras["cam1"] = flight.truth;
  const AdjustmentResult r = Adjust(project, AdjustOptions{});
  ASSERT_TRUE(r.solve.converged);
  EXPECT_GT(r.sigma0, 1.5);
}

TEST(PlatformPriors, InseparableParametersAreNamed) {
  // One strip flown one way: v dt and the lever arm's x are both a constant shift along X.
  FlightSimulationOptions o = PlantedPlatform();
  o.strips = 1;
  o.exposures = 12;
  const SimulatedFlight flight = SimulateFlight(o);
  Project project = testing::ProjectFromFlight(flight);
  project.cameras["cam1"] = flight.truth;
  project.platform.lever_arm = PlatformParamMode::kFree;
  project.platform.time_offset = PlatformParamMode::kFree;
  const AdjustmentResult r = Adjust(project, AdjustOptions{});
  bool named = false;
  for (const auto& w : r.determinability.warnings)
    named |= w.find("platform time_offset.dt") != std::string::npos ||
             w.find("platform lever_arm.x") != std::string::npos;
  for (const auto& u : r.determinability.undetermined) named |= u.rfind("platform ", 0) == 0;
  EXPECT_TRUE(named);
}

TEST(PlatformPriors, TimeOffsetWithoutVelocityIsAnInputError) {
  FlightSimulationOptions o;
  o.gnss_sigma_m = 0.05;
  const SimulatedFlight flight = SimulateFlight(o);
  Project project = testing::ProjectFromFlight(flight);
  project.exposures_file = "exposures.csv";
  project.platform.time_offset = PlatformParamMode::kFree;
  try {
    Adjust(project, AdjustOptions{});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exposures.csv:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("vX, vY, vZ"), std::string::npos) << e.what();
  }
}

TEST(PlatformPriors, ExampleConfigReadsAndBadValuesCiteTheLine) {
  const std::string path = std::string(AEROCAL_CONFIGS_DIR) + "/platform_gnss_imu.yaml";
  const PlatformSpec p = ReadPlatform(YAML::LoadFile(path)["platform"], path);
  EXPECT_EQ(p.lever_arm, PlatformParamMode::kWeighted);
  EXPECT_DOUBLE_EQ(p.lever_arm_sigma_m, 0.05);
  EXPECT_DOUBLE_EQ(p.lever_arm_m.z(), 1.30);
  EXPECT_EQ(p.boresight, PlatformParamMode::kFree);
  EXPECT_EQ(p.time_offset, PlatformParamMode::kFree);
  const char* bad[][2] = {{"platform:\n  lever_arm: loose\n", "project.yaml:2"},
                          {"platform:\n  lever_arm_m: [1, 2]\n", "project.yaml:2"},
                          {"platform:\n  time_offset: weighted\n", "time_offset_sigma_ms"},
                          {"platform:\n  lever_arm_mm: [0, 0, 1]\n", "lever_arm_mm"}};
  for (const auto& [text, expected] : bad) {
    SCOPED_TRACE(text);
    try {
      ReadPlatform(YAML::Load(text)["platform"], "project.yaml");
      FAIL() << "accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace aerocal::triangulation
