// Monte-Carlo study of the line-camera calibration (ctest label `long`; run it through
// /work/bin/cpu-long): several simulated flights with the noise (0.25 px image, 0.1 m
// control, POS 5 cm / 0.005 deg), each calibrated; the RMS error of the detector table against
// its predicted sigma over all flights must agree within 30 %, and the recovered dx_i, dy_i must
// lie within 3 sigma of the truth in (almost) every flight.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <gtest/gtest.h>

#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_simulation.h"

namespace aerocal::triangulation {
namespace {

TEST(LineCalibrationStudy, TableErrorMatchesItsPredictedSigma) {
  const int flights = std::getenv("AEROCAL_PUSHBROOM_FLIGHTS")
                          ? std::atoi(std::getenv("AEROCAL_PUSHBROOM_FLIGHTS"))
                          : 12;
  double sum_e2 = 0, sum_s2 = 0;
  int flights_within = 0, n_values = 0;
  for (int f = 0; f < flights; ++f) {
    LineSimulationOptions o;
    o.detectors_per_camera = 300;
    o.lines = 1500;
    o.control_points = 1500;
    o.image_noise_px = o.image_sigma_px = 0.25;
    o.seed = 1000 + f;
    const LineSimulation sim = SimulateLineFlight(o);
    const PosTrajectory pos = PosTrajectory::FromRecords(sim.pos, "pos.csv");
    LineCalibrationOptions options;
    options.degree = 3;  // the model the truth has: the study measures the sigmas, not the test
    const LineCalibrationResult r =
        CalibrateLineCamera(sim.nominal, pos, sim.observations, sim.points, options, "obs");
    ASSERT_TRUE(r.report.converged);
    double worst = 0, fe2 = 0, fs2 = 0;
    for (int i = 0; i < sim.truth.detectors; ++i) {
      const Eigen::Vector2d truth = sim.truth.Correction(i);
      for (int axis = 0; axis < 2; ++axis) {
        const double e = axis ? r.dy_mm[i] - truth.y() : r.dx_mm[i] - truth.x();
        const double s = (axis ? r.dy_sigma_mm[i] : r.dx_sigma_mm[i]).value_or(0.0);
        fe2 += e * e;
        fs2 += s * s;
        if (s > 0) worst = std::max(worst, std::abs(e) / s);
        ++n_values;
      }
    }
    sum_e2 += fe2;
    sum_s2 += fs2;
    flights_within += worst < 3.0;
    std::printf("flight %d: sigma0 %.3f, table RMS error %.4f px, predicted %.4f px, worst %.2f sigma\n",
                f, r.report.sigma0, std::sqrt(fe2 / (2 * sim.truth.detectors)) / sim.truth.pitch_mm,
                std::sqrt(fs2 / (2 * sim.truth.detectors)) / sim.truth.pitch_mm, worst);
  }
  const double ratio = std::sqrt(sum_e2 / sum_s2);
  std::printf("over %d flights: table RMS error / predicted sigma = %.3f; %d flights within 3 sigma\n",
              flights, ratio, flights_within);
  EXPECT_NEAR(ratio, 1.0, 0.3);
  // A flight's table errors are a few polynomial coefficients: its worst |e|/sigma over all
  // detectors exceeds 3 with a few per cent probability; allow one flight in ten.
  EXPECT_GE(flights_within, flights - std::max(1, flights / 10));
  (void)n_values;
}

}  // namespace
}  // namespace aerocal::triangulation
