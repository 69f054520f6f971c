// The line-camera calibration's options, observation file and driver (line_calibration.h); its
// steps are in line_calibration_run.h (set-up, datum, solve, results, correlations) and its
// result file in line_calibration_json.cc.
#include "triangulation/pushbroom/line_calibration.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/pushbroom/line_calibration_run.h"

#include <sstream>

namespace aerocal::triangulation {
namespace {

using calib::kLineMaxTerms;

constexpr double kMaxPixel = 1e7;
constexpr double kMaxSigmaPx = 1e4;

}  // namespace

const char* LineDatumName(LineDatum datum) {
  switch (datum) {
    case LineDatum::kGauge:
      return "gauge";
    case LineDatum::kReference:
      return "reference";
    case LineDatum::kNone:
      return "none";
  }
  return "";
}

void LineCalibrationOptions::Validate() const {
  if (node_spacing_lines < 1)
    throw ConfigError("--node-spacing must be >= 1 line (got " +
                      std::to_string(node_spacing_lines) + ")");
  if (max_degree < 0 || max_degree >= kLineMaxTerms)
    throw ConfigError("--max-degree must be within 0 .. 5 (got " + std::to_string(max_degree) +
                      ")");
  if (degree && (*degree < 0 || *degree >= kLineMaxTerms))
    throw ConfigError("--degree must be within 0 .. 5 (got " + std::to_string(*degree) + ")");
  if (!(degree_test_alpha > 0 && degree_test_alpha < 0.5))
    throw ConfigError("--degree-alpha must be within (0, 0.5) (got " +
                      FormatNumber(degree_test_alpha) + ")");
  if (!(pos_sigma_m > 0) || !(pos_sigma_deg > 0))
    throw ConfigError("--pos-sigma-m and --pos-sigma-deg must be > 0");
  if (!(gauge_threshold > 0 && gauge_threshold <= 1e-3))
    throw ConfigError("--gauge-threshold must be within (0, 1e-3] (got " +
                      FormatNumber(gauge_threshold) + ")");
  if (min_observations_per_segment < 0) throw ConfigError("--min-per-segment must be >= 0");
  if (boresight == PlatformParamMode::kWeighted && !(boresight_sigma_rad > 0))
    throw ConfigError("--boresight-sigma-deg must be > 0 when --boresight is weighted (got " +
                      FormatNumber(boresight_sigma_rad * 180.0 / M_PI) + ")");
  if (lever_arm == PlatformParamMode::kWeighted && !(lever_arm_sigma_m > 0))
    throw ConfigError("--lever-arm-sigma-m must be > 0 when --lever-arm is weighted (got " +
                      FormatNumber(lever_arm_sigma_m) + ")");
}

void WriteLineObservations(const std::string& path,
                           const std::vector<LineObservation>& observations) {
  std::ostringstream out;
  out << "image,point,col,row,sigma_px\n";
  for (const auto& o : observations)
    out << "strip," << o.point << "," << FormatNumber(o.detector, 17) << ","
        << FormatNumber(o.line, 17) << "," << FormatNumber(o.sigma_px) << "\n";
  WriteFileAtomically(path, out.str());
}

std::vector<LineObservation> ReadLineObservations(const std::string& path,
                                                  double default_sigma_px) {
  const CsvTable t = CsvTable::Read(path);
  t.RequireColumns({"point", "col", "row"});
  t.RejectUnknownColumns({"image", "point", "col", "row", "sigma_px"});
  std::vector<LineObservation> out;
  for (const auto& row : t.rows()) {
    LineObservation o;
    o.source_line = row.line;
    o.point = t.String(row, "point");
    if (o.point.empty()) ThrowInputError(t.Where(row), "point id must not be empty");
    o.detector = t.Bounded(row, "col", -kMaxPixel, kMaxPixel);
    o.line = t.Bounded(row, "row", -kMaxPixel * 100, kMaxPixel * 100);
    o.sigma_px = default_sigma_px;
    if (const auto s = t.OptionalNumber(row, "sigma_px")) {
      if (!(*s > 0 && *s <= kMaxSigmaPx))
        ThrowInputError(t.Where(row),
                        "sigma_px must be > 0 and <= " + FormatNumber(kMaxSigmaPx) + " (got " +
                            FormatNumber(*s) + ")");
      o.sigma_px = *s;
    }
    out.push_back(o);
  }
  if (out.empty()) ThrowInputError({path, 1}, "no observations");
  return out;
}

// The steps in order (line_calibration_run.h). The degree test may drop terms, re-derive the datum
// and re-solve; the statistics and results are taken from the final solve.
LineCalibrationResult CalibrateLineCamera(const calib::LineCamera& camera,
                                          const PosTrajectory& pos,
                                          const std::vector<LineObservation>& observations,
                                          const std::vector<GroundPoint>& points,
                                          const LineCalibrationOptions& options,
                                          const std::string& observations_file) {
  using namespace internal;  // the steps (line_calibration_run.h)
  options.Validate();
  LineRun run(camera, pos, options, observations_file);
  run.sensor.RegisterBlocks(run.context);
  const auto control = AddControlPoints(run, points);
  const LineCoverage coverage = AddImageObservations(run, observations, control);
  // The kind's own residuals: POS priors on the node values, weighted boresight / lever arm.
  run.sensor.AddOwnResiduals(run.context);
  CheckCoverage(run, coverage);
  HoldEntriesAboveStartDegree(run);
  ApplyFixedEntries(run);
  DeriveDatum(run);
  RmsBySubcamera(run, /*after=*/false);  // at the POS and the file's camera
  SolveAndEstimateCovariance(run);
  ApplyDegreeTest(run);
  RmsBySubcamera(run, /*after=*/true);
  ScaleToPixels(run, observations);
  CheckSolve(run);
  CollectDetectorCalibration(run);
  CollectErrorSamples(run);
  CollectTrajectory(run);
  CollectMountedParameters(run);
  NameCorrelations(run);
  CollectUpdatedCamera(run);
  return std::move(run.result);
}

}  // namespace aerocal::triangulation
