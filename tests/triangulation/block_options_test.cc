// How the block data and the adjustment options enter the self-calibrating block adjustment of
// the simulated example flight: check points only through their rays, the camera file's
// interior_sigma and the GNSS/IMU sigma columns as weighted observations, one interior block per
// camera id.
#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

constexpr double kRadiansPerDegree = M_PI / 180.0;

using testing::ProjectFromFlight;

AdjustOptions SelfCalibration(const std::string& parameters = "all") {
  AdjustOptions o;
  o.free_interior = ParseSelfCalibration(parameters);
  return o;
}

const CameraEstimate* FindCamera(const AdjustmentResult& r, const std::string& id) {
  for (const auto& c : r.cameras)
    if (c.id == id) return &c;
  return nullptr;
}

double WrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

TEST(BlockOptions, CheckPointsDoNotInfluenceTheAdjustment) {
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  const Project project = ProjectFromFlight(flight);
  Project moved = project;
  constexpr double kShiftX = 3.0, kShiftZ = 10.0;  // m
  int n_moved = 0;
  for (auto& p : moved.points)
    if (p.role == PointRole::kCheck && p.xyz_m) {
      p.xyz_m->x() += kShiftX;
      p.xyz_m->z() += kShiftZ;
      ++n_moved;
    }
  ASSERT_GT(n_moved, 100);
  const AdjustmentResult a = Adjust(project, SelfCalibration());
  const AdjustmentResult b = Adjust(moved, SelfCalibration());
  ASSERT_TRUE(a.converged());
  ASSERT_TRUE(b.converged());
  std::printf(
      "check RMSE X/Y/Z: survey %.3f %.3f %.3f m, moved survey %.3f %.3f %.3f m; "
      "sigma0 %.6f / %.6f\n",
      a.check.rmse_m.x(),
      a.check.rmse_m.y(),
      a.check.rmse_m.z(),
      b.check.rmse_m.x(),
      b.check.rmse_m.y(),
      b.check.rmse_m.z(),
      a.sigma0,
      b.sigma0);

  // The surveyed check coordinates appear in no residual and in no starting value (check points
  // start from the intersection of their rays), so both runs solve the same least-squares
  // problem from the same start: only floating-point summation order (multi-threaded Ceres) may
  // differ. kRelative is relative to max(|value|, sigma) of each estimate.
  constexpr double kRelative = 1e-9;
  constexpr double kMetres = 1e-6;
  EXPECT_NEAR(b.sigma0, a.sigma0, kRelative * a.sigma0);
  EXPECT_EQ(b.rejected.size(), a.rejected.size());
  ASSERT_EQ(a.cameras.size(), 1u);
  ASSERT_EQ(b.cameras.size(), 1u);
  double max_interior = 0.0;  // largest difference in units of max(|value|, sigma)
  for (int k = 0; k < Model::kNumParams; ++k) {
    const double scale = std::max(std::abs(a.cameras[0].estimated[k]), a.cameras[0].sigma[k]);
    const double d = std::abs(b.cameras[0].estimated[k] - a.cameras[0].estimated[k]);
    max_interior = std::max(max_interior, d / scale);
    EXPECT_LE(d, kRelative * scale) << Model::kParams[k].name;
    EXPECT_NEAR(b.cameras[0].sigma[k], a.cameras[0].sigma[k], kRelative * scale)
        << Model::kParams[k].name;
  }
  ASSERT_EQ(a.exposures.size(), b.exposures.size());
  double max_centre = 0.0;
  for (size_t i = 0; i < a.exposures.size(); ++i) {
    ASSERT_EQ(a.exposures[i].image, b.exposures[i].image);
    const double d = (b.exposures[i].center_m - a.exposures[i].center_m).norm();
    max_centre = std::max(max_centre, d);
    EXPECT_LE(d, kMetres) << a.exposures[i].image;
  }
  ASSERT_EQ(a.check_points.size(), b.check_points.size());
  double max_point = 0.0;
  for (size_t i = 0; i < a.check_points.size(); ++i)
    max_point =
        std::max(max_point, (b.check_points[i].adjusted_m - a.check_points[i].adjusted_m).norm());
  EXPECT_LE(max_point, kMetres);
  std::printf("largest differences: interior %.2e relative, centre %.2e m, check point %.2e m\n",
              max_interior,
              max_centre,
              max_point);

  // Adjusted minus surveyed: the adjusted points stay, the survey moved by (+3, 0, +10) m, so
  // the differences move by (-3, 0, -10) m; the RMSE per axis is sqrt(shift^2 + 2 shift mean +
  // rmse^2) with the original mean and RMSE of a few decimetres at most.
  constexpr double kRmseTolerance = 0.5;  // m: the original per-axis RMSE and bias
  EXPECT_NEAR(b.check.rmse_m.z(), kShiftZ, kRmseTolerance);
  EXPECT_NEAR(b.check.rmse_m.x(), kShiftX, kRmseTolerance);
  EXPECT_NEAR(b.check.rmse_m.y(), a.check.rmse_m.y(), kMetres);
  EXPECT_NEAR(b.check.mean_m.z() - a.check.mean_m.z(), -kShiftZ, kMetres);
  EXPECT_NEAR(b.check.mean_m.x() - a.check.mean_m.x(), -kShiftX, kMetres);
  // The control statistics are untouched.
  EXPECT_NEAR(b.control.spatial_rmse_m, a.control.spatial_rmse_m, kMetres);
}

