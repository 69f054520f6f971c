// The pushbroom datum from the null space (issue 28 part 1; module README "Datum"): on flights
// whose every sub-camera has its own offset, scale, rotation and curvature error, for both layouts
// (the `subcameras` design, and the sub-cameras as polynomial ranges of one straight virtual CCD):
// - the rank defect of the normal matrix without a datum equals the number of constraints the
//   gauge datum adds, per configuration, and the constrained problem has full rank with the same
//   fit (v^T P v) as the datum-free one;
// - the tables of any two valid datum choices (reference 0, 1, 2) are equal modulo the gauge (a
//   rotation of the camera frame, and with c free its scale) to 1e-6 px on data without error;
//   with noise to the non-closure of the degree-5 table under the finite rotation between them
//   (~1e-4 px; pushbroom_gauge_oracle_test.cc proves that no datum on the reference does better);
// - the default datum equals `--datum none` with POS priors (no defect: nothing is held), and is
//   within a few sigma of the truth; the earlier reference datum fits worse (it holds functions
//   the data determine).
#include "calib/camera/rotation.h"
#include "tests/triangulation/pushbroom_flights.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_simulation.h"
#include "triangulation/pushbroom/pos_trajectory.h"
#include "triangulation/sensor/line_scan_camera.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

namespace aerocal::triangulation {
namespace {

LineCalibrationResult Calibrate(const LineSimulation& sim, const LineCalibrationOptions& options) {
  const PosTrajectory pos = PosTrajectory::FromRecords(sim.pos, "pos.csv");
  return CalibrateLineCamera(
      sim.nominal, pos, sim.observations, sim.points, options, "observations.csv");
}

// Detector directions of a calibrated table: (x_i, y_i, -c) with x_i, y_i = design + table (mm).
struct Table {
  std::vector<Eigen::Vector3d> ray;
  double c = 0;
};
Table TableOf(const calib::LineCamera& design,
              const std::vector<double>& dx,
              const std::vector<double>& dy,
              double c) {
  Table t;
  t.c = c;
  for (int i = 0; i < design.detectors; ++i) {
    const Eigen::Vector2d p = design.DesignPosition(i);
    t.ray.emplace_back(p.x() + dx[i], p.y() + dy[i], -c);
  }
  return t;
}
Table TableOf(const LineCalibrationResult& r, const calib::LineCamera& design) {
  return TableOf(design, r.dx_mm, r.dy_mm, r.c_mm);
}
Table TruthTable(const LineSimulation& sim) {
  std::vector<double> dx, dy;
  for (int i = 0; i < sim.truth.detectors; ++i) {
    dx.push_back(sim.truth.Correction(i).x());
    dy.push_back(sim.truth.Correction(i).y());
  }
  return TableOf(sim.nominal, dx, dy, sim.truth.c_mm);
}

// b's detector rays turned by the camera rotation R(angles) and projected into a's focal plane
// (principal distance a.c), minus a's positions, px (x then y per detector).
Eigen::VectorXd RotatedDifference(const Table& a,
                                  const Table& b,
                                  const Eigen::Vector3d& angles,
                                  double pitch_mm) {
  const Eigen::Matrix3d r = calib::RotationFromOpk(angles);
  Eigen::VectorXd out(2 * a.ray.size());
  for (size_t i = 0; i < a.ray.size(); ++i) {
    const Eigen::Vector3d d = r * b.ray[i];
    out(2 * i) = (-a.c * d.x() / d.z() - a.ray[i].x()) / pitch_mm;
    out(2 * i + 1) = (-a.c * d.y() / d.z() - a.ray[i].y()) / pitch_mm;
  }
  return out;
}

// The difference of two tables modulo the gauge: the camera rotation that maps b onto a best
// (Gauss-Newton, the exact rotation, not its first order), and the scale through each table's c.
// Returns the remaining difference, px.
Eigen::VectorXd ModuloGauge(const Table& a,
                            const Table& b,
                            double pitch_mm,
                            Eigen::Vector3d* angles_out = nullptr) {
  Eigen::Vector3d angles = Eigen::Vector3d::Zero();
  for (int iteration = 0; iteration < 10; ++iteration) {
    const Eigen::VectorXd f = RotatedDifference(a, b, angles, pitch_mm);
    Eigen::MatrixXd j(f.size(), 3);
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d h = angles;
      h[k] += 1e-7;
      j.col(k) = (RotatedDifference(a, b, h, pitch_mm) - f) / 1e-7;
    }
    angles -= j.colPivHouseholderQr().solve(f);
  }
  if (angles_out) *angles_out = angles;
  return RotatedDifference(a, b, angles, pitch_mm);
}

struct Config {
  const char* name;
  bool pos_prior, free_c;
  PlatformParamMode boresight, lever_arm;
  int expected_defect;  // from the math (module README "Datum"); -1: measured only
};

// Exact gauges on the linear layout (its gauge functions are polynomials of degree <= 2 in u):
// with the POS priors every node is anchored, so only what the camera itself can trade is free:
// c against the focal plane's scale (1), a free boresight against the table's rotations (3).
// Without the priors the trajectory's constant attitude is a rotation of the camera too: measured.
const Config kConfigs[] = {
    {"priors", true, false, PlatformParamMode::kFixed, PlatformParamMode::kFixed, 0},
    {"priors, c free", true, true, PlatformParamMode::kFixed, PlatformParamMode::kFixed, 1},
    {"priors, boresight free", true, false, PlatformParamMode::kFree, PlatformParamMode::kFixed, 3},
    {"priors, boresight and c free",
     true,
     true,
     PlatformParamMode::kFree,
     PlatformParamMode::kFixed,
     4},
    {"priors, lever arm free", true, false, PlatformParamMode::kFixed, PlatformParamMode::kFree, 0},
    {"no priors", false, false, PlatformParamMode::kFixed, PlatformParamMode::kFixed, 3},
    {"no priors, c free", false, true, PlatformParamMode::kFixed, PlatformParamMode::kFixed, 4},
    {"no priors, boresight free",
     false,
     false,
     PlatformParamMode::kFree,
     PlatformParamMode::kFixed,
     6},
};

LineCalibrationOptions OptionsOf(const Config& config) {
  LineCalibrationOptions options;
  options.pos_prior = config.pos_prior;
  options.free_c = config.free_c;
  options.boresight = config.boresight;
  options.lever_arm = config.lever_arm;
  options.degree = 3;  // the truth's degree; no test, so every datum fits the same model
  return options;
}

void PrintDatum(const char* what, const LineCalibrationResult& r) {
  std::printf("%s: defect %d, constraints %d, in table %d, eigenvalues",
              what,
              r.datum.rank_defect,
              r.datum.n_constraints,
              r.datum.in_table);
  for (size_t k = 0; k < r.datum.smallest_relative_eigenvalues.size() && k < 10; ++k)
    std::printf(" %.1e", r.datum.smallest_relative_eigenvalues[k]);
  std::printf(", gauge:");
  for (const auto& d : r.datum.directions) std::printf(" %s (%.9f)", d.name.c_str(), d.fraction);
  std::printf(", sigma0 %.6f, vtpv %.6f, c %.6f, %d iterations (%s)\n",
              r.report.sigma0,
              r.report.vtpv,
              r.c_mm,
              r.report.iterations,
              r.report.termination.c_str());
}

class GaugeDatum : public ::testing::TestWithParam<bool> {};

// The gauge directions are null directions of the model (the table functions of a camera rotation
// or scale), and the angular residual (calib/residuals/line_ray_angle.h) makes them exact: their
// relative eigenvalues lie at the numerical floor on the linear layout (1e-16) and below 1.5e-10
// on the sub-camera design (whose tilted design is not a polynomial in u: degree 3 represents its
// gauge functions approximately), against >= 1.9e-2 for every determined direction with the
// boresight and lever arm fixed, but only 4.4e-5 for the lever arm free (its vertical component is
// nearly a scale of the table, told apart by the relief). Without the priors the exact gauges (the
// three rotations of the trajectory's attitude against the table, the scale with c, the mount
// against the attitude) are followed by the trajectory's weak directions from 7.5e-7 (position
// against attitude). A time offset without the priors is a near-gauge at 2.1e-8 (TimeOffset below).
// The default threshold 1e-7 lies a factor 4 or more from both sides in every configuration, so
// the defect is asserted with and without the priors (module README "Datum").
constexpr double kGaugeFloor = 1e-9;  // the gauge directions' eigenvalues lie below it (measured)
constexpr double kMargin = 4.0;       // eigenvalue ratio to the threshold on either side, at least

TEST_P(GaugeDatum, RankDefectEqualsTheConstraintsPerConfiguration) {
  const bool linear = GetParam();
  const LineSimulation sim = SimulateLineFlight(DatumFlight(linear, 11));
  for (const Config& config : kConfigs) {
    LineCalibrationOptions options = OptionsOf(config);
    options.datum = LineDatum::kNone;
    const LineCalibrationResult none = Calibrate(sim, options);
    options.datum = LineDatum::kGauge;
    const LineCalibrationResult gauge = Calibrate(sim, options);
    std::printf("%s layout, %s\n", linear ? "linear" : "subcameras", config.name);
    PrintDatum("  none ", none);
    PrintDatum("  gauge", gauge);
    ASSERT_TRUE(none.datum.null_space_computed) << config.name;
    EXPECT_TRUE(gauge.report.converged) << config.name;
    const int k = none.datum.rank_defect;
    if (config.expected_defect >= 0) {
      EXPECT_EQ(k, config.expected_defect) << config.name;
      const auto& e = none.datum.smallest_relative_eigenvalues;
      EXPECT_GT(e[k], kMargin * none.datum.threshold) << config.name;
      if (k > 0) {
        EXPECT_LT(e[k - 1], none.datum.threshold / kMargin) << config.name;
        EXPECT_LT(std::abs(e[k - 1]), kGaugeFloor) << config.name;
      }
    }
    // The datum adds exactly the defect, and the problem with it has full rank: a covariance
    // without undetermined parameters; the pseudo-observations count in the redundancy.
    EXPECT_EQ(gauge.datum.n_constraints, k) << config.name;
    EXPECT_TRUE(gauge.undetermined.empty()) << config.name;
    for (const auto& w : gauge.warnings) EXPECT_NE(w.name, "covariance") << config.name;
    EXPECT_EQ(gauge.report.redundancy, none.report.redundancy + k);
    // c free on the linear layout: the scale gauge is exact there (a scale of its design is linear
    // in u), so the datum-free solve keeps the fit of the datum (it no longer walks down the
    // scale to c ~ 0) and the datum costs nothing. On the sub-camera design the polynomials
    // follow a scale of the tilted design only approximately (eigenvalue 2.4e-11): printed.
    if (linear && config.pos_prior && config.free_c &&
        config.boresight == PlatformParamMode::kFixed) {
      EXPECT_NEAR(gauge.report.vtpv, none.report.vtpv, 1e-9 * none.report.vtpv) << config.name;
      EXPECT_NEAR(none.c_mm, sim.truth.c_mm, 0.05 * sim.truth.c_mm) << config.name;
    }
    // No defect: nothing is held, the problem is the datum-free one.
    if (k == 0) {
      EXPECT_DOUBLE_EQ(gauge.report.vtpv, none.report.vtpv) << config.name;
    }
    // The gauge functions named are those of the configuration (with the priors: scale with c,
    // the three rotations with the boresight).
    if (config.pos_prior && k > 0) {
      std::set<std::string> names;
      for (const auto& d : gauge.datum.directions) names.insert(d.name);
      EXPECT_EQ(names.count("scale"), config.free_c ? 1u : 0u) << config.name;
      const size_t rotation = config.boresight == PlatformParamMode::kFree ? 1u : 0u;
      EXPECT_EQ(names.count("pitch"), rotation) << config.name;
      EXPECT_EQ(names.count("roll"), rotation) << config.name;
      EXPECT_EQ(names.count("yaw"), rotation) << config.name;
    }
  }
}

// Any two valid choices of the sub-camera that carries the datum: with the POS priors and the
// boresight fixed (the default) there is no defect and the tables are identical. With a defect
// (boresight and c free: 4 gauge directions) the tables agree modulo the gauge to 1e-6 px on
// data without any error. With noise (0.25 px, POS errors with priors) they agree to 5.4e-5 ..
// 1.65e-4 px: the issue's 1e-6 px is not reachable there (module README "Datum", "The
// finite-gauge oracle"): a pitch or roll of the camera is a homography of the focal plane, which
// maps the noise's degree-5 content of a table out of the degree-5 model (non-closure ~1e-4 px
// at the 1e-3 .. 1.4e-2 rad between the references' solutions; pushbroom_gauge_oracle_test.cc),
// so the three constrained minima are different fits (their v^T P v differ by up to 0.004), not
// one fit in three gauges. The bound asserted is the measured one with a margin of 5.
constexpr double kNoisyGaugePx = 1e-3;

// The three references' tables for one configuration, solved to `tolerance` (relative cost change,
// step and gradient) within `iterations`.
std::vector<Table> ReferenceTables(const LineSimulation& sim,
                                   const Config& config,
                                   double tolerance,
                                   int iterations) {
  std::vector<Table> tables;
  for (int reference = 0; reference < 3; ++reference) {
    LineCalibrationOptions options = OptionsOf(config);
    options.degree = 5;  // a rotated error-free table is a degree-5 polynomial to 1e-9 px
    options.reference_subcamera = reference;
    options.solver.function_tolerance = tolerance;
    options.solver.parameter_tolerance = tolerance;
    options.solver.gradient_tolerance = tolerance * 1e-4;
    options.solver.max_iterations = iterations;
    const LineCalibrationResult r = Calibrate(sim, options);
    EXPECT_TRUE(r.report.usable) << r.report.message;
    const calib::ResidualGroupStats* datum = r.report.Group(kGroupLineDatum);
    std::printf("  reference %d: v^T P v %.9f (datum %.1e), %d iterations (%s)\n",
                reference,
                r.report.vtpv,
                datum ? datum->vtpv : 0.0,
                r.report.iterations,
                r.report.message.c_str());
    EXPECT_EQ(r.datum.n_constraints, config.expected_defect) << config.name;
    tables.push_back(TableOf(r, sim.nominal));
  }
  return tables;
}

// The largest difference modulo the gauge between any two of the tables, px (printed per pair).
double WorstModuloGauge(const std::vector<Table>& tables, double pitch, const std::string& what) {
  double worst = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      Eigen::Vector3d angles;
      const Eigen::VectorXd plain =
          RotatedDifference(tables[a], tables[b], Eigen::Vector3d::Zero(), pitch);
      const Eigen::VectorXd d = ModuloGauge(tables[a], tables[b], pitch, &angles);
      std::printf(
          "%s: reference %d vs %d: max difference %.2e px, modulo the gauge %.2e px (rotation "
          "%.2e %.2e %.2e rad)\n",
          what.c_str(),
          a,
          b,
          plain.cwiseAbs().maxCoeff(),
          d.cwiseAbs().maxCoeff(),
          angles.x(),
          angles.y(),
          angles.z());
      worst = std::max(worst, d.cwiseAbs().maxCoeff());
    }
  return worst;
}

