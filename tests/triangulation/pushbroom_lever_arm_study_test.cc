// Monte-Carlo of the free lever arm (issue 28 part 1; module README "Datum", "The free lever
// arm"; ctest label `long`, ~10 s): the flight of the boresight / lever-arm test (SmallFlight of
// pushbroom_test.cc: 3 x 120 detectors, 800 lines, 700 control points, 0.25 px, POS 5 cm /
// 0.005 deg) with the seeds 1 .. 25, the camera file's lever arm off the truth by (0.5, -0.5,
// 0.5) m, calibrated with the defaults (POS priors, gauge datum: no defect) and
// `--lever-arm free`, per axis: the mean error, the SD of the errors, the mean sigma, the RMS of
// error / sigma and how many flights lie beyond 3 sigma.
// - At the truth's degree (3): the errors follow their sigmas (asserted). With the residual
//   weighted at the start's angles the vertical lever arm was biased by +32.8 m (6 sigma, every
//   flight): line_collinearity.h, pushbroom_gauge_oracle_test.cc (the profile).
// - With the automatic degree (the default): printed. In some flights the test drops a term the
//   lever arm's near-gauge needs (a roll needs x^2 in every sub-camera, like a lever arm across
//   track seen from the height): its sigma collapses (~0.06 m) and it lies many sigma off.
// AEROCAL_LEVER_ARM_FLIGHTS sets the number of flights.
#include "tests/triangulation/pushbroom_flights.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_simulation.h"
#include "triangulation/pushbroom/pos_trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <vector>

namespace aerocal::triangulation {
namespace {

struct AxisFigures {
  double mean_error_m = 0, standard_error_m = 0, sd_m = 0, mean_sigma_m = 0, rms_ratio = 0;
  int beyond_3_sigma = 0, n = 0;
};

// The lever arm's errors and sigmas over the flights, per axis, with `degree` (none: automatic).
std::vector<AxisFigures> Study(std::optional<int> degree) {
  const int flights = std::getenv("AEROCAL_LEVER_ARM_FLIGHTS")
                          ? std::atoi(std::getenv("AEROCAL_LEVER_ARM_FLIGHTS"))
                          : 25;
  std::vector<std::vector<double>> errors(3), sigmas(3);
  for (int f = 0; f < flights; ++f) {
    const LineSimulationOptions o = SmallFlight(1 + f);
    LineSimulation sim = SimulateLineFlight(o);
    sim.nominal.lever_arm_m = sim.truth.lever_arm_m + Eigen::Vector3d(0.5, -0.5, 0.5);
    LineCalibrationOptions options;
    options.lever_arm = PlatformParamMode::kFree;
    options.degree = degree;
    const PosTrajectory pos = PosTrajectory::FromRecords(sim.pos, "pos.csv");
    const LineCalibrationResult r =
        CalibrateLineCamera(sim.nominal, pos, sim.observations, sim.points, options, "obs");
    EXPECT_TRUE(r.report.converged) << "seed " << o.seed;
    if (!r.lever_arm_sigma_m) {
      ADD_FAILURE() << "seed " << o.seed << ": no lever-arm sigma";
      continue;
    }
    std::printf("  seed %2d: sigma0 %.4f,", int(o.seed), r.report.sigma0);
    for (int a = 0; a < 3; ++a) {
      const double e = r.lever_arm_m[a] - sim.truth.lever_arm_m[a], s = (*r.lever_arm_sigma_m)[a];
      errors[a].push_back(e);
      sigmas[a].push_back(s);
      std::printf(" %c %+7.3f +- %5.3f m (%+6.2f sigma)", "xyz"[a], e, s, e / s);
    }
    std::printf("\n");
  }
  std::vector<AxisFigures> out(3);
  for (int a = 0; a < 3; ++a) {
    AxisFigures& x = out[a];
    x.n = int(errors[a].size());
    double sum_ratio2 = 0;
    for (int k = 0; k < x.n; ++k) {
      x.mean_error_m += errors[a][k] / x.n;
      x.mean_sigma_m += sigmas[a][k] / x.n;
      const double ratio = errors[a][k] / sigmas[a][k];
      sum_ratio2 += ratio * ratio;
      x.beyond_3_sigma += std::abs(ratio) > 3;
    }
    for (double e : errors[a]) x.sd_m += (e - x.mean_error_m) * (e - x.mean_error_m);
    x.sd_m = std::sqrt(x.sd_m / std::max(1, x.n - 1));
    x.standard_error_m = x.sd_m / std::sqrt(double(std::max(1, x.n)));
    x.rms_ratio = std::sqrt(sum_ratio2 / std::max(1, x.n));
    std::printf(
        "lever arm %c: mean error %+.3f m (standard error %.3f), SD of the errors %.3f m, mean "
        "sigma %.3f m, RMS error / sigma %.2f, beyond 3 sigma %d of %d\n",
        "xyz"[a],
        x.mean_error_m,
        x.standard_error_m,
        x.sd_m,
        x.mean_sigma_m,
        x.rms_ratio,
        x.beyond_3_sigma,
        x.n);
  }
  return out;
}

TEST(LeverArmStudy, AtTheTruthsDegreeTheErrorsFollowTheirSigmas) {
  std::printf("degree 3 (the truth's):\n");
  for (const AxisFigures& x : Study(3)) {
    // No bias: the mean error within 3 of its standard errors (measured: within 0.8).
    EXPECT_LT(std::abs(x.mean_error_m), 3 * x.standard_error_m);
    // The spread is the sigmas' (measured 0.89 .. 0.94; 25 flights: +-0.28 at 2 SD).
    EXPECT_GT(x.rms_ratio, 0.6);
    EXPECT_LT(x.rms_ratio, 1.4);
    EXPECT_LE(x.beyond_3_sigma, 1);
  }
}

TEST(LeverArmStudy, WithTheAutomaticDegreeMeasured) {
  std::printf("automatic degree (the default):\n");
  const std::vector<AxisFigures> figures = Study(std::nullopt);
  // The vertical lever arm is no longer biased (was +32.8 m); the degree test's collapsed sigmas
  // are measured, not asserted (module README).
  EXPECT_LT(std::abs(figures[2].mean_error_m), 3 * figures[2].standard_error_m);
}

}  // namespace
}  // namespace aerocal::triangulation
