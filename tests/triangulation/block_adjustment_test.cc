// Self-calibrating bundle block adjustment on the simulated example flight (37 exposures, 2x3-CCD
// camera, nominal camera off by DMZ-like corrections): the acceptance figures of the adjustment.
#include "triangulation/adjustment/block_adjustment.h"

#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/conventional_reference.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

using testing::ProjectFromFlight;

AdjustOptions SelfCalibration() {
  AdjustOptions o;
  o.free_interior = ParseSelfCalibration("all");
  return o;
}

void ExpectTruthWithinThreeSigma(const CameraEstimate& c, const calib::Camera& truth) {
  for (int k = 0; k < Model::kNumParams; ++k) {
    SCOPED_TRACE(std::string(Model::kParams[k].name));
    ASSERT_GT(c.sigma[k], 0.0);
    EXPECT_LE(std::abs(c.estimated[k] - truth.interior[k]), 3.0 * c.sigma[k])
        << "estimate " << c.estimated[k] << " truth " << truth.interior[k] << " sigma "
        << c.sigma[k];
  }
}

bool HasCorrelation(const Determinability& d, const std::string& a, const std::string& b_part) {
  for (const auto& h : d.high_correlations)
    if (h.a == a && h.b.find(b_part) != std::string::npos && std::abs(h.correlation) > 0.95)
      return true;
  return false;
}

class SimulatedFlightAdjustment : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    flight_ = std::make_unique<SimulatedFlight>(SimulateFlight(FlightSimulationOptions{}));
    project_ = std::make_unique<Project>(ProjectFromFlight(*flight_));
    self_ = std::make_unique<AdjustmentResult>(Adjust(*project_, SelfCalibration()));
    conventional_ = std::make_unique<AdjustmentResult>(
        AdjustConventionalReference(*project_, AdjustOptions{}, *self_));
    std::printf("%s\n%s", FormatSummary(*conventional_).c_str(), FormatSummary(*self_).c_str());
  }
  static std::unique_ptr<SimulatedFlight> flight_;
  static std::unique_ptr<Project> project_;
  static std::unique_ptr<AdjustmentResult> conventional_, self_;
};
std::unique_ptr<SimulatedFlight> SimulatedFlightAdjustment::flight_;
std::unique_ptr<Project> SimulatedFlightAdjustment::project_;
std::unique_ptr<AdjustmentResult> SimulatedFlightAdjustment::conventional_;
std::unique_ptr<AdjustmentResult> SimulatedFlightAdjustment::self_;

TEST_F(SimulatedFlightAdjustment, SelfCalibrationRecoversEveryParameterWithinThreeSigma) {
  ASSERT_TRUE(self_->converged());
  ASSERT_TRUE(self_->determinability.covariance_ok) << self_->determinability.message;
  ASSERT_EQ(self_->cameras.size(), 1u);
  ExpectTruthWithinThreeSigma(self_->cameras[0], flight_->truth);
}

TEST_F(SimulatedFlightAdjustment, Sigma0MatchesTheInjectedNoise) {
  // The observations carry N(0, 0.2 px) noise and a-priori sigma 0.2 px: sigma0 ~ 1, 0.2 px.
  const double noise_px = flight_->options.image_noise_px;
  EXPECT_NEAR(self_->sigma0_px / noise_px, 1.0, 0.10);
  EXPECT_NEAR(self_->sigma0_um, self_->sigma0_px * 9.0, 1e-9);
  // The conventional run absorbs the interior errors into the exterior orientation and points.
  EXPECT_GT(conventional_->sigma0, self_->sigma0);
}

TEST_F(SimulatedFlightAdjustment, SelfCalibrationImprovesCheckPointsAtLeastOneAndAHalfTimes) {
  ASSERT_TRUE(conventional_->converged());
  ASSERT_GT(self_->check.n, 100);
  EXPECT_EQ(self_->check.n, conventional_->check.n);
  const double ratio = conventional_->check.spatial_rmse_m / self_->check.spatial_rmse_m;
  std::printf("check spatial RMSE: conventional %.3f m, self-calibration %.3f m, ratio %.2f\n",
              conventional_->check.spatial_rmse_m,
              self_->check.spatial_rmse_m,
              ratio);
  EXPECT_GE(ratio, 1.5);
  // The comparison is made on the same observations: the conventional run leaves out exactly what
  // the self-calibrating run rejected and rejects nothing of its own (its residuals carry the
  // camera error; snooping would throw away good rays of the control points).
  EXPECT_EQ(conventional_->rejected.size(), self_->rejected.size());
  int unused = 0;
  for (const auto& v : conventional_->residuals) unused += v.used ? 0 : 1;
  EXPECT_EQ(unused, 0);
}

TEST_F(SimulatedFlightAdjustment, WithoutGnssPrincipalDistanceAndHeightsAreReportedInseparable) {
  EXPECT_TRUE(HasCorrelation(self_->determinability, "camera cam1.c", "centre.Z"));
  bool said = false;
  for (const auto& w : self_->determinability.warnings)
    said |= w.find("camera cam1.c is not separable") != std::string::npos;
  EXPECT_TRUE(said);
  // The JSON says it too.
  const auto json = AdjustmentToJson(*self_);
  EXPECT_FALSE(json["determinability"]["high_correlations"].empty());
}