TEST(BlockOptions, InteriorSigmaIsAWeightedObservation) {
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  Project project = ProjectFromFlight(flight);
  calib::Camera& camera = project.cameras.at("cam1");
  camera.interior_sigma = {};
  constexpr double kSigmaC = 0.001;  // mm
  camera.interior_sigma[Model::kC] = kSigmaC;
  const double nominal_c = flight.nominal.interior[Model::kC];

  AdjustOptions weighted = SelfCalibration();
  weighted.use_interior_sigma = true;
  AdjustOptions unweighted = SelfCalibration();
  unweighted.use_interior_sigma = false;
  const AdjustmentResult w = Adjust(project, weighted);
  const AdjustmentResult u = Adjust(project, unweighted);
  ASSERT_TRUE(w.converged());
  ASSERT_TRUE(u.converged());
  ASSERT_EQ(w.cameras.size(), 1u);
  ASSERT_EQ(u.cameras.size(), 1u);
  const CameraEstimate& cw = w.cameras[0];
  const CameraEstimate& cu = u.cameras[0];
  const double truth_c = flight.truth.interior[Model::kC];
  std::printf(
      "c: nominal %.5f truth %.5f mm; with interior_sigma %.5f +- %.5f mm (sigma0 %.4f), "
      "without %.5f +- %.5f mm (sigma0 %.4f)\n",
      nominal_c,
      truth_c,
      cw.estimated[Model::kC],
      cw.sigma[Model::kC],
      w.sigma0,
      cu.estimated[Model::kC],
      cu.sigma[Model::kC],
      u.sigma0);

  // The prior is one scalar observation c = nominal with sigma 0.001 mm. The images alone
  // determine c poorly (no GNSS: c trades with the flying heights), so the weighted mean of the
  // two stays at the prior to well within its 3 sigma.
  const auto* prior = w.solve.Group(calib::kGroupInteriorPrior);
  ASSERT_NE(prior, nullptr);
  EXPECT_EQ(prior->n_observations, 1);
  EXPECT_EQ(prior->n_residual_blocks, 1);
  EXPECT_NEAR(cw.estimated[Model::kC], nominal_c, 3.0 * kSigmaC);
  // a-posteriori sigma = sigma0 * sqrt((1 / sigma_prior^2 + N_images)^-1) <= sigma0 * sigma_prior
  EXPECT_LE(cw.sigma[Model::kC], w.sigma0 * kSigmaC);
  EXPECT_EQ(u.solve.Group(calib::kGroupInteriorPrior), nullptr);
  EXPECT_GT(cu.sigma[Model::kC], 10.0 * cw.sigma[Model::kC]);
  // Exactly (to linearization): adding one observation of c updates the marginal of c like a
  // weighted mean of the image-only estimate (cofactor q_u) and the prior (sigma_p^2):
  // q_w = q_u sigma_p^2 / (q_u + sigma_p^2), c_w = c_p + (c_u - c_p) sigma_p^2 / (q_u + sigma_p^2).
  const double q_u = std::pow(cu.sigma[Model::kC] / u.sigma0, 2);
  const double s2 = kSigmaC * kSigmaC;
  const double sigma_predicted = w.sigma0 * std::sqrt(q_u * s2 / (q_u + s2));
  const double c_predicted = nominal_c + (cu.estimated[Model::kC] - nominal_c) * s2 / (q_u + s2);
  std::printf(
      "with interior_sigma: c - nominal %.3e mm (predicted %.3e), sigma %.8f mm "
      "(predicted %.8f, sigma0 * sigma_prior %.8f)\n",
      cw.estimated[Model::kC] - nominal_c,
      c_predicted - nominal_c,
      cw.sigma[Model::kC],
      sigma_predicted,
      w.sigma0 * kSigmaC);
  // Measured agreement 1e-5 (sigma) and 1e-3 (shift, -5.8e-7 mm); the tolerances allow for the
  // different linearization points (c differs by 0.05 mm between the runs) and the solver's stop.
  constexpr double kSigmaAgreement = 1e-3;  // relative
  constexpr double kShiftAgreement = 1e-2;  // relative to the predicted shift from the prior
  EXPECT_NEAR(cw.sigma[Model::kC], sigma_predicted, kSigmaAgreement * sigma_predicted);
  EXPECT_NEAR(cw.estimated[Model::kC] - nominal_c,
              c_predicted - nominal_c,
              kShiftAgreement * std::abs(c_predicted - nominal_c));
  // One more observation, the same unknowns.
  EXPECT_EQ(w.solve.redundancy, u.solve.redundancy + 1);
}

