// The finite-gauge oracle of the pushbroom datum (issue 28 part 1; module README "Datum", "Why the
// reference choices differ with noise"). A converged solution (POS priors, boresight and c fixed:
// no defect) is moved along a FINITE gauge orbit: the camera frame turned by Q (the mount
// M -> M Q, so the ray to every point v -> Q^T v) and scaled by s (c -> s c), the table following
// exactly (every detector ray d -> Q^T d, rescaled to the focal plane z = -s c: a homography of
// the focal plane). Then v^T P v is evaluated
// - with the table transformed exactly (per observation: a polynomial block whose value and
//   derivative at that observation's u are the transformed table's, so the residual functor sees
//   the exact ray and line direction): it must be unchanged to ~1e-12 relative, i.e. nothing else
//   in the model (lever arm, POS priors, the spline, the weights, the control) breaks the gauge;
// - with the transformed table projected onto the model (least squares per sub-camera and axis,
//   degree 5: what a solution can hold) and re-solved with the mount and c held at the moved
//   values: if the gauge were exact in the model this profile would be flat.
// The projection's residual is the non-closure of the polynomial table under the finite gauge: a
// yaw maps (x, y) linearly and a scale multiplies them (both polynomials again), but a pitch or
// roll divides by q3 . d (a rational function of u): the degree-5 content of the table (noise
// and real errors) times the rotation and x/c becomes degree 6..10, which no degree-5 table holds.
#include "calib/camera/rotation.h"
#include "calib/problem/problem_builder.h"
#include "calib/residuals/prior.h"
#include "tests/triangulation/pushbroom_flights.h"
#include "triangulation/pushbroom/line_simulation.h"
#include "triangulation/pushbroom/pos_trajectory.h"
#include "triangulation/sensor/frame_camera.h"
#include "triangulation/sensor/line_scan_camera.h"

#include <Eigen/Dense>
#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace aerocal::triangulation {
namespace {

using calib::kLineMaxTerms;
using DetectorValues = LineScanCamera::DetectorValues;

// A finite gauge transformation: the camera frame turned by q (about its own axes, q = R(opk))
// and scaled by `scale`. `closed`: a degree-5 table stays one (identity, yaw, scale on the linear
// layout, whose design is linear in u).
struct Gauge {
  const char* name;
  Eigen::Vector3d opk_rad;
  double scale;
  bool closed;
};

// Where an observation's functor reads the table: its sub-camera, u, the start table's position
// and line direction there (as LineScanCamera::Observe computes them).
struct Site {
  int subcamera = 0;
  double u = 0, du_di = 0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero(), slope = Eigen::Vector2d::Zero();
};

// The calibration problem of CalibrateLineCamera (POS priors, degree 5, boresight and c fixed,
// no datum: no defect) built from the same sensor kind, with a copy of every image functor kept
// for evaluation at parameter values of the oracle's choosing.
class Oracle {
 public:
  explicit Oracle(const LineSimulation& sim)
      : sim_(sim),
        pos_(PosTrajectory::FromRecords(sim.pos, "pos.csv")),
        index_(strip_),
        sensor_(sim.nominal, pos_, LineScanOptions{}),
        context_{strip_, adjust_, builder_, index_, poses_, frame_} {
    sensor_.RegisterBlocks(context_);
    std::map<std::string, calib::BlockId> point_block;
    points_.reserve(sim.points.size());
    for (const auto& g : sim.points) {
      if (g.role != PointRole::kControl || !g.xyz_m) continue;
      points_.push_back(*g.xyz_m);
      const calib::BlockId block = builder_.AddBlock("point_" + g.id,
                                                     points_.back().data(),
                                                     3,
                                                     calib::BlockKind::kGroundPoint,
                                                     {"X", "Y", "Z"});
      point_block[g.id] = block;
      const Eigen::Vector3d& v = *g.xyz_m;
      builder_.AddResidual(
          calib::kGroupControl,
          calib::PriorCostFunction::Create({v.x(), v.y(), v.z()},
                                           {g.sigma_m.x(), g.sigma_m.y(), g.sigma_m.z()}),
          {block},
          "control " + g.id);
    }
    for (const auto& o : sim.observations) {
      const auto it = point_block.find(o.point);
      if (it == point_block.end()) continue;
      ImageObservation observation;
      observation.image = kLineStripImage;
      observation.point = o.point;
      observation.pixel = Eigen::Vector2d(o.detector, o.line);
      observation.sigma_px = o.sigma_px;
      ObservationTerm term = sensor_.Observe(context_, observation, it->second);
      copies_.push_back(sensor_.Observe(context_, observation, it->second).cost);
      blocks_.push_back(term.blocks);
      sites_.push_back(SiteOf(o.detector));
      lines_.push_back(o.line);
      points_of_.push_back(it->second);
      nominal_scale_.push_back(MeasurementScale(image_ids_.size()));
      image_ids_.push_back(
          builder_.AddResidual(term.group, std::move(term.cost), term.blocks, "point " + o.point));
    }
    sensor_.AddOwnResiduals(context_);
  }

