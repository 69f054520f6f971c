// The reported standard deviations of the interior parameters match the spread of the estimates
// over many simulated flights. To keep the test fast the block is reduced (fewer surveyed and tie
// points than the example flight); exposures, camera and noise are those of the example.
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

TEST(BlockAdjustmentMonteCarlo, ReportedSigmasMatchTheSpreadOverFlights) {
  // z = (estimate - truth) / reported sigma has unit standard deviation when the sigmas are right.
  // With n flights the sample standard deviation of z has a standard error of ~1/sqrt(2(n-1)):
  // 0.1 for n = 50, so the 25 % band is 2.5 standard errors wide for each of the 10 parameters.
  constexpr int kFlights = 50;
  constexpr double kTolerance = 0.25;
  std::array<double, Model::kNumParams> sum_z2{};
  int used = 0;
  for (int i = 0; i < kFlights; ++i) {
    FlightSimulationOptions options;
    options.seed = 1000 + i;
    options.ground_points = 60;
    options.tie_points = 200;
    const SimulatedFlight flight = SimulateFlight(options);
    Project project;
    project.cameras["cam1"] = flight.nominal;
    project.exposures = flight.exposures_file;
    project.observations = flight.observations;
    project.points = flight.points_file;
    AdjustOptions adjust;
    adjust.free_interior = ParseSelfCalibration("all");
    adjust.data_snooping = false;  // Gaussian noise only: nothing to reject
    const AdjustmentResult r = Adjust(project, adjust);
    ASSERT_TRUE(r.converged()) << "seed " << options.seed;
    ASSERT_TRUE(r.determinability.covariance_ok) << "seed " << options.seed;
    for (int k = 0; k < Model::kNumParams; ++k) {
      const double z =
          (r.cameras[0].estimated[k] - flight.truth.interior[k]) / r.cameras[0].sigma[k];
      sum_z2[k] += z * z;
    }
    ++used;
  }
  for (int k = 0; k < Model::kNumParams; ++k) {
    // The truth is known, so the spread is about the truth (n degrees of freedom).
    const double spread_over_sigma = std::sqrt(sum_z2[k] / used);
    std::printf("%-3s empirical spread / reported sigma = %.3f\n",
                std::string(Model::kParams[k].name).c_str(),
                spread_over_sigma);
    EXPECT_NEAR(spread_over_sigma, 1.0, kTolerance) << Model::kParams[k].name;
  }
}

}  // namespace
}  // namespace aerocal::triangulation
