// Result assembly of a line-camera calibration (line_calibration_run.h): the detector calibration
// with its sigmas, the error samples of the plots, the trajectory corrections, c and the mounted
// parameters, and the updated camera.
#include "triangulation/pushbroom/line_calibration_run.h"

#include <algorithm>
#include <cmath>

namespace aerocal::triangulation::internal {

using calib::BlockId;
using calib::kLineMaxTerms;
using Vector6d = Eigen::Matrix<double, 6, 1>;

std::optional<double> EntrySigma(const LineRun& run, BlockId block, int entry) {
  const auto& cov = run.cov;
  if (!cov.ok) return std::nullopt;
  const auto it = cov.offsets.find(block);
  if (it == cov.offsets.end() || !cov.free[it->second + entry]) return std::nullopt;
  return cov.sigma[it->second + entry];
}

namespace {

// The polynomial coefficients of every sub-camera with their sigmas (null: fixed).
void CollectCoefficients(LineRun& run) {
  for (int s = 0; s < run.n_sub; ++s) {
    auto& out = run.result.subcameras[s];
    const auto& a = run.sensor.Detectors()[s];
    const BlockId block = run.sensor.DetectorBlocks()[s];
    out.dx_coefficients_mm.assign(a.begin(), a.begin() + kLineMaxTerms);
    out.dy_coefficients_mm.assign(a.begin() + kLineMaxTerms, a.end());
    for (int k = 0; k < kLineMaxTerms; ++k) {
      out.dx_sigma_mm.push_back(EntrySigma(run, block, k));
      out.dy_sigma_mm.push_back(EntrySigma(run, block, kLineMaxTerms + k));
    }
  }
}

// Whether sub-camera s estimates any term of an axis beyond the datum's: without one the
// correction is fixed (sigma 0), not the datum pseudo-observations' own ~1e-4 px.
bool AxisEstimated(const LineRun& run, int s, int axis) {
  bool estimated = false;
  for (int k = 0; k < kLineMaxTerms; ++k) {
    const int e = axis * kLineMaxTerms + k;
    estimated |= !run.fixed_entries[s].count(e) && !run.datum_entries[s].count(e);
  }
  return estimated;
}

}  // namespace

// Per detector: the file's correction plus the fitted table, the fit sigma, and the table sigma
// (after a degree test at least the start-degree fit's: SelectedTableSigma).
void CollectDetectorCalibration(LineRun& run) {
  CollectCoefficients(run);
  auto& result = run.result;
  const int detectors = run.camera.detectors;
  for (auto* v : {&result.dx_mm, &result.dy_mm}) v->resize(detectors);
  for (auto* v :
       {&result.dx_sigma_mm, &result.dy_sigma_mm, &result.dx_fit_sigma_mm, &result.dy_fit_sigma_mm})
    v->resize(detectors);
  const std::vector<TableValue> table = DetectorTable(run, run.cov);
  for (int s = 0; s < run.n_sub; ++s)
    for (int axis = 0; axis < 2; ++axis) {
      const bool estimated = AxisEstimated(run, s, axis);
      for (int i = run.ranges[s].first; i <= run.ranges[s].second; ++i) {
        const size_t j = axis * size_t(detectors) + i;
        const Eigen::Vector2d base = run.camera.Correction(i);
        (axis == 0 ? result.dx_mm : result.dy_mm)[i] = base[axis] + table[j].value;
        if (!run.cov.ok) continue;
        auto& sigma = (axis == 0 ? result.dx_sigma_mm : result.dy_sigma_mm)[i];
        auto& fit_sigma = (axis == 0 ? result.dx_fit_sigma_mm : result.dy_fit_sigma_mm)[i];
        fit_sigma = estimated ? std::sqrt(table[j].variance) : 0.0;
        sigma =
            run.start_table.empty() ? *fit_sigma : SelectedTableSigma(table[j], run.start_table[j]);
      }
    }
}

// Error samples (plots): the fitted correction at the measured position minus the residual,
// i.e. what remains without the detector calibration, in pitches.
void CollectErrorSamples(LineRun& run) {
  const LineScanCamera& sensor = run.sensor;
  const double pitch_mm = run.camera.pitch_mm;
  for (size_t k = 0; k < run.image_residuals.size(); ++k) {
    const auto r = run.builder.EvaluateResidual(run.image_residuals[k]);
    if (r.size() != 2) continue;
    const LineTerm& term = sensor.Terms()[k];
    const double* a = sensor.Detectors()[term.subcamera].data();
    const Eigen::Vector2d base = run.camera.Correction(term.detector);
    const double dx = base.x() + calib::EvaluatePolynomial(a, kLineMaxTerms, term.u);
    const double dy =
        base.y() + calib::EvaluatePolynomial(a + kLineMaxTerms, kLineMaxTerms, term.u);
    run.result.error_samples.push_back({term.detector,
                                        term.subcamera,
                                        (dx - r[0] * term.sigma_mm.x()) / pitch_mm,
                                        (dy - r[1] * term.sigma_mm.y()) / pitch_mm});
  }
}

namespace {

// The correction of one scan line and its sigma: the spline's four nodes, weighted, with their
// cross-covariances (var = sum_m sum_n w_m w_n C(m, n)).
void LineCorrection(const LineRun& run, double line, Vector6d* value, Vector6d* sigma) {
  const LineScanCamera& sensor = run.sensor;
  const calib::SplineSpan span = calib::CubicBSplineWeights(line - run.first_line, run.spacing);
  const int j = std::min(span.first_node, run.n_nodes - 4);
  *value = Vector6d::Zero();
  Eigen::Matrix<double, 6, 6> var = Eigen::Matrix<double, 6, 6>::Zero();
  for (int m = 0; m < 4; ++m) {
    *value += span.weights[m] * sensor.Nodes()[j + m];
    if (!run.cov.ok) continue;
    for (int n = 0; n < 4; ++n) {
      Eigen::MatrixXd cross;
      if (run.cov.CrossCovariance(sensor.NodeBlocks()[j + m], sensor.NodeBlocks()[j + n], &cross))
        var += span.weights[m] * span.weights[n] * cross;
    }
  }
  *sigma = var.diagonal().cwiseMax(0.0).cwiseSqrt();
}

}  // namespace

// Spline nodes and per-line corrections with sigmas.
void CollectTrajectory(LineRun& run) {
  auto& result = run.result;
  for (int j = 0; j < run.n_nodes; ++j) {
    result.node_line.push_back(run.first_line + (j - 1) * double(run.spacing));
    result.node_values.push_back(run.sensor.Nodes()[j]);
    Vector6d sigma = Vector6d::Zero();
    if (run.cov.ok)
      for (int e = 0; e < 6; ++e)
        sigma[e] = EntrySigma(run, run.sensor.NodeBlocks()[j], e).value_or(0.0);
    result.node_sigma.push_back(sigma);
  }
  for (double line = run.first_line; line <= run.last_line + 1e-9; line += 1.0) {
    Vector6d value, sigma;
    LineCorrection(run, line, &value, &sigma);
    result.lines.push_back(line);
    result.line_corrections.push_back(value);
    result.line_sigma.push_back(sigma);
  }
}

namespace {

// The sigmas of a 3-vector block; nullopt when one entry has none.
std::optional<Eigen::Vector3d> Vector3Sigma(const LineRun& run, BlockId block) {
  Eigen::Vector3d sigma;
  for (int e = 0; e < 3; ++e) {
    const auto s = EntrySigma(run, block, e);
    if (!s) return std::nullopt;
    sigma[e] = *s;
  }
  return sigma;
}

// Requested parameters in the null space (DeriveDatum): not determined by the data. Not with the
// explicit reference datum (its convention sets them).
void WarnNotDeterminable(LineRun& run) {
  auto& result = run.result;
  const double fail = run.options.correlation_fail;
  if (run.options.datum == LineDatum::kReference) return;
  for (const std::string& name : result.datum.parameters_in_null_space) {
    if (name == "time_offset") continue;  // below, with its own message
    result.valid = false;
    result.warnings.push_back({name + "_not_determinable",
                               name,
                               1.0,
                               fail,
                               "ill-posed: " + name +
                                   " lies in the null space of the problem "
                                   "(a gauge direction: its value is the datum's convention, not "
                                   "the data's; datum.gauge_directions says which)"});
  }
  if (!run.time_offset_in_null_space) return;
  result.valid = false;
  result.time_offset_sigma_s.reset();
  result.warnings.push_back({"time_offset_not_determinable",
                             "time offset",
                             1.0,
                             fail,
                             "ill-posed: the time offset lies in the null space (an along-track "
                             "shift v dt the trajectory takes over entirely; the POS priors are "
                             "off)"});
}

}  // namespace

void CollectMountedParameters(LineRun& run) {
  auto& result = run.result;
  const auto& options = run.options;
  const LineScanCamera& sensor = run.sensor;
  result.c_mm = sensor.CMm();
  if (options.free_c) result.c_sigma_mm = EntrySigma(run, sensor.CBlock(), 0);
  // Boresight and lever arm: values, sigmas (null when fixed or not determined).
  result.boresight = options.boresight;
  result.lever_arm = options.lever_arm;
  result.boresight_rad = sensor.MountRad();
  result.lever_arm_m = sensor.LeverArmM();
  if (options.boresight != PlatformParamMode::kFixed)
    result.boresight_sigma_rad = Vector3Sigma(run, sensor.MountBlock());
  if (options.lever_arm != PlatformParamMode::kFixed)
    result.lever_arm_sigma_m = Vector3Sigma(run, sensor.LeverArmBlock());
  result.time_offset_estimated = options.time_offset;
  result.time_offset_s = sensor.TimeOffsetS();
  if (options.time_offset &&
      (!run.time_offset_in_null_space || options.datum == LineDatum::kReference))
    result.time_offset_sigma_s = EntrySigma(run, sensor.TimeOffsetBlock(), 0);
  WarnNotDeterminable(run);
}

namespace {

// Whether the file's calibration is absent or polynomials over the sub-cameras' own ranges (the
// estimate is then written as polynomials, else as a table).
bool SameRanges(const LineRun& run) {
  const calib::LineCamera& camera = run.camera;
  bool same_ranges = camera.dx_mm.empty();
  if (camera.calibration.empty()) return same_ranges;
  same_ranges = int(camera.calibration.size()) == run.n_sub;
  for (int s = 0; same_ranges && s < run.n_sub; ++s)
    same_ranges = camera.calibration[s].first == run.ranges[s].first &&
                  camera.calibration[s].last == run.ranges[s].second &&
                  camera.calibration[s].dx.size() <= size_t(kLineMaxTerms) &&
                  camera.calibration[s].dy.size() <= size_t(kLineMaxTerms);
  return same_ranges;
}

// Sub-camera s's polynomial: the estimate plus the file's, trailing zero terms dropped.
calib::LinePolynomial UpdatedPolynomial(const LineRun& run, int s) {
  const auto& a = run.sensor.Detectors()[s];
  calib::LinePolynomial poly;
  poly.first = run.ranges[s].first;
  poly.last = run.ranges[s].second;
  poly.dx.assign(a.begin(), a.begin() + kLineMaxTerms);
  poly.dy.assign(a.begin() + kLineMaxTerms, a.end());
  if (!run.camera.calibration.empty()) {
    const calib::LinePolynomial& file = run.camera.calibration[s];
    for (size_t k = 0; k < file.dx.size(); ++k) poly.dx[k] += file.dx[k];
    for (size_t k = 0; k < file.dy.size(); ++k) poly.dy[k] += file.dy[k];
  }
  while (poly.dx.size() > 1 && poly.dx.back() == 0.0) poly.dx.pop_back();
  while (poly.dy.size() > 1 && poly.dy.back() == 0.0) poly.dy.pop_back();
  return poly;
}

}  // namespace

// The updated camera: design + the estimated calibration (polynomials when the file had none or
// had polynomials over the same ranges, else the table).
void CollectUpdatedCamera(LineRun& run) {
  calib::LineCamera& camera = run.result.camera;
  camera = run.camera;
  camera.c_mm = run.sensor.CMm();
  camera.mount_rad = run.sensor.MountRad();
  camera.lever_arm_m = run.sensor.LeverArmM();
  if (SameRanges(run)) {
    std::vector<calib::LinePolynomial> polys;
    for (int s = 0; s < run.n_sub; ++s) polys.push_back(UpdatedPolynomial(run, s));
    camera.calibration = polys;
    camera.dx_mm.clear();
    camera.dy_mm.clear();
  } else {
    camera.calibration.clear();
    camera.dx_mm = run.result.dx_mm;
    camera.dy_mm = run.result.dy_mm;
  }
}

}  // namespace aerocal::triangulation::internal