  calib::SolveReport Solve() {
    calib::SolverOptions options;
    options.function_tolerance = options.parameter_tolerance = 1e-16;
    options.gradient_tolerance = 1e-20;
    options.max_iterations = 100;
    return builder_.Solve(options);
  }

  // v^T P v at the builder's current values (every residual).
  double Vtpv() const {
    double sum = 0;
    for (int id = 0; id < builder_.NumResiduals(); ++id)
      if (builder_.IsActive(id))
        for (double r : builder_.EvaluateResidual(id)) sum += r * r;
    return sum;
  }

  // v^T P v after the exact finite gauge: the image residuals through the kept functors with the
  // exactly transformed table, mount and c; the other residuals (priors, control) do not see it.
  double ExactGaugeVtpv(const Gauge& g) const {
    double sum = Vtpv();
    const Eigen::Matrix3d q = calib::RotationFromOpk(g.opk_rad);
    const Eigen::Vector3d mount =
        calib::OpkFromRotation(calib::RotationFromOpk(sensor_.MountRad()) * q);
    const double c = g.scale * sensor_.CMm();
    for (size_t k = 0; k < copies_.size(); ++k) {
      double r[2];
      Evaluate(k, sensor_.Detectors()[sites_[k].subcamera], sensor_.CMm(), sensor_.MountRad(), r);
      sum -= r[0] * r[0] + r[1] * r[1];
      Evaluate(k, ExactBlock(k, q, g.scale), c, mount, r);
      sum += r[0] * r[0] + r[1] * r[1];
    }
    return sum;
  }