TEST(BlockOptions, TwoCamerasGetOneInteriorBlockEach) {
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  Project project = ProjectFromFlight(flight);
  project.cameras["cam2"] = flight.nominal;
  // The first strip (the exposures at the first exposure's true Y) is cam1, the rest cam2.
  const double first_strip_y = flight.exposures_truth.front().center_m.y();
  int n_cam1 = 0;
  for (size_t i = 0; i < project.exposures.size(); ++i) {
    ASSERT_EQ(project.exposures[i].image, flight.exposures_truth[i].image);
    const bool first_strip = std::abs(flight.exposures_truth[i].center_m.y() - first_strip_y) < 1.0;
    project.exposures[i].camera = first_strip ? "cam1" : "cam2";
    n_cam1 += first_strip ? 1 : 0;
  }
  const int n_cam2 = static_cast<int>(project.exposures.size()) - n_cam1;
  ASSERT_GT(n_cam1, 2);
  ASSERT_GT(n_cam2, n_cam1);

  const AdjustmentResult r = Adjust(project, SelfCalibration("c,x0,y0,K1,K2"));
  std::printf("%d exposures cam1, %d cam2\n%s", n_cam1, n_cam2, FormatSummary(r).c_str());
  ASSERT_TRUE(r.converged()) << r.solve.message;
  ASSERT_TRUE(r.determinability.covariance_ok) << r.determinability.message;
  ASSERT_EQ(r.cameras.size(), 2u);
  const CameraEstimate* cam1 = FindCamera(r, "cam1");
  const CameraEstimate* cam2 = FindCamera(r, "cam2");
  ASSERT_NE(cam1, nullptr);
  ASSERT_NE(cam2, nullptr);
  for (const CameraEstimate* c : {cam1, cam2}) {
    for (int k = 0; k < Model::kNumParams; ++k) {
      SCOPED_TRACE(c->id + "." + std::string(Model::kParams[k].name));
      const double truth = flight.truth.interior[k];
      if (!c->free[k]) {
        EXPECT_EQ(c->estimated[k], c->initial[k]);
        continue;
      }
      ASSERT_GT(c->sigma[k], 0.0);
      std::printf("%s.%-2s estimate %.6g truth %.6g sigma %.3g (%.2f sigma)\n",
                  c->id.c_str(),
                  std::string(Model::kParams[k].name).c_str(),
                  c->estimated[k],
                  truth,
                  c->sigma[k],
                  (c->estimated[k] - truth) / c->sigma[k]);
      EXPECT_LE(std::abs(c->estimated[k] - truth), 3.0 * c->sigma[k])
          << "estimate " << c->estimated[k] << " truth " << truth << " sigma " << c->sigma[k];
    }
  }
  // cam1 sees one strip of 13 exposures, cam2 two strips of 24: every free parameter of cam1 is
  // less determined. Without GNSS, c of both trades with the flying heights (correlation 0.9999
  // with a centre Z; measured sigma 0.31 / 0.30 mm, held only by the control heights), so its
  // 3-sigma check above is weak and the c sigmas differ by 5 % only; x0, y0, K1, K2 by 1.5-2.4x.
  for (int k = 0; k < Model::kNumParams; ++k)
    if (cam1->free[k]) {
      EXPECT_GT(cam1->sigma[k], cam2->sigma[k]) << Model::kParams[k].name;
    }
}

