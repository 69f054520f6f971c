// Monte-Carlo study of the line-camera calibration (ctest label `long`, ~2 min): simulated flights
// with the noise (0.25 px image, 0.1 m control, POS 5 cm / 0.005 deg) and three sizes of
// per-detector errors, each calibrated with the defaults (the degree test) and at the truth's
// degree; the RMS error of the detector table against its predicted sigma over all flights must
// agree within 30 %, and the recovered dx_i, dy_i must lie within the 1 % simultaneous band of
// their curves (Scheffe) in (almost) every flight; how many flights stay within pointwise 3 sigma
// is printed. AEROCAL_PUSHBROOM_FLIGHTS sets the number of flights (30), AEROCAL_PUSHBROOM_VERBOSE
// prints each.
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace aerocal::triangulation {
namespace {

struct StudyFigures {
  double ratio = 0.0;  // table RMS error / predicted sigma over all flights
  int flights = 0, within_3_sigma = 0, within_band = 0;
};

// `flights` simulated flights (seeds 1000..) with per-detector errors of `amplitude_px`, each
// calibrated with `options`.
StudyFigures Study(double amplitude_px, const LineCalibrationOptions& options, const char* label) {
  const int flights = std::getenv("AEROCAL_PUSHBROOM_FLIGHTS")
                          ? std::atoi(std::getenv("AEROCAL_PUSHBROOM_FLIGHTS"))
                          : 30;
  // The worst |e| / sigma over a whole polynomial curve is a supremum, not one value: with k free
  // coefficients it stays below sqrt(chi2_k(1 %)) (Scheffe's band) in 99 % of the curves. For the
  // degree-3 polynomials (k = 4): sqrt(13.28) = 3.64; pointwise 3 sigma is exceeded somewhere on
  // one of the six curves in 11 of 100 flights (README "Measured") even at the truth's degree.
  const double kScheffeBound = std::sqrt(13.28);
  double sum_e2 = 0, sum_s2 = 0;
  StudyFigures out;
  out.flights = flights;
  for (int f = 0; f < flights; ++f) {
    LineSimulationOptions o;
    o.detectors_per_camera = 300;
    o.lines = 1500;
    o.control_points = 1500;
    o.image_noise_px = o.image_sigma_px = 0.25;
    o.detector_error_px = amplitude_px;
    o.seed = 1000 + f;
    const LineSimulation sim = SimulateLineFlight(o);
    const PosTrajectory pos = PosTrajectory::FromRecords(sim.pos, "pos.csv");
    const LineCalibrationResult r =
        CalibrateLineCamera(sim.nominal, pos, sim.observations, sim.points, options, "obs");
    EXPECT_TRUE(r.report.converged) << label << " flight " << f;
    double worst = 0, fe2 = 0, fs2 = 0;
    for (int i = 0; i < sim.truth.detectors; ++i) {
      const Eigen::Vector2d truth = sim.truth.Correction(i);
      for (int axis = 0; axis < 2; ++axis) {
        const double e = axis ? r.dy_mm[i] - truth.y() : r.dx_mm[i] - truth.x();
        const double s = (axis ? r.dy_sigma_mm[i] : r.dx_sigma_mm[i]).value_or(0.0);
        fe2 += e * e;
        fs2 += s * s;
        if (s > 0) worst = std::max(worst, std::abs(e) / s);
      }
    }
    sum_e2 += fe2;
    sum_s2 += fs2;
    out.within_3_sigma += worst < 3.0;
    out.within_band += worst < kScheffeBound;
    if (std::getenv("AEROCAL_PUSHBROOM_VERBOSE"))
      std::printf(
          "%s flight %d: sigma0 %.3f, table RMS error %.4f px, predicted %.4f px, worst %.2f "
          "sigma\n",
          label,
          f,
          r.report.sigma0,
          std::sqrt(fe2 / (2 * sim.truth.detectors)) / sim.truth.pitch_mm,
          std::sqrt(fs2 / (2 * sim.truth.detectors)) / sim.truth.pitch_mm,
          worst);
  }
  out.ratio = std::sqrt(sum_e2 / sum_s2);
  std::printf(
      "%s, errors %.1f px, %d flights: table RMS error / predicted sigma = %.3f; %d flights "
      "within 3 sigma, %d within the 1 %% band\n",
      label,
      amplitude_px,
      flights,
      out.ratio,
      out.within_3_sigma,
      out.within_band);
  return out;
}

// The sigmas must predict the errors within 30 % (the issue; `lowest`: a bound below 0.7 where
// the sigma is knowingly conservative), and the curves stay within their 1 % simultaneous band in
// (almost) every flight: six curves per flight at 1 % each, about 6 % of the flights leave it;
// allow one in ten.
void ExpectHonest(const StudyFigures& f, double lowest = 0.7) {
  EXPECT_LE(f.ratio, 1.3);
  EXPECT_GE(f.ratio, lowest);
  EXPECT_GE(f.within_band, f.flights - std::max(1, f.flights / 10));
}

// The default: the degree chosen by the test, the table sigmas SelectedTableSigma. Per-detector
// errors of 0 (a camera whose file already holds its calibration), 0.5 px (the simulator's
// default: cubics at their detection limit, the pre-test's worst case) and 2 px (strong terms).
// With errors of 0 the test drops every term of most curves: their table is zero and exact, while
// its sigma stays the start-degree fit's (the data cannot tell the curve from zero any better):
// 0.66 over 30 flights, conservative by design (line_degree_choice.h), not optimistic. Since the
// datum comes from the null space (issue 28), the reference sub-camera's curves are tested and
// dropped like the others (the reference datum pinned them): 0.477 over the same 30 flights, and
// the floor of this case 0.45 (a floor against gross over-statement; every value below 1 is
// conservative).
class LineCalibrationStudy : public ::testing::TestWithParam<double> {};

TEST_P(LineCalibrationStudy, AutomaticDegreeTableErrorMatchesItsPredictedSigma) {
  ExpectHonest(Study(GetParam(), LineCalibrationOptions{}, "automatic degree"),
               GetParam() == 0.0 ? 0.45 : 0.7);
}

// The oracle: the truth's degree (3) given, no test; the study measures the sigmas alone.
TEST_P(LineCalibrationStudy, TruthDegreeTableErrorMatchesItsPredictedSigma) {
  LineCalibrationOptions options;
  options.degree = 3;
  ExpectHonest(Study(GetParam(), options, "degree 3"));
}

INSTANTIATE_TEST_SUITE_P(DetectorErrors, LineCalibrationStudy, ::testing::Values(0.0, 0.5, 2.0));

}  // namespace
}  // namespace aerocal::triangulation