  // The gauge applied with the table projected onto degree 5 (least squares per sub-camera and
  // axis over the detectors and the midpoints between them). Returns the projection's largest
  // and RMS residual (px): the non-closure; the builder then holds the moved values.
  std::pair<double, double> ApplyProjected(const Gauge& g) {
    const Eigen::Matrix3d q = calib::RotationFromOpk(g.opk_rad);
    const double c0 = sensor_.CMm();
    const auto ranges = sim_.nominal.Ranges();
    double worst = 0, sum = 0;
    int n = 0;
    std::vector<DetectorValues> projected(ranges.size());
    for (size_t s = 0; s < ranges.size(); ++s) {
      const double* p = sensor_.Detectors()[s].data();
      std::vector<double> us;
      std::vector<Eigen::Vector2d> targets;
      for (double i = ranges[s].first; i <= ranges[s].second + 1e-9; i += 0.5) {
        const double u =
            calib::LinePolynomial{ranges[s].first, ranges[s].second, {}, {}}.Normalised(i);
        const Eigen::Vector2d design = sim_.nominal.DetectorPosition(i);
        const Eigen::Vector3d d(
            design.x() + calib::EvaluatePolynomial(p, kLineMaxTerms, u),
            design.y() + calib::EvaluatePolynomial(p + kLineMaxTerms, kLineMaxTerms, u),
            -c0);
        const Eigen::Vector3d w = q.transpose() * d;
        us.push_back(u);
        targets.push_back((-g.scale * c0 / w.z()) * w.head<2>() - design);
      }
      Eigen::MatrixXd a(us.size(), kLineMaxTerms);
      for (size_t m = 0; m < us.size(); ++m)
        for (int k = 0; k < kLineMaxTerms; ++k) a(m, k) = std::pow(us[m], k);
      const auto qr = a.colPivHouseholderQr();
      for (int axis = 0; axis < 2; ++axis) {
        Eigen::VectorXd b(us.size());
        for (size_t m = 0; m < us.size(); ++m) b(m) = targets[m][axis];
        const Eigen::VectorXd coefficients = qr.solve(b);
        const Eigen::VectorXd residual = (a * coefficients - b) / sim_.nominal.pitch_mm;
        worst = std::max(worst, residual.cwiseAbs().maxCoeff());
        sum += residual.squaredNorm();
        n += int(residual.size());
        for (int k = 0; k < kLineMaxTerms; ++k)
          projected[s][axis * kLineMaxTerms + k] = coefficients(k);
      }
    }
    for (size_t s = 0; s < ranges.size(); ++s)
      std::copy(projected[s].begin(),
                projected[s].end(),
                builder_.BlockValues(sensor_.DetectorBlocks()[s]));
    const Eigen::Vector3d mount =
        calib::OpkFromRotation(calib::RotationFromOpk(sensor_.MountRad()) * q);
    std::copy(mount.data(), mount.data() + 3, builder_.BlockValues(sensor_.MountBlock()));
    *builder_.BlockValues(sensor_.CBlock()) = g.scale * c0;
    return {worst, std::sqrt(sum / n)};
  }

  // The lever arm (body frame, m) held at a value of the oracle's choosing (the block is fixed).
  void SetLeverArm(const Eigen::Vector3d& lever) {
    std::copy(lever.data(), lever.data() + 3, builder_.BlockValues(sensor_.LeverArmBlock()));
  }
  const Eigen::Vector3d& LeverArm() const { return sensor_.LeverArmM(); }

  // v^T P v with the image residuals weighted at the START angle per detector and per line, as
  // before issue 28's fix: the functor's rescaling (line_collinearity.h: start / current, across
  // and along) undone, r_k scaled per component by current / start.
  double VtpvWithStartWeights() const {
    double sum = Vtpv();
    for (size_t k = 0; k < image_ids_.size(); ++k) {
      const std::vector<double> r = builder_.EvaluateResidual(image_ids_[k]);
      const Eigen::Vector2d ratio = MeasurementScale(k).cwiseQuotient(nominal_scale_[k]);
      sum +=
          std::pow(r[0] * ratio.x(), 2) + std::pow(r[1] * ratio.y(), 2) - r[0] * r[0] - r[1] * r[1];
    }
    return sum;
  }

  std::vector<double> Snapshot() const { return builder_.ValuesSnapshot(); }
  void Restore(const std::vector<double>& values) { builder_.RestoreValues(values); }

 private:
  Site SiteOf(double detector) const {
    const auto ranges = sim_.nominal.Ranges();
    const LineDetectorSite where = sensor_.DetectorSite(detector);
    const auto& range = ranges[where.subcamera];
    const double h = 0.01;
    const double ic = std::max(range.first + h, std::min(range.second - h, detector));
    Site site;
    site.subcamera = where.subcamera;
    site.u = where.u;
    site.du_di = 2.0 / double(range.second - range.first);
    site.xy = sim_.nominal.DetectorPosition(detector);
    site.slope =
        (sim_.nominal.DetectorPosition(ic + h) - sim_.nominal.DetectorPosition(ic - h)) / (2 * h);
    return site;
  }