TEST_P(GaugeDatum, ReferenceChoicesAgreeModuloTheGauge) {
  const bool linear = GetParam();
  for (const bool noise : {false, true}) {
    LineSimulationOptions o = DatumFlight(linear, 12);
    if (!noise) RemoveNoise(&o);  // no residual at all: the POS is exact, the priors hold the truth
    const LineSimulation sim = SimulateLineFlight(o);
    const double pitch = sim.nominal.pitch_mm;
    for (const Config& config : {kConfigs[0], kConfigs[3]}) {
      const std::string what = std::string(linear ? "linear" : "subcameras") + " layout, " +
                               (noise ? "noise" : "noise-free") + ", " + config.name;
      std::printf("%s\n", what.c_str());
      const std::vector<Table> tables = ReferenceTables(sim, config, 1e-16, 100);
      const double worst = WorstModuloGauge(tables, pitch, what);
      // No defect: the same problem; it differs in the last bits only (the Schur ordering
      // follows block addresses; 100 iterations near a zero residual amplify them).
      if (config.expected_defect == 0) {
        EXPECT_LT(RotatedDifference(tables[0], tables[1], Eigen::Vector3d::Zero(), pitch)
                      .cwiseAbs()
                      .maxCoeff(),
                  1e-9);
      }
      EXPECT_LT(worst, noise ? kNoisyGaugePx : 1e-6) << what;
      // The solver without its stopping rules (1e-30, 200 iterations; one layout, ~5 s): does the
      // noisy case approach the gauge-equivalent solution? Measured, printed.
      if (noise && linear && config.expected_defect > 0) {
        std::printf("%s, solver run to its limits:\n", what.c_str());
        WorstModuloGauge(ReferenceTables(sim, config, 1e-30, 200), pitch, what + " (limits)");
      }
    }
  }
}

