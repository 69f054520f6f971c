// Study of the rig bundle over many simulated dual-lens flights (label `long`, not in the default
// suite): the reported sigmas of head B's mount and lever arm against the spread of the estimates
// around the truth over N seeded flights (issue 13: N >= 20, within 25 %), and the share of
// estimates within 3 sigmas. N = AEROCAL_RIG_FLIGHTS (default 40).
#include "tests/support/rig_flight_project.h"
#include "triangulation/block/block_io.h"
#include "triangulation/sensor/rig_head_camera.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace aerocal::triangulation {
namespace {

TEST(RigBundleStudy, SigmasAgreeWithTheSpreadOfSimulatedFlights) {
  const char* env = std::getenv("AEROCAL_RIG_FLIGHTS");
  const int flights = env ? std::atoi(env) : 40;
  ASSERT_GE(flights, 20);
  // Six parameters: mount omega, phi, kappa (rad), lever arm tx, ty, tz (m).
  Eigen::Matrix<double, 6, 1> sum_error2 = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> sum_sigma2 = Eigen::Matrix<double, 6, 1>::Zero();
  int within = 0, total = 0;
  double sigma0_sum = 0.0;
  for (int seed = 1; seed <= flights; ++seed) {
    RigFlightSimulationOptions o;
    o.interior_correction = {calib::InteriorParams{}};
    o.flight.seed = seed;
    const SimulatedRigFlight f = SimulateRigFlight(o);
    const Project p = testing::RigFlightProject(f, f.nominal);
    AdjustOptions options;
    options.data_snooping = false;  // clean simulated data; the spread is the question here
    const RigAdjustmentResult r = AdjustRig(p, options, {});
    ASSERT_TRUE(r.adjustment.valid) << "seed " << seed;
    const RigHeadEstimate& b = r.heads[1];
    const calib::RigHead& truth = f.truth.heads[1];
    Eigen::Matrix<double, 6, 1> error, sigma;
    error << b.mount_rad - truth.mount_rad, b.lever_arm_m - truth.lever_arm_m;
    sigma << *b.mount_sigma_rad, *b.lever_arm_sigma_m;
    sum_error2 += error.cwiseAbs2();
    sum_sigma2 += sigma.cwiseAbs2();
    for (int i = 0; i < 6; ++i) within += std::abs(error(i)) <= 3.0 * sigma(i);
    total += 6;
    sigma0_sum += r.adjustment.sigma0;
  }
  const Eigen::Matrix<double, 6, 1> spread = (sum_error2 / flights).cwiseSqrt();
  const Eigen::Matrix<double, 6, 1> sigma = (sum_sigma2 / flights).cwiseSqrt();
  const char* names[6] = {"omega", "phi", "kappa", "tx", "ty", "tz"};
  for (int i = 0; i < 6; ++i) {
    std::printf("head B %-5s  spread %.4g  reported sigma %.4g  ratio %.3f\n",
                names[i],
                spread(i),
                sigma(i),
                spread(i) / sigma(i));
    // Within 25 % (issue 13); the sample spread of N flights is itself uncertain by
    // 1 / sqrt(2 N) (11 % at N = 40).
    EXPECT_NEAR(spread(i) / sigma(i), 1.0, 0.25) << names[i];
  }
  std::printf("%d flights: %d of %d estimates within 3 sigma, mean sigma0 %.4f\n",
              flights,
              within,
              total,
              sigma0_sum / flights);
  EXPECT_GE(within, static_cast<int>(std::floor(0.98 * total)));
}

}  // namespace
}  // namespace aerocal::triangulation
