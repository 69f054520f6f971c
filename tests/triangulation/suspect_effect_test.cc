// Validity judged by effect (issue 28 part 2).
// - EffectOfLeavingOut on a problem whose answer is known in closed form: the mean of n
//   observations of equal sigma s; leaving out observation k moves the mean by
//   (mean - x_k) / (n - 1), the mean's sigma is s0 s / sqrt(n) (s0 the a-posteriori sigma0 the
//   covariance is scaled by); the builder ends in its state before (values and residuals).
// - On a simulated planar board (the Zhang-like case: the board's design coordinates as control),
//   two corners slightly off the plane: the calibration stays valid and the warning names them
//   (left out, or unresolved with an effect within the limit); the same with the limit at 1e-6
//   sigmas is not valid when they are unresolved; one corner off by 20 survey sigmas is left out,
//   or the run is not valid, as before.
#include "calib/problem/suspect_effect.h"

#include "calib/residuals/prior.h"
#include "triangulation/calibration/calibration.h"
#include "triangulation/simulation/test_field_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace aerocal::triangulation {
namespace {

TEST(EffectOfLeavingOut, TheMeanOfNObservationsMovesAsTheClosedFormSays) {
  const std::vector<double> x = {1.0, 1.2, 0.9, 1.1, 1.05, 0.95, 3.0};
  const double s = 0.1;
  calib::ProblemBuilder builder;
  double mean = 0.0;
  const calib::BlockId b = builder.AddBlock("mean", &mean, 1, calib::BlockKind::kOther, {"m"});
  std::vector<calib::ResidualId> ids;
  for (double xi : x)
    ids.push_back(builder.AddResidual("obs", calib::PriorCostFunction::Create({xi}, {s}), {b}));
  const calib::SolveReport solved = builder.Solve({});
  ASSERT_TRUE(solved.usable);
  const double n = static_cast<double>(x.size());
  double sum = 0.0;
  for (double xi : x) sum += xi;
  ASSERT_NEAR(mean, sum / n, 1e-7);  // the solver's tolerance
  const calib::CovarianceReport cov = builder.EstimateCovariance({b}, solved.sigma0, 0.95);
  ASSERT_TRUE(cov.ok);
  const double sigma_mean = solved.sigma0 * s / std::sqrt(n);
  ASSERT_NEAR(cov.BlockSigma(b, 1)(0), sigma_mean, 1e-9);
  const double before = mean;
  const SuspectEffect e =
      calib::EffectOfLeavingOut(builder, {ids.back()}, cov, {b}, {b}, calib::SolverOptions{}, 1.0);
  ASSERT_TRUE(e.computed) << e.message;
  const double change = (sum / n - x.back()) / (n - 1);
  ASSERT_EQ(e.calibrated.size(), 1u);
  EXPECT_NEAR(e.calibrated[0].change, change, 1e-7);
  EXPECT_NEAR(e.max_sigmas, std::abs(change) / sigma_mean, 1e-4);
  EXPECT_EQ(e.parameter, cov.names[0]);
  // sigma0 carries the outlier too (about 7): the mean moves by about one of its sigmas.
  EXPECT_EQ(e.Matters(), std::abs(change) / sigma_mean > 1.0);
  // The builder is back where it was: the value and every residual.
  EXPECT_EQ(mean, before);
  for (calib::ResidualId id : ids) EXPECT_TRUE(builder.IsActive(id));
  // A suspect within the crowd hardly moves it.
  const SuspectEffect small =
      calib::EffectOfLeavingOut(builder, {ids[3]}, cov, {b}, {b}, calib::SolverOptions{}, 1.0);
  EXPECT_NEAR(small.max_sigmas, std::abs((sum / n - x[3]) / (n - 1)) / sigma_mean, 1e-4);
  EXPECT_FALSE(small.Matters());
  // Without a covariance the effect is unknown, and an unknown effect matters.
  const SuspectEffect unknown = calib::EffectOfLeavingOut(
      builder, {ids[3]}, calib::CovarianceReport{}, {b}, {b}, calib::SolverOptions{}, 1.0);
  EXPECT_FALSE(unknown.computed);
  EXPECT_TRUE(unknown.Matters());
}

// A planar board (one group of 8 images, targets on Y = 0) whose file coordinates of the listed
// targets are off the plane by `off_m` (the truth is planar: the design coordinates are wrong).
struct Board {
  SimulatedTestField field;
  Project project;
  std::vector<std::string> moved;
};
Board PlanarBoard(const std::vector<int>& corners, double off_m, std::uint64_t seed) {
  TestFieldOptions o;
  o.seed = seed;
  o.planar = true;
  o.groups = 1;
  o.images_per_group = 8;
  o.check_every = 0;
  Board b{SimulateTestField(o), {}, {}};
  b.project = TestFieldProject(b.field);
  for (int k : corners) {
    GroundPoint& p = b.project.points.at(k);
    p.xyz_m = *p.xyz_m + Eigen::Vector3d(0.0, off_m, 0.0);
    b.moved.push_back(p.id);
  }
  return b;
}

CalibrationRun CalibrateBoard(const Board& b, double limit) {
  CalibrateOptions options;
  options.adjust.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2");
  options.adjust.suspect_effect_limit = limit;
  options.control_propagation = false;
  return Calibrate(b.project, options, {});
}

bool Names(const AdjustmentResult& r, const std::string& point) {
  for (const auto& w : r.warnings)
    if (w.subject.find(point) != std::string::npos) return true;
  return false;
}

TEST(PlanarBoard, TwoSlightlyNonPlanarCornersAreWarnedNotInvalid) {
  // Two neighbouring corners 10 survey sigmas (5 mm on the 20 m board) off the plane: they fail
  // the survey test and cannot be told apart (seed 11; over seeds 11-13 and 6-14 sigmas the
  // unresolved cases moved the calibrated parameters by 0.26-0.79 of their sigmas, exterior
  // orientations by up to 1.7).
  const Board b = PlanarBoard({0, 1}, 10 * 0.0005, 11);
  const CalibrationRun run = CalibrateBoard(b, 1.0);
  const AdjustmentResult& r = run.all.result;
  ASSERT_TRUE(r.converged());
  ASSERT_EQ(r.snooping.unresolved_surveys.size(), 2u);
  const SuspectEffect& effect = r.snooping.unresolved_effect;
  std::printf("two corners 5 mm off: effect %.3f sigmas at %s (every parameter: %.3f at %s)\n",
              effect.max_sigmas,
              effect.parameter.c_str(),
              effect.max_all_sigmas,
              effect.parameter_all.c_str());
  ASSERT_TRUE(effect.computed) << effect.message;
  EXPECT_EQ(effect.calibrated.size(), 5u);  // c, x0, y0, K1, K2
  EXPECT_LE(effect.max_sigmas, 1.0);
  EXPECT_EQ(effect.parameter.rfind("camera ", 0), 0u) << effect.parameter;
  EXPECT_TRUE(r.valid) << (r.invalid_reasons.empty() ? "" : r.invalid_reasons.front());
  EXPECT_TRUE(Names(r, b.moved[0]) && Names(r, b.moved[1]));
  // The same suspicion with a limit no effect can pass: not valid, by the same rule.
  const CalibrationRun strict = CalibrateBoard(b, 1e-6);
  EXPECT_FALSE(strict.all.result.valid);
}

TEST(PlanarBoard, OneCornerTwentySigmasOffIsLeftOutOrInvalid) {
  const Board b = PlanarBoard({0}, 20 * 0.0005, 11);
  const CalibrationRun run = CalibrateBoard(b, 1.0);
  const AdjustmentResult& r = run.all.result;
  bool left_out = false;
  for (const auto& l : r.control_left_out) left_out = left_out || l.difference.point == b.moved[0];
  EXPECT_TRUE(left_out || !r.valid);
  EXPECT_TRUE(Names(r, b.moved[0]));
}

}  // namespace
}  // namespace aerocal::triangulation