// The default datum on the flight: the POS priors leave no defect, so nothing is held and
// the result is the datum-free one; the table is within a few sigma of the truth. The earlier
// reference datum (4 constraints whatever the null space) fits worse.
TEST_P(GaugeDatum, DefaultEqualsNoDatumWithPriorsAndTheTruth) {
  const bool linear = GetParam();
  const LineSimulation sim = SimulateLineFlight(DatumFlight(linear, 13));
  const double pitch = sim.nominal.pitch_mm;
  LineCalibrationOptions options;
  options.degree = 3;
  const LineCalibrationResult gauge = Calibrate(sim, options);
  options.datum = LineDatum::kNone;
  const LineCalibrationResult none = Calibrate(sim, options);
  options.datum = LineDatum::kReference;
  const LineCalibrationResult reference = Calibrate(sim, options);
  ASSERT_TRUE(gauge.report.converged);
  EXPECT_TRUE(gauge.valid);
  EXPECT_EQ(gauge.datum.rank_defect, 0);
  EXPECT_EQ(gauge.datum.n_constraints, 0);
  double worst_px = 0;
  for (int i = 0; i < sim.truth.detectors; ++i)
    worst_px = std::max({worst_px,
                         std::abs(gauge.dx_mm[i] - none.dx_mm[i]) / pitch,
                         std::abs(gauge.dy_mm[i] - none.dy_mm[i]) / pitch});
  EXPECT_LT(worst_px, 1e-9);
  EXPECT_DOUBLE_EQ(gauge.report.sigma0, none.report.sigma0);
  // Adding constraints that are not in the null space can only raise v^T P v.
  EXPECT_GT(reference.report.vtpv, gauge.report.vtpv);
  // Against the truth: per detector within the 1 % band of 4 free coefficients (Scheffe:
  // sqrt(chi2_4(1 %)) = 3.64), and the table error per axis.
  auto table_error = [&](const LineCalibrationResult& r, double* worst_z) -> Eigen::Vector2d {
    double ex = 0, ey = 0;
    *worst_z = 0;
    for (int i = 0; i < sim.truth.detectors; ++i) {
      const Eigen::Vector2d e = Eigen::Vector2d(r.dx_mm[i], r.dy_mm[i]) - sim.truth.Correction(i);
      ex += e.x() * e.x();
      ey += e.y() * e.y();
      if (r.dx_sigma_mm[i] && *r.dx_sigma_mm[i] > 0)
        *worst_z = std::max(*worst_z, std::abs(e.x()) / *r.dx_sigma_mm[i]);
      if (r.dy_sigma_mm[i] && *r.dy_sigma_mm[i] > 0)
        *worst_z = std::max(*worst_z, std::abs(e.y()) / *r.dy_sigma_mm[i]);
    }
    return Eigen::Vector2d(std::sqrt(ex / sim.truth.detectors),
                           std::sqrt(ey / sim.truth.detectors)) /
           pitch;
  };
  double z_gauge = 0, z_reference = 0;
  const Eigen::Vector2d e_gauge = table_error(gauge, &z_gauge);
  const Eigen::Vector2d e_reference = table_error(reference, &z_reference);
  const Eigen::VectorXd modulo = ModuloGauge(TruthTable(sim), TableOf(gauge, sim.nominal), pitch);
  std::printf(
      "%s layout: table error across / along: gauge (default) %.4f / %.4f px (worst %.2f "
      "sigma, modulo the gauge RMS %.4f px), sigma0 %.4f; reference datum %.4f / %.4f px "
      "(worst %.1f sigma), sigma0 %.4f\n",
      linear ? "linear" : "subcameras",
      e_gauge.x(),
      e_gauge.y(),
      z_gauge,
      std::sqrt(modulo.squaredNorm() / double(modulo.size())),
      gauge.report.sigma0,
      e_reference.x(),
      e_reference.y(),
      z_reference,
      reference.report.sigma0);
  EXPECT_LT(z_gauge, 3.64);
  EXPECT_NEAR(gauge.report.sigma0, 1.0, 3.0 / std::sqrt(2.0 * gauge.report.redundancy));
}