TEST(BlockOptions, ImuPriorsEnterAsWeightedObservations) {
  FlightSimulationOptions options;
  options.gnss_sigma_m = 0.05;
  options.imu_sigma_deg = 0.005;
  const SimulatedFlight flight = SimulateFlight(options);
  const Project project = ProjectFromFlight(flight);
  const AdjustmentResult r = Adjust(project, SelfCalibration());
  ASSERT_TRUE(r.converged()) << r.solve.message;
  const int n = static_cast<int>(flight.exposures_file.size());
  const auto* prior = r.solve.Group(calib::kGroupEoPrior);
  ASSERT_NE(prior, nullptr);
  // X0, Y0, Z0 from GNSS and omega, phi, kappa from the IMU per exposure.
  EXPECT_EQ(prior->n_observations, 6 * n);
  EXPECT_EQ(prior->n_residual_blocks, 2 * n);

  // The IMU angles are truth + N(0, 0.005 deg); the image rays determine the angles far better
  // (0.2 px over c = 170 mm is 0.0006 deg per ray), so adjusted - IMU is essentially the IMU
  // noise: its normalized RMS over the 3n angles is 1 +- 1/sqrt(2 * 3n) (0.07 for n = 37).
  const double sigma = options.imu_sigma_deg * kRadiansPerDegree;
  double sum_prior = 0.0, sum_truth = 0.0, sum_imu_truth = 0.0, max_prior = 0.0;
  ASSERT_EQ(static_cast<int>(r.exposures.size()), n);
  for (const auto& e : r.exposures) {
    const Exposure* given = project.FindExposure(e.image);
    ASSERT_NE(given, nullptr);
    const Exposure* truth = nullptr;
    for (const auto& t : flight.exposures_truth)
      if (t.image == e.image) truth = &t;
    ASSERT_NE(truth, nullptr);
    for (int k = 0; k < 3; ++k) {
      const double to_prior = WrapAngle(e.opk_rad[k] - given->opk_rad[k]) / sigma;
      const double to_truth = WrapAngle(e.opk_rad[k] - truth->opk_rad[k]) / sigma;
      const double imu_truth = WrapAngle(given->opk_rad[k] - truth->opk_rad[k]) / sigma;
      sum_prior += to_prior * to_prior;
      sum_truth += to_truth * to_truth;
      sum_imu_truth += imu_truth * imu_truth;
      max_prior = std::max(max_prior, std::abs(to_prior));
    }
  }
  const double rms_prior = std::sqrt(sum_prior / (3 * n));
  const double rms_truth = std::sqrt(sum_truth / (3 * n));
  const double rms_imu_truth = std::sqrt(sum_imu_truth / (3 * n));
  std::printf(
      "angles in IMU sigmas (0.005 deg), RMS over %d: adjusted - IMU %.3f (max %.2f), "
      "adjusted - truth %.3f, IMU - truth %.3f; eo_prior rms %.3f, sigma0 %.4f\n",
      3 * n,
      rms_prior,
      max_prior,
      rms_truth,
      rms_imu_truth,
      prior->rms,
      r.sigma0);
  constexpr double kRmsBound = 1.5;  // 1 + 7 standard errors of the RMS for n = 37
  EXPECT_LT(rms_prior, kRmsBound);
  // The adjustment stays closer to the truth than the IMU it was given.
  EXPECT_LT(rms_truth, rms_imu_truth);
}