  // Observation k's angle per detector (across: |l_perp| / |d| of the current table) and a
  // quantity proportional to its angle per line (along: 1 / range to the point), at the current
  // values. Called with k = the next observation while building (its site is already stored).
  Eigen::Vector2d MeasurementScale(size_t k) const {
    const Site& site = sites_[k];
    const double* p = sensor_.Detectors()[site.subcamera].data();
    const Eigen::Vector3d d(
        site.xy.x() + calib::EvaluatePolynomial(p, kLineMaxTerms, site.u),
        site.xy.y() + calib::EvaluatePolynomial(p + kLineMaxTerms, kLineMaxTerms, site.u),
        -sensor_.CMm());
    const Eigen::Vector3d l(
        site.slope.x() + site.du_di * calib::EvaluatePolynomialDerivative(p, kLineMaxTerms, site.u),
        site.slope.y() + site.du_di * calib::EvaluatePolynomialDerivative(
                                          p + kLineMaxTerms, kLineMaxTerms, site.u),
        0.0);
    const Eigen::Vector3d e = d.normalized();
    Eigen::Vector3d center, opk;
    sensor_.PoseAtLine(lines_[k], &center, &opk);
    const Eigen::Vector3d camera = center + calib::RotationFromOpk(opk) * sensor_.LeverArmM();
    const Eigen::Vector3d point =
        Eigen::Map<const Eigen::Vector3d>(builder_.BlockValues(points_of_[k]));
    return {(l - l.dot(e) * e).norm() / d.norm(), 1.0 / (point - camera).norm()};
  }

  // A polynomial block (a0 + a1 u per axis) whose value and derivative at observation k's u are
  // the exactly transformed table's: the functor then sees the transformed ray and line
  // direction. d1 = -s c0 Q^T d0 / (Q^T d0)_z, l1 = dd1/dd0 l0.
  DetectorValues ExactBlock(size_t k, const Eigen::Matrix3d& q, double scale) const {
    const Site& site = sites_[k];
    const double* p = sensor_.Detectors()[site.subcamera].data();
    const double c0 = sensor_.CMm();
    const Eigen::Vector3d d0(
        site.xy.x() + calib::EvaluatePolynomial(p, kLineMaxTerms, site.u),
        site.xy.y() + calib::EvaluatePolynomial(p + kLineMaxTerms, kLineMaxTerms, site.u),
        -c0);
    const Eigen::Vector3d l0(
        site.slope.x() + site.du_di * calib::EvaluatePolynomialDerivative(p, kLineMaxTerms, site.u),
        site.slope.y() + site.du_di * calib::EvaluatePolynomialDerivative(
                                          p + kLineMaxTerms, kLineMaxTerms, site.u),
        0.0);
    const Eigen::Vector3d w = q.transpose() * d0, m = q.transpose() * l0;
    const double f = -scale * c0 / w.z();
    const Eigen::Vector3d d1 = f * w, l1 = f * (m - w * (m.z() / w.z()));
    DetectorValues block;
    block.fill(0.0);
    for (int axis = 0; axis < 2; ++axis) {
      const double a1 = (l1[axis] - site.slope[axis]) / site.du_di;
      block[axis * kLineMaxTerms + 1] = a1;
      block[axis * kLineMaxTerms] = d1[axis] - site.xy[axis] - a1 * site.u;
    }
    return block;
  }

  // Observation k's residual at the builder's nodes, lever arm, time offset and point, with the
  // given detector block, c and mount.
  void Evaluate(size_t k,
                const DetectorValues& detector,
                double c,
                const Eigen::Vector3d& mount,
                double* r) const {
    const std::vector<calib::BlockId>& b = blocks_[k];
    const double* parameters[10] = {builder_.BlockValues(b[0]),
                                    builder_.BlockValues(b[1]),
                                    builder_.BlockValues(b[2]),
                                    builder_.BlockValues(b[3]),
                                    detector.data(),
                                    &c,
                                    mount.data(),
                                    builder_.BlockValues(b[7]),
                                    builder_.BlockValues(b[8]),
                                    builder_.BlockValues(b[9])};
    ASSERT_TRUE(copies_[k]->Evaluate(parameters, r, nullptr));
  }