// A shutter / POS latency of 5 ms (0.3 m along track at 60 m/s): recovered within 3 sigma when
// estimated with the POS priors (its correlation with the trajectory's along-track and pitch
// corrections named); without the priors it lies in the null space: named, invalid.
TEST(TimeOffset, RecoveredWithPosPriorsAndNamedWithout) {
  LineSimulationOptions o = DatumFlight(false, 14);
  o.time_offset_s = 0.005;
  const LineSimulation sim = SimulateLineFlight(o);
  LineCalibrationOptions options;
  options.degree = 3;
  options.time_offset = true;
  const LineCalibrationResult r = Calibrate(sim, options);
  ASSERT_TRUE(r.report.converged);
  ASSERT_TRUE(r.time_offset_sigma_s.has_value());
  double rho = -1, rho_offset = -1;
  for (const auto& [name, value] : r.correlations) {
    if (name == "time_offset_vs_along_track") rho = value;
    if (name == "time_offset_vs_offset") rho_offset = value;
  }
  std::printf(
      "time offset %.6f +- %.6f s (truth 0.005), time_offset_vs_along_track %.4f, "
      "time_offset_vs_offset %.4f, sigma0 %.4f, defect %d\n",
      r.time_offset_s,
      *r.time_offset_sigma_s,
      rho,
      rho_offset,
      r.report.sigma0,
      r.datum.rank_defect);
  EXPECT_GT(rho_offset, 0.0);
  EXPECT_LT(rho_offset, 1.0);
  EXPECT_LT(std::abs(r.time_offset_s - 0.005), 3 * *r.time_offset_sigma_s);
  EXPECT_GT(rho, 0.0);
  EXPECT_LT(rho, 1.0);
  EXPECT_EQ(r.datum.rank_defect, 0);
  EXPECT_NEAR(r.report.sigma0, 1.0, 3.0 / std::sqrt(2.0 * r.report.redundancy));
  // Not estimated: the trajectory's corrections take the shift against their priors.
  options.time_offset = false;
  const LineCalibrationResult without = Calibrate(sim, options);
  std::printf("without the time offset: sigma0 %.4f, along-track node corrections take it\n",
              without.report.sigma0);
  // Without the POS priors: not determinable, named.
  options.time_offset = true;
  options.pos_prior = false;
  const LineCalibrationResult free = Calibrate(sim, options);
  PrintDatum("without the POS priors", free);
  if (free.time_offset_sigma_s)
    std::printf("  time offset %.6f +- %.6f s\n", free.time_offset_s, *free.time_offset_sigma_s);
  bool named = false;
  for (const auto& w : free.warnings) named |= w.name == "time_offset_not_determinable";
  EXPECT_TRUE(named);
  EXPECT_FALSE(free.valid);
  EXPECT_FALSE(free.time_offset_sigma_s.has_value());
}

INSTANTIATE_TEST_SUITE_P(Layouts, GaugeDatum, ::testing::Values(false, true), LayoutName);

}  // namespace
}  // namespace aerocal::triangulation