TEST(BlockOptions, ADatumDefectIsReportedNotHidden) {
  // No control, no GNSS and no free-network datum: seven parameters (the similarity of the whole
  // block) are not determined. The run must say so and name them, not report sigmas.
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  Project project = ProjectFromFlight(flight);
  for (auto& p : project.points)
    if (p.role == PointRole::kControl) p.role = PointRole::kCheck;
  AdjustOptions options;
  options.free_network_datum = false;
  const AdjustmentResult r = Adjust(project, options);
  EXPECT_NE(r.datum.find("datum defect"), std::string::npos) << r.datum;
  EXPECT_FALSE(r.determinability.determinable());
  EXPECT_FALSE(r.determinability.undetermined.empty());
  EXPECT_FALSE(r.determinability.warnings.empty());
  // ~3000 free parameters: found in the reduced system, so the names are exterior parameters (the
  // 7-parameter similarity moves the projection centres most).
  for (const auto& name : r.determinability.undetermined)
    EXPECT_EQ(name.rfind("image ", 0), 0u) << name;
  std::printf(
      "datum defect: %zu undetermined parameter(s) named, e.g. %s; %s\n",
      r.determinability.undetermined.size(),
      r.determinability.undetermined.empty() ? "-" : r.determinability.undetermined.front().c_str(),
      r.determinability.message.c_str());
}

TEST(BlockOptions, SchurCovarianceAgreesWithCeresCovariance) {
  // Above 300 free parameters the builder computes the covariance by eliminating the ground
  // points (Schur complement, sparse LDLT). Here ~3000 parameters: the sigmas of the interior and
  // of an exposure centre must be those of Ceres' own covariance (sparse QR) of the same problem.
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  const Project project = ProjectFromFlight(flight);
  AdjustOptions options = SelfCalibration();
  options.data_snooping = false;
  BlockAdjustment adjustment(project, options);
  const AdjustmentResult r = adjustment.Run();
  ASSERT_TRUE(r.converged());
  ASSERT_TRUE(r.determinability.covariance_ok);
  ASSERT_GT(adjustment.builder().NumFreeParameters(), 300);
  ASSERT_EQ(r.determinability.covariance_method.rfind("schur_", 0), 0u)
      << r.determinability.covariance_method;

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  double* interior = adjustment.builder().BlockValues(adjustment.InteriorBlock("cam1"));
  double* centre = adjustment.builder().BlockValues(adjustment.CenterBlock(r.exposures[18].image));
  const std::vector<std::pair<const double*, const double*>> blocks = {{interior, interior},
                                                                       {centre, centre}};
  ASSERT_TRUE(covariance.Compute(blocks, &adjustment.builder().problem()));
  double q_interior[Model::kNumParams * Model::kNumParams], q_centre[9];
  ASSERT_TRUE(covariance.GetCovarianceBlock(interior, interior, q_interior));
  ASSERT_TRUE(covariance.GetCovarianceBlock(centre, centre, q_centre));
  double worst = 0.0;
  for (int k = 0; k < Model::kNumParams; ++k) {
    const double ceres_sigma = r.sigma0 * std::sqrt(q_interior[k * Model::kNumParams + k]);
    worst = std::max(worst, std::abs(r.cameras[0].sigma[k] / ceres_sigma - 1.0));
  }
  for (int k = 0; k < 3; ++k) {
    const double ceres_sigma = r.sigma0 * std::sqrt(q_centre[4 * k]);
    worst = std::max(worst, std::abs((*r.exposures[18].center_sigma_m)(k) / ceres_sigma - 1.0));
  }
  std::printf("Schur vs Ceres covariance: largest relative sigma difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-3);  // the same matrix inverted two ways: rounding and conditioning only
}

}  // namespace
}  // namespace aerocal::triangulation