  const LineSimulation& sim_;
  const PosTrajectory pos_;
  Project strip_;
  const AdjustOptions adjust_{};
  const DenseIndex index_;
  const std::vector<PoseBlocks> poses_;
  const FrameCamera frame_{};
  calib::ProblemBuilder builder_;
  LineScanCamera sensor_;
  const SensorContext context_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::unique_ptr<ceres::CostFunction>> copies_;
  std::vector<std::vector<calib::BlockId>> blocks_;
  std::vector<Site> sites_;
  std::vector<calib::ResidualId> image_ids_;
  std::vector<double> lines_;
  std::vector<calib::BlockId> points_of_;
  std::vector<Eigen::Vector2d> nominal_scale_;
};

const Gauge kGauges[] = {
    {"identity", {0, 0, 0}, 1.0, true},
    {"yaw 1e-2", {0, 0, 1e-2}, 1.0, true},
    {"scale 1.01", {0, 0, 0}, 1.01, true},
    {"pitch 1e-2", {1e-2, 0, 0}, 1.0, false},
    {"roll 1e-2", {0, 1e-2, 0}, 1.0, false},
    {"roll 5e-3", {0, 5e-3, 0}, 1.0, false},
    {"roll 2.5e-3", {0, 2.5e-3, 0}, 1.0, false},
    {"roll -1e-2", {0, -1e-2, 0}, 1.0, false},
    {"pitch, roll, yaw 1e-2, scale 1.01", {1e-2, 1e-2, 1e-2}, 1.01, false},
    // The rotation between the solutions of references 1 and 2 (linear layout, with noise;
    // ReferenceChoicesAgreeModuloTheGauge prints it).
    {"as between references 1 and 2", {-3.75e-3, -8.07e-3, -6.41e-3}, 1.0, false},
};

class GaugeOracle : public ::testing::TestWithParam<bool> {};

TEST_P(GaugeOracle, ExactGaugeKeepsTheFitAndTheDegreeFiveTableDoesNot) {
  const bool linear = GetParam();
  for (const bool noise : {false, true}) {
    LineSimulationOptions options = DatumFlight(linear, 12);
    if (!noise) RemoveNoise(&options);
    const LineSimulation sim = SimulateLineFlight(options);
    Oracle oracle(sim);
    const calib::SolveReport report = oracle.Solve();
    ASSERT_TRUE(report.usable) << report.message;
    const double vtpv0 = oracle.Vtpv();
    std::printf("%s layout, %s: v^T P v %.9f (solve %.9f), %d iterations\n",
                linear ? "linear" : "subcameras",
                noise ? "noise" : "noise-free",
                vtpv0,
                report.vtpv,
                report.iterations);
    const std::vector<double> solution = oracle.Snapshot();
    const std::string what =
        std::string(linear ? "linear" : "subcameras") + (noise ? ", noise: " : ", noise-free: ");
    std::map<std::string, double> non_closure;  // by gauge name, px
    for (const Gauge& g : kGauges) {
      const double exact = oracle.ExactGaugeVtpv(g) - vtpv0;
      const auto [worst_px, rms_px] = oracle.ApplyProjected(g);
      const double projected = oracle.Vtpv() - vtpv0;
      const calib::SolveReport moved = oracle.Solve();
      const double profile = oracle.Vtpv() - vtpv0;
      std::printf(
          "  %-34s exact %+.2e, degree 5: non-closure max %.2e RMS %.2e px, v^T P v %+.3e, "
          "re-solved %+.3e (%d it.)\n",
          g.name,
          exact,
          worst_px,
          rms_px,
          projected,
          profile,
          moved.iterations);
      oracle.Restore(solution);
      non_closure[g.name] = worst_px;
      // Nothing but the table breaks the gauge: exact to the rounding of ~1e3 squared residuals
      // (measured <= 1.8e-11 of 1411).
      EXPECT_LT(std::abs(exact), 1e-12 * std::max(1.0, vtpv0)) << what << g.name;
      if (linear && g.closed) {  // yaw and scale keep a degree-5 table one: the orbit is exact
        EXPECT_LT(worst_px, 1e-12) << what << g.name;
        EXPECT_LT(std::abs(profile), 1e-9 * std::max(1.0, vtpv0)) << what << g.name;
      }
      if (!noise) {  // a cubic truth: no degree-4/5 content to push out of the model
        EXPECT_LT(worst_px, 2e-6) << what << g.name;
        EXPECT_LT(std::abs(profile), 1e-7) << what << g.name;
      }
      if (noise && !g.closed) {  // the noise's degree-5 content leaves it: a real change of fit
        EXPECT_GT(worst_px, 1e-5) << what << g.name;
        EXPECT_GT(std::abs(profile), 1e-4) << what << g.name;
      }
    }
    // First order in the angle: halving the roll halves the non-closure.
    if (noise) {
      EXPECT_NEAR(non_closure["roll 1e-2"] / non_closure["roll 5e-3"], 2.0, 0.1) << what;
      EXPECT_NEAR(non_closure["roll 5e-3"] / non_closure["roll 2.5e-3"], 2.0, 0.1) << what;
    }
  }
}

// The free lever arm's bias (module README "Datum", "The free lever arm"): on the boresight
// test's flight (seed 7, no sub-camera errors) the lever arm is held at the truth + (0, 0, dz) and
// everything else re-solved: the profile of v^T P v over dz. Raising the camera by dz with the
// table shrunk by H / (H + dz) sees the ground through the same rays (up to the relief), while
// every measured detector and line is then a smaller angle: residuals weighted at the START angle
// per detector and per line (VtpvWithStartWeights: the residual before the fix) shrink with it,
// so the noise part E of v^T P v (~ its redundancy) falls by 2 E dz / H and the minimum moves to
// dz ~ sigma_z^2 E / H. The residual in the current detectors and lines (line_collinearity.h)
// has no such pull: its noisy profile is the noise-free one, minimum at the truth.
TEST(LeverArmOracle, ProfileOfTheVerticalLeverArm) {
  for (const bool noise : {false, true}) {
    LineSimulationOptions o = SmallFlight(7);
    if (!noise) RemoveNoise(&o);
    const LineSimulation sim = SimulateLineFlight(o);
    Oracle oracle(sim);
    const Eigen::Vector3d truth = sim.truth.lever_arm_m;
    std::printf("%s: lever arm truth %.3f %.3f %.3f m\n",
                noise ? "noise" : "noise-free",
                truth.x(),
                truth.y(),
                truth.z());
    std::map<double, std::pair<double, double>> profile;  // dz -> (v^T P v, start weights)
    for (const double dz : {0.0, -40.0, -20.0, -10.0, 10.0, 20.0, 30.0, 40.0, 60.0}) {
      oracle.SetLeverArm(truth + Eigen::Vector3d(0, 0, dz));
      const calib::SolveReport report = oracle.Solve();
      ASSERT_TRUE(report.usable) << report.message;
      profile[dz] = {oracle.Vtpv(), oracle.VtpvWithStartWeights()};
      std::printf(
          "  dz %+5.1f m: v^T P v %+10.4f, weighted at the start's angles %+10.4f (%d it.)\n",
          dz,
          profile[dz].first - profile[0.0].first,
          profile[dz].second - profile[0.0].second,
          report.iterations);
    }
    // The minimum at the truth (within +-10 m, sigma_z ~5 m); weighted at the start's angles the
    // noisy profile falls towards +dz (measured: -18.5 at +10 m, minimum -33.5 near +30 m).
    EXPECT_GT(profile[10.0].first, profile[0.0].first);
    EXPECT_GT(profile[-10.0].first, profile[0.0].first);
    if (noise) {
      EXPECT_LT(profile[10.0].second, profile[0.0].second - 5.0);
      EXPECT_LT(profile[30.0].second, profile[10.0].second);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, GaugeOracle, ::testing::Values(false, true), LayoutName);

}  // namespace
}  // namespace aerocal::triangulation
