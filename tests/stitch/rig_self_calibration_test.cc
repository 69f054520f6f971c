// Self-calibrating stitching of the four-head rig (stitch/rig/self_calibration.h) on lines of the
// uav4 simulator: noise-free recovery, noisy recovery within 3 sigma, the before/after RMS of the
// paper's kind and its noise floor (why 1.55 x the tie noise), sigmas against the spread over seeds
// (pooled), the dT-rotation correlation of the per-exposure mode, a planted wrong tie.
#include "stitch/rig/self_calibration.h"
#include "tests/stitch/rig_stitch_line.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace aerocal::stitch {
namespace {

using triangulation::RigFlightSimulationOptions;
using triangulation::SimulatedRigFlight;
using Inputs = testing::RigStitchInputs;
using testing::InputsFromFlight;

RigFlightSimulationOptions Line(std::uint64_t seed, int exposures) {
  return testing::Uav4Line(seed, exposures);
}

RigStitchResult Stitch(const SimulatedRigFlight& f,
                       const Inputs& in,
                       RigStitchOptions options = {}) {
  return SelfCalibrateRigStitching(
      f.truth, in.exposures, in.ties, in.observations, in.positions, options);
}

TEST(RigSelfCalibration, NoiseFreeFlatTerrainExactPosRecoversTheIncrements) {
  RigFlightSimulationOptions o = Line(3, 3);
  o.flight.image_noise_px = 0.0;
  o.flight.terrain_relief_m = 0.0;
  o.flight.gnss_sigma_m = 1e-9;
  o.flight.imu_sigma_deg = 1e-12;
  SimulatedRigFlight f = triangulation::SimulateRigFlight(o);
  f.exposures_file = f.exposures_truth;                                  // exact POS
  for (auto& e : f.exposures_file) e.z_ref_m = o.flight.terrain_base_m;  // the flat terrain
  const Inputs in = InputsFromFlight(f);
  RigStitchOptions options;
  options.snooping = false;
  const RigStitchResult r = Stitch(f, in, options);
  ASSERT_TRUE(r.report.usable) << r.report.termination << ": " << r.report.message;
  constexpr double kTolDeg = 1e-6;  // the noise-free bound
  for (size_t i = 0; i < r.exposures.size(); ++i)
    for (size_t k = 0; k < 4; ++k) {
      const auto& truth = f.rig_exposures[i * 4 + k];
      const RigStitchHead& h = r.exposures[i].heads[k];
      EXPECT_LT((h.increment_rad - truth.increment_rad).cwiseAbs().maxCoeff() * 180 / M_PI, kTolDeg)
          << r.exposures[i].image << " " << h.head;
      // dT over 3 exposures correlates with an angle beyond the 0.95 threshold, so it may be
      // reported as not determinable; where it is reported it must be right.
      if (h.dt_s) {
        EXPECT_NEAR(*h.dt_s, truth.dt_s, 1e-7) << h.head;
      }
    }
  EXPECT_LT(r.after.fit.per_coordinate, 1e-4);
  EXPECT_GT(r.before.fit.per_coordinate, 0.5);
}

TEST(RigSelfCalibration, NoisyLineWithinThreeSigmaAndThePapersBeforeAfter) {
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(Line(11, 8));
  const Inputs in = InputsFromFlight(f);
  const RigStitchResult r = Stitch(f, in);
  ASSERT_TRUE(r.report.converged) << r.report.message;
  EXPECT_FALSE(r.stopped);
  EXPECT_NEAR(r.sigma0, 1.0, 3.0 / std::sqrt(2.0 * r.redundancy) + 0.05);
  int outside = 0, n = 0;
  for (size_t i = 0; i < r.exposures.size(); ++i)
    for (size_t k = 1; k < 4; ++k) {
      const RigStitchHead& h = r.exposures[i].heads[k];
      for (int a = 0; a < 3; ++a, ++n)
        outside += std::abs(h.increment_rad[a] - f.rig_exposures[i * 4 + k].increment_rad[a]) >
                   3 * h.increment_sigma_rad[a];
    }
  EXPECT_LE(outside, 1 + n / 100) << "of " << n << " angles beyond 3 sigma";
  for (size_t k = 1; k < 4; ++k) {
    const RigStitchHead& h = r.exposures[0].heads[k];
    ASSERT_TRUE(h.dt_s && h.dt_sigma_s) << h.head;
    EXPECT_LT(std::abs(*h.dt_s - f.rig_exposures[k].dt_s), 3 * *h.dt_sigma_s) << h.head;
  }
  // About 2 px before (ground calibration alone), about 1.3 x the tie noise after (per coordinate).
  EXPECT_GT(r.before.fit.per_coordinate, 1.0);
  EXPECT_LT(r.before.fit.per_coordinate, 4.0);
  EXPECT_GT(r.after.fit.per_coordinate, 0.8 * 0.3);
  EXPECT_LT(r.after.fit.per_coordinate, 2.0 * 0.3);
  EXPECT_LT(r.after.check.per_coordinate, 2.5 * 0.3);
  EXPECT_NEAR(r.after.fit.pair_2d / r.after.fit.per_coordinate, std::sqrt(2.0), 1e-12);
  std::printf("before %.3f / %.3f px, after %.3f / %.3f px (fit / check, per coordinate)\n",
              r.before.fit.per_coordinate,
              r.before.check.per_coordinate,
              r.after.fit.per_coordinate,
              r.after.check.per_coordinate);
  // Why "after" is ~1.55 x the 0.3 px tie noise, not the paper's ~1.3 x: the metric. A pair
  // compares TWO measured rays (sqrt 2) carried into the level virtual image, where a tilted
  // head's pixel covers more than one virtual pixel. The noise alone, propagated, predicts the
  // after figure; the true increments give the same floor (relief and POS noise add little).
  const testing::PairMetricFloor floor = testing::PairFloor(f, in);
  std::printf(
      "pair metric floor: noise prediction %.3f px (mean scale %.3f virtual px per head "
      "px), true parameters %.3f px; after / prediction %.3f\n",
      floor.noise_prediction,
      floor.mean_scale,
      floor.truth_parameters,
      r.after.fit.per_coordinate / floor.noise_prediction);
  constexpr double kFloorTolerance = 0.10;  // the fit absorbs ~1 % (9 of ~1400 dof per exposure),
                                            // relief and POS noise add a few %
  EXPECT_NEAR(r.after.fit.per_coordinate / floor.noise_prediction, 1.0, kFloorTolerance);
  EXPECT_NEAR(floor.truth_parameters / floor.noise_prediction, 1.0, kFloorTolerance);
  EXPECT_GT(floor.noise_prediction / 0.3, std::sqrt(2.0)) << "two rays at >= 1 virtual px each";
}

// The reported sigmas against the spread of the estimates over simulated lines, pooled (the
// default-suite version of the study in rig_self_calibration_study_test.cc): z = (estimate -
// truth) / sigma over 8 seeds x 2 exposures x 9 angles; RMS(z) = 1 when the sigmas are right.
TEST(RigSelfCalibration, SigmasMatchTheSpreadOverSeedsPooled) {
  double z2 = 0.0;
  int n = 0;
  for (std::uint64_t seed = 100; seed < 108; ++seed) {
    const SimulatedRigFlight f = triangulation::SimulateRigFlight(Line(seed, 2));
    RigStitchOptions options;
    options.snooping = false;
    const RigStitchResult r = Stitch(f, InputsFromFlight(f), options);
    ASSERT_TRUE(r.report.converged && r.failures.empty()) << seed;
    for (size_t i = 0; i < r.exposures.size(); ++i)
      for (size_t k = 1; k < 4; ++k)
        for (int a = 0; a < 3; ++a, ++n) {
          const RigStitchHead& h = r.exposures[i].heads[k];
          const double z = (h.increment_rad[a] - f.rig_exposures[i * 4 + k].increment_rad[a]) /
                           h.increment_sigma_rad[a];
          z2 += z * z;
        }
  }
  // 144 values, partly correlated within an exposure: RMS(z) has a spread of ~0.06-0.1; the issue
  // asks for 25 %.
  constexpr double kTolerance = 0.25;
  const double rms_z = std::sqrt(z2 / n);
  std::printf("RMS of (estimate - truth) / sigma over %d angles: %.3f\n", n, rms_z);
  EXPECT_NEAR(rms_z, 1.0, kTolerance);
}

TEST(RigSelfCalibration, PerExposureModeNamesTheDtRotationCorrelation) {
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(Line(5, 3));
  RigStitchOptions options;
  options.mode = RigStitchMode::kPerExposure;
  options.snooping = false;
  const RigStitchResult r = Stitch(f, InputsFromFlight(f), options);
  ASSERT_TRUE(r.report.usable) << r.report.message;
  ASSERT_FALSE(r.dt_correlations.empty());
  double largest = 0.0;
  for (const auto& c : r.dt_correlations) {
    largest = std::max(largest, std::abs(c.rho));
    EXPECT_EQ(c.dt.rfind("dT[", 0), 0u);
    EXPECT_EQ(c.angle.rfind("E[", 0), 0u);
  }
  std::printf("largest |rho| dT-angle per exposure: %.4f\n", largest);
  EXPECT_GT(largest, 0.9);
}

TEST(RigSelfCalibration, PlantedWrongTieIsRejectedWithoutEmptyingAStandardPosition) {
  SimulatedRigFlight f = triangulation::SimulateRigFlight(Line(7, 2));
  Inputs in = InputsFromFlight(f);
  // A wrong match: 8 px off in head C of a fitted tie seen by three heads (with two, either ray
  // could be the wrong one: no test can tell them apart).
  std::map<int, int> rays;
  for (const auto& o : in.observations) ++rays[o.tie];
  int planted = -1;
  for (size_t o = 0; o < in.observations.size() && planted < 0; ++o)
    if (!in.ties[in.observations[o].tie].check && in.observations[o].head == 2 &&
        rays[in.observations[o].tie] >= 3)
      planted = o;
  ASSERT_GE(planted, 0);
  in.observations[planted].pixel += Eigen::Vector2d(6.0, -5.0);
  const RigStitchResult r = Stitch(f, in);
  ASSERT_TRUE(r.report.converged);
  ASSERT_FALSE(r.rejected.empty());
  EXPECT_NE(std::find(r.rejected.begin(), r.rejected.end(), in.observations[planted].label),
            r.rejected.end());
  for (const auto& s : r.standard_positions) EXPECT_GE(s.ties_after, 1) << s.image << " " << s.name;
  EXPECT_GE(r.standard_positions.size(), 2u * 12u - 2u);
}

}  // namespace
}  // namespace aerocal::stitch