TEST_F(SimulatedFlightAdjustment, ResultJsonHasTheFormatsKeys) {
  const auto j = AdjustmentToJson(*self_);
  for (const char* key : {"kind",
                          "sigma0",
                          "sigma0_px",
                          "sigma0_um",
                          "redundancy",
                          "iterations",
                          "converged",
                          "cameras",
                          "control",
                          "check",
                          "exposures",
                          "rejected"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["kind"], "adjust");
  EXPECT_EQ(j["exposures"].size(), flight_->exposures_truth.size());
  EXPECT_EQ(j["check"]["rmse_m"].size(), 3u);
  EXPECT_TRUE(j["cameras"][0]["sigma"].contains("c"));
  EXPECT_EQ(j["check"]["points"].size(), static_cast<size_t>(self_->check.n));
}

TEST_F(SimulatedFlightAdjustment, ResultJsonCarriesItsSchemaVersionAndTheModelsParameterTable) {
  const auto j = AdjustmentToJson(*self_);
  EXPECT_EQ(j["schema_version"], ResultSchemaVersion("adjust"));
  const auto& model = j["camera_model"];
  EXPECT_EQ(model["name"], std::string(Model::kName));
  EXPECT_EQ(model["id"], static_cast<int>(Model::kId));
  ASSERT_EQ(model["parameters"].size(), static_cast<size_t>(Model::kNumParams));
  const std::vector<std::string> units = {
      "mm", "mm", "mm", "mm^-2", "mm^-4", "mm^-6", "mm^-1", "mm^-1", "1", "1"};  // CONVENTIONS.md
  const std::vector<std::string> groups = {"principal_distance",
                                           "principal_point",
                                           "principal_point",
                                           "radial",
                                           "radial",
                                           "radial",
                                           "decentering",
                                           "decentering",
                                           "affinity",
                                           "affinity"};
  for (int k = 0; k < Model::kNumParams; ++k) {
    const auto& p = model["parameters"][k];
    EXPECT_EQ(p["name"], std::string(Model::kParams[k].name));
    EXPECT_EQ(p["unit"], units[k]) << k;
    EXPECT_EQ(p["group"], groups[k]) << k;
    // The reported estimates are keyed by the table's names.
    EXPECT_TRUE(j["cameras"][0]["sigma"].contains(p["name"].get<std::string>()));
  }
}

TEST_F(SimulatedFlightAdjustment, ConvergesToTheSameSolutionFromTheTrueStart) {
  // Starting values off by 20 m and 1 degree (the default flight) and the true exterior
  // orientation reach the same minimum.
  Project from_truth = *project_;
  from_truth.exposures = flight_->exposures_truth;
  const AdjustmentResult r = Adjust(from_truth, SelfCalibration());
  ASSERT_TRUE(r.converged());
  for (int k = 0; k < Model::kNumParams; ++k)
    EXPECT_NEAR(r.cameras[0].estimated[k],
                self_->cameras[0].estimated[k],
                1e-3 * self_->cameras[0].sigma[k])
        << Model::kParams[k].name;
}

TEST(BlockAdjustment, ConvergesFromExteriorOrientationOffByFiftyMetresAndTwoDegrees) {
  FlightSimulationOptions options;
  options.seed = 7;
  options.start_position_error_m = 50.0;
  options.start_angle_error_deg = 2.0;
  const SimulatedFlight flight = SimulateFlight(options);
  const AdjustmentResult r = Adjust(ProjectFromFlight(flight), SelfCalibration());
  ASSERT_TRUE(r.converged()) << r.solve.message;
  EXPECT_NEAR(r.sigma0_px / options.image_noise_px, 1.0, 0.10);
  ExpectTruthWithinThreeSigma(r.cameras[0], flight.truth);
}

TEST(BlockAdjustment, GnssCentresDeterminePrincipalDistance) {
  FlightSimulationOptions options;
  options.gnss_sigma_m = 0.05;
  const SimulatedFlight flight = SimulateFlight(options);
  const AdjustmentResult r = Adjust(ProjectFromFlight(flight), SelfCalibration());
  std::printf("%s", FormatSummary(r).c_str());
  ASSERT_TRUE(r.converged());
  const auto& c = r.cameras[0];
  EXPECT_LE(c.sigma[Model::kC], 0.005);  // mm
  ExpectTruthWithinThreeSigma(c, flight.truth);
  EXPECT_FALSE(HasCorrelation(r.determinability, "camera cam1.c", "centre.Z"));
  const auto* prior = r.solve.Group(calib::kGroupEoPrior);
  ASSERT_NE(prior, nullptr);
  EXPECT_EQ(prior->n_observations, 3 * static_cast<int>(flight.exposures_truth.size()));
}

TEST(BlockAdjustment, FreeNetworkChecksTheShapeAfterAHelmertTransformation) {
  // No control and no GNSS: the datum is the dependent relative orientation of the starting
  // values (20 m / 1 deg off). With the true camera the block's shape is right to the noise, so
  // after the 7-parameter transformation the check points agree to the precision of a 4500 m block
  // (measured 0.05 / 0.06 / 0.45 m: Z a little worse than with control, 0.29 m, as nothing holds
  // the block's bending); in the arbitrary datum they would be metres off.
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  Project project = ProjectFromFlight(flight);
  project.cameras["cam1"] = flight.truth;
  for (auto& p : project.points)
    if (p.role == PointRole::kControl) p.role = PointRole::kCheck;
  const AdjustmentResult r = Adjust(project, AdjustOptions{});
  ASSERT_TRUE(r.converged());
  EXPECT_NE(r.datum.find("free network"), std::string::npos) << r.datum;
  ASSERT_GT(r.check.n, 300);
  bool said = false;
  for (const auto& note : r.notes) said |= note.find("7-parameter similarity") != std::string::npos;
  EXPECT_TRUE(said);
  std::printf("free network, check RMSE after Helmert: X %.3f Y %.3f Z %.3f m\n",
              r.check.rmse_m.x(),
              r.check.rmse_m.y(),
              r.check.rmse_m.z());
  EXPECT_LT(r.check.spatial_rmse_m, 0.8);
  EXPECT_LT(r.check.mean_m.norm(), 0.05);  // the transformation leaves no bias
}

TEST(BlockAdjustment, PlantedGrossErrorIsFoundListedAndRemoved) {
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  const Project clean = ProjectFromFlight(flight);
  // Plant 5 px in one observation of a point seen in >= 3 images (with two rays both are
  // equally suspect and the wrong one cannot be told apart).
  std::map<std::string, int> rays;
  for (const auto& o : flight.observations) ++rays[o.point];
  Project planted = clean;
  size_t index = 0;
  while (rays[planted.observations[index].point] < 3 || planted.observations[index].point[0] != 'K')
    ++index;
  planted.observations[index].pixel.x() += 3.0;
  planted.observations[index].pixel.y() += 4.0;
  // "Without it": the same block with that observation left out.
  Project omitted = clean;
  omitted.observations.erase(omitted.observations.begin() + index);
  const AdjustmentResult a = Adjust(omitted, SelfCalibration());
  const AdjustmentResult b = Adjust(planted, SelfCalibration());
  bool listed = false;
  for (const auto& r : b.rejected)
    if (r.image == planted.observations[index].image &&
        r.point == planted.observations[index].point) {
      listed = true;
      EXPECT_GT(r.residual_px.norm(), 1.0);  // part of the 5 px shows in the residual
    }
  EXPECT_TRUE(listed) << "image " << planted.observations[index].image << " point "
                      << planted.observations[index].point;
  EXPECT_EQ(b.rejected.size(), a.rejected.size() + 1);
  EXPECT_EQ(AdjustmentToJson(b)["rejected"].size(), b.rejected.size());
  // After the rejection the adjustment is the one without the observation.
  EXPECT_EQ(a.check.n, b.check.n);
  EXPECT_NEAR(b.check.spatial_rmse_m, a.check.spatial_rmse_m, 1e-3 * a.check.spatial_rmse_m);
  EXPECT_NEAR(b.sigma0, a.sigma0, 1e-6);
}

// An exposure that sees two points cannot be oriented: it is left out with its observations
// (DropUndeterminedExposures, which no other test checks), and the result is the one of the
// block that never observed it: the same residuals, in the same order, and the same sigma0.
TEST(BlockAdjustment, ExposureSeeingTwoPointsIsLeftOutAsIfNeverObserved) {
  const Project clean = ProjectFromFlight(SimulateFlight(FlightSimulationOptions{}));
  const std::string image = clean.exposures[clean.exposures.size() / 2].image;
  Project two = clean, none = clean;
  two.observations.clear();
  none.observations.clear();
  int kept_of_image = 0;
  for (const auto& o : clean.observations) {
    if (o.image != image) {
      two.observations.push_back(o);
      none.observations.push_back(o);
    } else if (kept_of_image < 2) {
      two.observations.push_back(o);
      ++kept_of_image;
    }
  }
  ASSERT_EQ(kept_of_image, 2);
  const AdjustmentResult a = Adjust(two, AdjustOptions{});
  const AdjustmentResult b = Adjust(none, AdjustOptions{});
  EXPECT_NE(std::find(a.notes.begin(),
                      a.notes.end(),
                      "image " + image +
                          " sees 2 point(s) only: its orientation cannot be determined; left out"),
            a.notes.end());
  ASSERT_EQ(a.residuals.size(), b.residuals.size());
  EXPECT_NEAR(a.sigma0, b.sigma0, 1e-9 * b.sigma0);
  for (size_t i = 0; i < a.residuals.size(); ++i) {
    ASSERT_EQ(a.residuals[i].image, b.residuals[i].image);
    ASSERT_EQ(a.residuals[i].point, b.residuals[i].point);
    EXPECT_NEAR((a.residuals[i].residual_px - b.residuals[i].residual_px).norm(), 0.0, 1e-9);
  }
}

}  // namespace
}  // namespace aerocal::triangulation
