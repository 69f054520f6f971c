// Solve and statistics of a line-camera calibration (line_calibration_run.h): the solve and the
// covariance of the calibrated blocks, the degree test, the RMS per sub-camera, sigma0 in px and
// the rules that make the result not valid.
#include "triangulation/pushbroom/line_calibration_run.h"

#include <algorithm>
#include <cmath>

namespace aerocal::triangulation::internal {

using calib::kLineMaxTerms;

void SolveAndEstimateCovariance(LineRun& run) {
  const LineScanCamera& sensor = run.sensor;
  if (run.cov_blocks.empty()) {
    run.cov_blocks = sensor.NodeBlocks();
    run.cov_blocks.insert(
        run.cov_blocks.end(), sensor.DetectorBlocks().begin(), sensor.DetectorBlocks().end());
    run.cov_blocks.push_back(sensor.CBlock());
    if (run.options.boresight != PlatformParamMode::kFixed)
      run.cov_blocks.push_back(sensor.MountBlock());
    if (run.options.lever_arm != PlatformParamMode::kFixed)
      run.cov_blocks.push_back(sensor.LeverArmBlock());
    if (run.options.time_offset) run.cov_blocks.push_back(sensor.TimeOffsetBlock());
  }
  auto& report = run.result.report;
  report = run.builder.Solve(run.options.solver);
  run.cov = report.usable ? run.builder.EstimateCovariance(run.cov_blocks, report.sigma0)
                          : calib::CovarianceReport{};
}

std::vector<TableValue> DetectorTable(const LineRun& run, const calib::CovarianceReport& cov) {
  const int detectors = run.camera.detectors;
  std::vector<TableValue> table(2 * size_t(detectors));
  for (int s = 0; s < run.n_sub; ++s) {
    const calib::BlockId block = run.sensor.DetectorBlocks()[s];
    const Eigen::MatrixXd q =
        cov.ok ? cov.BlockCovariance(block, 2 * kLineMaxTerms) : Eigen::MatrixXd();
    for (int i = run.ranges[s].first; i <= run.ranges[s].second; ++i)
      for (int axis = 0; axis < 2; ++axis)
        table[axis * size_t(detectors) + i] = EvaluateDetectorPolynomial(
            run.sensor.Detectors()[s].data(), q, axis, NormalisedIndex(run.ranges[s], i));
  }
  return table;
}

namespace {

// One sub-camera's degree per axis by the test; true when a term was dropped (now held).
bool TestSubcameraDegrees(LineRun& run, int s) {
  bool changed = false;
  for (int axis = 0; axis < 2; ++axis) {
    SubcameraRms& out = run.result.subcameras[s];
    int& degree = axis == 0 ? out.degree_x : out.degree_y;
    // The datum sub-camera keeps the start degree: a term dropped there (insignificant, yet
    // real) is a bias the sigmas do not show, and the datum pins its correction where the
    // Legendre terms kept vanish (degree 2: u = +-1/sqrt(3), sigma ~0 there).
    if (s == run.reference && DatumOnReference(run)) {
      degree = run.start_degree;
      continue;
    }
    std::set<int> held = run.fixed_entries[s];
    held.insert(run.datum_entries[s].begin(), run.datum_entries[s].end());
    const calib::BlockId block = run.sensor.DetectorBlocks()[s];
    degree = TopDownWaldDegree(run.sensor.Detectors()[s].data(),
                               run.cov.BlockCovariance(block, 2 * kLineMaxTerms),
                               axis,
                               run.start_degree,
                               held,
                               run.options.degree_test_alpha);
    for (int k = degree + 1; k <= run.start_degree; ++k)
      if (run.fixed_entries[s].insert(axis * kLineMaxTerms + k).second) changed = true;
  }
  return changed;
}

}  // namespace

// The start-degree table is kept for the sigmas of the selected one (SelectedTableSigma).
void ApplyDegreeTest(LineRun& run) {
  auto& test = run.result.degree_test;
  test.start_degree = run.start_degree;
  test.alpha = run.options.degree_test_alpha;
  if (run.options.degree || !run.cov.ok || !(run.result.report.sigma0 > 1e-9)) {
    for (auto& s : run.result.subcameras) s.degree_x = s.degree_y = run.start_degree;
    return;
  }
  test.applied = true;
  bool changed = false;
  for (int s = 0; s < run.n_sub; ++s) changed |= TestSubcameraDegrees(run, s);
  if (!changed) return;
  test.reduced = true;
  run.start_table = DetectorTable(run, run.cov);
  ApplyFixedEntries(run);
  // Fewer terms can remove a gauge direction (e.g. a roll needs x^2 in every sub-camera): the
  // datum follows the reduced problem's null space.
  DeriveDatum(run);
  SolveAndEstimateCovariance(run);
}

void RmsBySubcamera(LineRun& run, bool after) {
  const int n_sub = run.n_sub;
  std::vector<double> sx(n_sub, 0), sy(n_sub, 0);
  std::vector<int> n(n_sub, 0);
  for (size_t k = 0; k < run.image_residuals.size(); ++k) {
    const auto r = run.builder.EvaluateResidual(run.image_residuals[k]);
    if (r.size() != 2) continue;
    const int s = run.sensor.Terms()[k].subcamera;
    sx[s] += r[0] * r[0];
    sy[s] += r[1] * r[1];
    ++n[s];
  }
  run.result.subcameras.resize(n_sub);
  for (int s = 0; s < n_sub; ++s) {
    auto& out = run.result.subcameras[s];
    out.id = run.sub_ids[s];
    out.first = run.ranges[s].first;
    out.last = run.ranges[s].second;
    out.n = n[s];
    const double ax = n[s] ? std::sqrt(sx[s] / n[s]) : 0, ay = n[s] ? std::sqrt(sy[s] / n[s]) : 0;
    (after ? out.across_after_px : out.across_before_px) = ax;
    (after ? out.along_after_px : out.along_before_px) = ay;
  }
}

// The median is the upper middle value of an even count (not calib/core/median.h's mean of the
// two): the figures written since issue 17 keep their values.
void ScaleToPixels(LineRun& run, const std::vector<LineObservation>& observations) {
  std::vector<double> sigmas;
  for (const auto& o : observations) sigmas.push_back(o.sigma_px);
  std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
  const double median_sigma_px = sigmas[sigmas.size() / 2];
  run.result.sigma0_px = run.result.report.sigma0 * median_sigma_px;
  for (auto& s : run.result.subcameras) {
    s.across_before_px *= median_sigma_px;
    s.along_before_px *= median_sigma_px;
    s.across_after_px *= median_sigma_px;
    s.along_after_px *= median_sigma_px;
  }
}

namespace {

// No covariance: not valid. Without the datum the singular direction is known: a constant
// along-track offset of all detectors IS a pitch of the strip (exactly, for a line at y = 0);
// without a covariance its correlation cannot be computed, so it is named with the value it has
// in the model.
void WarnNoCovariance(LineRun& run) {
  auto& result = run.result;
  result.valid = false;
  result.warnings.push_back({"covariance",
                             "adjustment",
                             0,
                             0,
                             "no covariance (singular normal matrix?): " + run.cov.message});
  if (run.options.datum == LineDatum::kNone)
    result.warnings.push_back({"offset_vs_pitch",
                               "detector polynomials",
                               1.0,
                               run.options.correlation_fail,
                               "ill-posed: no datum and a singular normal matrix: a constant "
                               "along-track offset of the detectors is a pitch of the strip"});
}

}  // namespace

void CheckSolve(LineRun& run) {
  auto& result = run.result;
  const auto& report = result.report;
  const auto& cov = run.cov;
  if (!report.converged) {
    result.valid = false;
    result.warnings.push_back({"not_converged",
                               "adjustment",
                               double(report.iterations),
                               0,
                               "the adjustment did not converge: " + report.message});
  }
  if (report.sigma0 > run.options.max_sigma0) {
    result.valid = false;
    result.warnings.push_back(
        {"sigma0",
         "adjustment",
         report.sigma0,
         run.options.max_sigma0,
         "sigma0 is far above 1: the a-priori sigmas or the model are wrong"});
  }
  if (!cov.ok && report.usable) WarnNoCovariance(run);
  result.undetermined = cov.undetermined;
  if (!cov.undetermined.empty()) {
    result.valid = false;
    result.warnings.push_back({"undetermined",
                               cov.undetermined.front(),
                               double(cov.undetermined.size()),
                               0,
                               std::to_string(cov.undetermined.size()) +
                                   " parameters are not determined (null space), first " +
                                   cov.undetermined.front()});
  }
}

}  // namespace aerocal::triangulation::internal
