#include "triangulation/pushbroom/line_calibration.h"

#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/problem/solve_statistics_json.h"
#include "calib/residuals/prior.h"
#include "triangulation/pushbroom/line_degree_choice.h"
#include "triangulation/sensor/frame_camera.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

namespace aerocal::triangulation {
namespace {

using calib::BlockId;
using calib::kLineMaxTerms;
using calib::kLineNodeSize;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr double kMaxPixel = 1e7;
constexpr double kMaxSigmaPx = 1e4;
// Sigma of the datum pseudo-observations (LineDatumResidual), px: tight against a table sigma of
// ~1e-3 .. 1e-2 px, loose enough for the normal matrix (its weight ~ that of an angle).
constexpr double kDatumSigmaPx = 1e-4;

// u in [-1, 1] of detector i in its sub-camera's range (module README "The model").
double NormalisedIndex(const std::pair<int, int>& range, int i) {
  return calib::LinePolynomial{range.first, range.second, {}, {}}.Normalised(i);
}

struct Problem {
  calib::ProblemBuilder builder;
  std::vector<Eigen::Vector3d> point_values;
  std::vector<calib::ResidualId> image_residuals;  // in the order of the kind's Terms()
  std::vector<std::set<int>> fixed_entries;        // per detector block
  std::vector<std::set<int>> datum_entries;        // per detector block: held by the datum
};

// Singular values of a constraint's restriction to the null space (Jacobi-scaled, the null
// vectors orthonormal) above this: the constraint holds every gauge direction firmly.
constexpr double kDatumReach = 1e-3;

// The gauge functions of the detector table at the current detector positions (x_i, y_i) and c
// (first order): a rotation of the camera frame about x (pitch), y (roll), z (yaw) and a scale of
// the focal plane; 2N values, dx of every detector then dy, mm per unit.
struct GaugeFunction {
  const char* name;
  const char* meaning;
  Eigen::VectorXd values;
};
std::vector<GaugeFunction> TableGaugeFunctions(const calib::LineCamera& camera,
                                               const LineScanCamera& sensor,
                                               const std::vector<std::pair<int, int>>& ranges) {
  const int n = camera.detectors;
  const double c = sensor.CMm();
  std::vector<GaugeFunction> out = {
      {"pitch",
       "a rotation about the line (camera x): dy = c + y^2/c, a constant along track",
       Eigen::VectorXd::Zero(2 * n)},
      {"roll",
       "a rotation about the flight direction (camera y): dx = -(c + x^2/c), the across-"
       "track shift 1 + x^2/c^2 together",
       Eigen::VectorXd::Zero(2 * n)},
      {"yaw",
       "a rotation about the camera axis (z): dx = -y, dy = x, a slope along track",
       Eigen::VectorXd::Zero(2 * n)},
      {"scale",
       "a scale of the focal plane (dx = x, dy = y), which c and the heights may fix",
       Eigen::VectorXd::Zero(2 * n)}};
  for (size_t s = 0; s < ranges.size(); ++s)
    for (int i = ranges[s].first; i <= ranges[s].second; ++i) {
      const double u = NormalisedIndex(ranges[s], i);
      const double* a = sensor.Detectors()[s].data();
      const Eigen::Vector2d xy =
          camera.DetectorPosition(i) +
          Eigen::Vector2d(calib::EvaluatePolynomial(a, kLineMaxTerms, u),
                          calib::EvaluatePolynomial(a + kLineMaxTerms, kLineMaxTerms, u));
      const double x = xy.x(), y = xy.y();
      out[0].values(i) = x * y / c;
      out[0].values(n + i) = c + y * y / c;
      out[1].values(i) = -(c + x * x / c);
      out[1].values(n + i) = -x * y / c;
      out[2].values(i) = -y;
      out[2].values(n + i) = x;
      out[3].values(i) = x;
      out[3].values(n + i) = y;
    }
  return out;
}

// The detector-table part of the null vectors (2N x k, mm): each sub-camera's polynomial
// components evaluated at its detectors.
Eigen::MatrixXd NullSpaceInTable(const calib::NullSpaceReport& null_space,
                                 const LineScanCamera& sensor,
                                 const std::vector<std::pair<int, int>>& ranges,
                                 int detectors) {
  Eigen::MatrixXd f = Eigen::MatrixXd::Zero(2 * detectors, null_space.rank_defect);
  for (size_t s = 0; s < ranges.size(); ++s) {
    const auto it = null_space.vectors.find(sensor.DetectorBlocks()[s]);
    if (it == null_space.vectors.end()) continue;
    for (int j = 0; j < null_space.rank_defect; ++j)
      for (int i = ranges[s].first; i <= ranges[s].second; ++i) {
        const double u = NormalisedIndex(ranges[s], i);
        const Eigen::VectorXd v = it->second.col(j);
        f(i, j) = calib::EvaluatePolynomial(v.data(), kLineMaxTerms, u);
        f(detectors + i, j) = calib::EvaluatePolynomial(v.data() + kLineMaxTerms, kLineMaxTerms, u);
      }
  }
  return f;
}

// Names the gauge functions the null space holds (LineDatumReport::directions, in_table).
void NameGaugeDirections(const calib::NullSpaceReport& null_space,
                         const calib::LineCamera& camera,
                         const LineScanCamera& sensor,
                         const std::vector<std::pair<int, int>>& ranges,
                         LineDatumReport* report) {
  report->directions.clear();
  report->in_table = 0;
  if (null_space.rank_defect == 0) return;
  const Eigen::MatrixXd f = NullSpaceInTable(null_space, sensor, ranges, camera.detectors);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(f, Eigen::ComputeThinU);
  const Eigen::VectorXd sv = svd.singularValues();
  int rank = 0;
  while (rank < sv.size() && sv(rank) > 1e-6 * sv(0) && sv(0) > 0) ++rank;
  report->in_table = rank;
  const Eigen::MatrixXd basis = svd.matrixU().leftCols(rank);
  for (const auto& g : TableGaugeFunctions(camera, sensor, ranges)) {
    const double norm = g.values.norm();
    if (!(norm > 0) || rank == 0) continue;
    const double fraction = (basis * (basis.transpose() * g.values)).norm() / norm;
    if (fraction > 0.999) report->directions.push_back({g.name, fraction, g.meaning});
  }
}

// The minimal datum of the gauge mode: exactly k = rank defect constraints, on the first of
// `candidates` (in order) that together reach every null direction (the singular values of the
// null vectors restricted to them, Jacobi-scaled, above kDatumReach): the projection of those
// parameters onto the null space's span there is held at its current value. Unit sigma in the
// Jacobi-scaled coordinates (the constraint does not compete with the data: it acts on the null
// space only). Returns the residual id, -1 when k = 0 or the candidates do not reach it.
calib::ResidualId AddGaugeDatum(calib::ProblemBuilder& builder,
                                const calib::NullSpaceReport& null_space,
                                const std::vector<BlockId>& candidates,
                                const std::string& label,
                                LineDatumReport* report) {
  const int k = null_space.rank_defect;
  report->n_constraints = 0;
  report->blocks.clear();
  if (k == 0) return -1;
  std::vector<BlockId> used;
  Eigen::MatrixXd w(0, k);
  bool reached = false;
  for (BlockId block : candidates) {
    const auto it = null_space.scaled.find(block);
    if (it == null_space.scaled.end() || it->second.cwiseAbs().maxCoeff() == 0.0) continue;
    used.push_back(block);
    Eigen::MatrixXd grown(w.rows() + it->second.rows(), k);
    grown.topRows(w.rows()) = w;
    grown.bottomRows(it->second.rows()) = it->second;
    w = grown;
    if (w.rows() >= k) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(w);
      if (svd.singularValues()(k - 1) > kDatumReach) {
        reached = true;
        break;
      }
    }
  }
  if (!reached) {
    report->message = "the gauge directions are not reached by the datum's candidate blocks";
    return -1;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(w, Eigen::ComputeThinU);
  const Eigen::MatrixXd u = svd.matrixU().leftCols(k);
  std::vector<Eigen::MatrixXd> weights;
  std::vector<Eigen::VectorXd> origins;
  int row = 0;
  for (BlockId block : used) {
    const int size = builder.BlockSize(block);
    weights.push_back(u.middleRows(row, size).transpose() *
                      null_space.scale.at(block).asDiagonal());
    origins.push_back(Eigen::Map<const Eigen::VectorXd>(builder.BlockValues(block), size));
    report->blocks.push_back(builder.BlockName(block));
    row += size;
  }
  report->n_constraints = k;
  return builder.AddResidual(
      kGroupLineDatum,
      std::make_unique<calib::LinearConstraintCostFunction>(weights, origins, 1.0),
      used,
      label);
}

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

LineCalibrationResult CalibrateLineCamera(const calib::LineCamera& camera,
                                          const PosTrajectory& pos,
                                          const std::vector<LineObservation>& observations,
                                          const std::vector<GroundPoint>& points,
                                          const LineCalibrationOptions& options,
                                          const std::string& observations_file) {
  options.Validate();
  LineCalibrationResult result;
  const auto ranges = camera.Ranges();
  const int n_sub = int(ranges.size());
  const int reference = options.reference_subcamera >= 0 ? options.reference_subcamera : n_sub / 2;
  if (reference >= n_sub)
    throw ConfigError("--reference must be a sub-camera index within 0 .. " +
                      std::to_string(n_sub - 1));
  std::vector<std::string> sub_ids;
  for (int s = 0; s < n_sub; ++s)
    sub_ids.push_back(camera.subcameras.empty() ? std::to_string(s) : camera.subcameras[s].id);

  const double first_line = pos.first_line(), last_line = pos.last_line();
  const int spacing = options.node_spacing_lines;
  const int n_nodes = calib::SplineNodeCount(last_line - first_line, spacing);

  // The line camera as a sensor kind (triangulation/sensor/line_scan_camera.h): it owns the
  // spline nodes, detector polynomials, c, mount and lever arm, and builds the residual of every
  // observation; the calibration owns the control points, the datum, the degree test and the
  // report. A line strip is not a block of frame exposures: its SensorContext has an empty
  // project (the observations file named in errors) and no exposure poses.
  LineScanOptions line_options;
  line_options.node_spacing_lines = spacing;
  line_options.free_c = options.free_c;
  line_options.pos_prior = options.pos_prior;
  line_options.pos_sigma_center_m =
      pos.MedianCenterSigma().value_or(Eigen::Vector3d::Constant(options.pos_sigma_m));
  line_options.pos_sigma_opk_rad = pos.MedianOpkSigma().value_or(
      Eigen::Vector3d::Constant(options.pos_sigma_deg * M_PI / 180.0));
  line_options.boresight = options.boresight;
  line_options.boresight_sigma_rad = options.boresight_sigma_rad;
  line_options.lever_arm = options.lever_arm;
  line_options.lever_arm_sigma_m = options.lever_arm_sigma_m;
  line_options.time_offset = options.time_offset;
  LineScanCamera sensor(camera, pos, line_options);
  Problem p;
  p.fixed_entries.assign(n_sub, {});
  p.datum_entries.assign(n_sub, {});
  Project strip;
  strip.observations_file = observations_file;
  const AdjustOptions adjust_options{};
  const DenseIndex dense_index(strip);
  const std::vector<PoseBlocks> no_poses;
  const FrameCamera no_frame{};
  const SensorContext context{strip, adjust_options, p.builder, dense_index, no_poses, no_frame};
  auto& b = p.builder;
  sensor.RegisterBlocks(context);

  // Control points: weighted ground points. Other roles cannot be used by a single line camera
  // (one ray per point): their observations are ignored and counted.
  std::map<std::string, int> point_index;
  std::vector<const GroundPoint*> control;
  for (const auto& g : points)
    if (g.role == PointRole::kControl && g.xyz_m) {
      point_index[g.id] = int(control.size());
      control.push_back(&g);
    }
  p.point_values.resize(control.size());
  for (size_t k = 0; k < control.size(); ++k) p.point_values[k] = *control[k]->xyz_m;

  std::vector<BlockId> point_blocks(control.size());
  for (size_t k = 0; k < control.size(); ++k) {
    point_blocks[k] = b.AddBlock("point_" + control[k]->id,
                                 p.point_values[k].data(),
                                 3,
                                 calib::BlockKind::kGroundPoint,
                                 {"X", "Y", "Z"});
    const Eigen::Vector3d& v = *control[k]->xyz_m;
    const Eigen::Vector3d& s = control[k]->sigma_m;
    b.AddResidual(calib::kGroupControl,
                  calib::PriorCostFunction::Create({v.x(), v.y(), v.z()}, {s.x(), s.y(), s.z()}),
                  {point_blocks[k]},
                  "control " + control[k]->id);
  }

  // Image observations: each built by the kind (through the interface), added under its group.
  std::vector<int> per_segment(n_nodes, 0);
  std::vector<int> per_node(n_nodes, 0);
  for (const auto& o : observations) {
    const SourceRef where{observations_file, o.source_line};
    const auto it = point_index.find(o.point);
    if (it == point_index.end()) {
      ++result.n_ignored;
      continue;
    }
    ImageObservation observation;
    observation.image = kLineStripImage;
    observation.point = o.point;
    observation.pixel = Eigen::Vector2d(o.detector, o.line);
    observation.sigma_px = o.sigma_px;
    observation.line = o.source_line;
    ObservationTerm term = sensor.Observe(context, observation, point_blocks[it->second]);
    const int j = sensor.Terms().back().segment;
    ++per_segment[j];
    for (int m = 0; m < 4; ++m) ++per_node[j + m];
    const auto id =
        b.AddResidual(term.group, std::move(term.cost), term.blocks, "point " + o.point);
    p.image_residuals.push_back(id);
    // The start must be a valid geometry (the point in front of the camera).
    if (b.EvaluateResidual(id).empty())
      ThrowInputError(where,
                      "point " + o.point + " lies behind the camera at line " +
                          FormatNumber(o.line) + " with the POS and the file's camera");
  }
  result.n_observations = int(p.image_residuals.size());
  result.n_control = int(control.size());
  if (p.image_residuals.empty())
    throw InputError(observations_file + ": no observation of a control point (" +
                     std::to_string(result.n_ignored) + " observations of other points ignored)");

  // The kind's own residuals: POS priors on the node values, weighted boresight / lever arm.
  sensor.AddOwnResiduals(context);

  // Too few points per line: per spline segment; a node no observation reaches is undetermined
  // without the POS prior (it is then fixed at 0 and the result is not valid).
  for (int j = 0; j + 3 < n_nodes; ++j) {
    const double a = first_line + j * spacing, z = std::min(last_line, a + spacing - 1);
    if (a > last_line) break;
    if (per_segment[j] < options.min_observations_per_segment)
      result.warnings.push_back({"few_points_per_line",
                                 "lines " + FormatNumber(a) + " .. " + FormatNumber(z),
                                 double(per_segment[j]),
                                 double(options.min_observations_per_segment),
                                 "only " + std::to_string(per_segment[j]) +
                                     " observations between two spline nodes: the per-line "
                                     "corrections there rest on the POS prior"});
  }
  for (int j = 0; j < n_nodes; ++j)
    if (per_node[j] == 0 && !options.pos_prior) {
      b.FixBlock(sensor.NodeBlocks()[j]);
      result.valid = false;
      result.warnings.push_back(
          {"few_points_per_line",
           "node " + std::to_string(j),
           0,
           1,
           "no observation reaches spline node " + std::to_string(j) +
               " and there is no POS prior: its correction is not determined"});
    }

  // Fixed detector entries: above the degree. The datum (module README "Datum"): the reference
  // sub-camera's Legendre mean and slope per axis are zero (LineDatumResidual), which holds the
  // same whatever degree the test leaves; its constant and linear entries follow the higher
  // terms (a_0 = -a_2/3 - a_4/5, a_1 = -3 a_3/5 - 3 a_5/7) and do not enter the test.
  const int start_degree = options.degree.value_or(options.max_degree);
  auto apply_fixed = [&]() {
    for (int s = 0; s < n_sub; ++s) {
      sensor.SetFixedDetectorEntries(
          b, s, std::vector<int>(p.fixed_entries[s].begin(), p.fixed_entries[s].end()));
    }
  };
  for (int s = 0; s < n_sub; ++s) {
    for (int k = start_degree + 1; k < kLineMaxTerms; ++k) {
      p.fixed_entries[s].insert(k);
      p.fixed_entries[s].insert(kLineMaxTerms + k);
    }
    if (options.datum == LineDatum::kReference && s == reference)
      p.datum_entries[s] = {0, 1, kLineMaxTerms, kLineMaxTerms + 1};
  }
  apply_fixed();
  // The datum (module README "Datum"): the null space of the problem as configured, without a
  // datum, is always computed and reported; the gauge mode constrains exactly its directions.
  result.datum.mode = options.datum;
  result.datum.subcamera = sub_ids[reference];
  calib::ResidualId datum_residual = -1;
  bool time_offset_in_null_space = false;
  std::vector<BlockId> datum_candidates = {sensor.DetectorBlocks()[reference],
                                           sensor.MountBlock(),
                                           sensor.LeverArmBlock(),
                                           sensor.CBlock()};
  datum_candidates.insert(
      datum_candidates.end(), sensor.NodeBlocks().begin(), sensor.NodeBlocks().end());
  auto derive_datum = [&]() {
    if (datum_residual >= 0) b.RemoveResidual(datum_residual);
    datum_residual = -1;
    const calib::NullSpaceReport null_space = b.NullSpace(options.gauge_threshold);
    auto& d = result.datum;
    d.null_space_computed = null_space.ok;
    d.message = null_space.message;
    d.threshold = options.gauge_threshold;
    d.rank_defect = null_space.rank_defect;
    d.smallest_relative_eigenvalues = null_space.smallest_relative_eigenvalues;
    NameGaugeDirections(null_space, camera, sensor, ranges, &d);
    // A parameter the user asked to estimate that lies in the null space is not determined by
    // the data (a datum only sets it by convention): named, the result is not valid. E.g. the
    // time offset or the lever arm without POS priors (a constant along-track shift / position
    // of the trajectory), c (the focal plane's scale), the boresight (a rotation of the table).
    auto in_null_space = [&](BlockId block) {
      const auto it = null_space.scaled.find(block);
      return it != null_space.scaled.end() && it->second.rows() > 0 && it->second.cols() > 0 &&
             Eigen::JacobiSVD<Eigen::MatrixXd>(it->second).singularValues()(0) > kDatumReach;
    };
    time_offset_in_null_space = in_null_space(sensor.TimeOffsetBlock());
    d.parameters_in_null_space.clear();
    const std::pair<BlockId, const char*> own[] = {{sensor.CBlock(), "c"},
                                                   {sensor.MountBlock(), "boresight"},
                                                   {sensor.LeverArmBlock(), "lever_arm"}};
    for (const auto& [block, name] : own)
      if (in_null_space(block)) d.parameters_in_null_space.push_back(name);
    if (time_offset_in_null_space) d.parameters_in_null_space.push_back("time_offset");
    if (options.datum == LineDatum::kGauge && null_space.ok)
      datum_residual =
          AddGaugeDatum(b, null_space, datum_candidates, "datum " + sub_ids[reference], &d);
    if (options.datum == LineDatum::kReference) {
      d.n_constraints = 4;
      d.blocks = {b.BlockName(sensor.DetectorBlocks()[reference])};
      datum_residual = b.AddResidual(kGroupLineDatum,
                                     LineDatumResidual::Create(kDatumSigmaPx * camera.pitch_mm),
                                     {sensor.DetectorBlocks()[reference]},
                                     "datum " + sub_ids[reference]);
    }
  };
  derive_datum();
  // The sub-camera carrying the constraints keeps the start degree (the degree test leaves it).
  auto datum_on_reference = [&]() {
    return std::find(result.datum.blocks.begin(),
                     result.datum.blocks.end(),
                     b.BlockName(sensor.DetectorBlocks()[reference])) != result.datum.blocks.end();
  };

  // Reprojection before: at the POS and the file's camera.
  auto rms_by_subcamera = [&](bool after) {
    std::vector<double> sx(n_sub, 0), sy(n_sub, 0);
    std::vector<int> n(n_sub, 0);
    for (size_t k = 0; k < p.image_residuals.size(); ++k) {
      const auto r = b.EvaluateResidual(p.image_residuals[k]);
      if (r.size() != 2) continue;
      const int s = sensor.Terms()[k].subcamera;
      sx[s] += r[0] * r[0];
      sy[s] += r[1] * r[1];
      ++n[s];
    }
    result.subcameras.resize(n_sub);
    for (int s = 0; s < n_sub; ++s) {
      auto& out = result.subcameras[s];
      out.id = sub_ids[s];
      out.first = ranges[s].first;
      out.last = ranges[s].second;
      out.n = n[s];
      const double ax = n[s] ? std::sqrt(sx[s] / n[s]) : 0, ay = n[s] ? std::sqrt(sy[s] / n[s]) : 0;
      (after ? out.across_after_px : out.across_before_px) = ax;
      (after ? out.along_after_px : out.along_before_px) = ay;
    }
  };
  rms_by_subcamera(false);

  std::vector<BlockId> cov_blocks = sensor.NodeBlocks();
  cov_blocks.insert(
      cov_blocks.end(), sensor.DetectorBlocks().begin(), sensor.DetectorBlocks().end());
  cov_blocks.push_back(sensor.CBlock());
  if (options.boresight != PlatformParamMode::kFixed) cov_blocks.push_back(sensor.MountBlock());
  if (options.lever_arm != PlatformParamMode::kFixed) cov_blocks.push_back(sensor.LeverArmBlock());
  if (options.time_offset) cov_blocks.push_back(sensor.TimeOffsetBlock());

  result.report = b.Solve(options.solver);
  calib::CovarianceReport cov;
  if (result.report.usable) cov = b.EstimateCovariance(cov_blocks, result.report.sigma0);

  // The per-detector table (values and variances, axis-major) at the current solution.
  auto detector_table = [&](const calib::CovarianceReport& c) {
    std::vector<TableValue> table(2 * size_t(camera.detectors));
    for (int s = 0; s < n_sub; ++s) {
      const Eigen::MatrixXd q =
          c.ok ? c.BlockCovariance(sensor.DetectorBlocks()[s], 2 * kLineMaxTerms)
               : Eigen::MatrixXd();
      for (int i = ranges[s].first; i <= ranges[s].second; ++i)
        for (int axis = 0; axis < 2; ++axis)
          table[axis * size_t(camera.detectors) + i] = EvaluateDetectorPolynomial(
              sensor.Detectors()[s].data(), q, axis, NormalisedIndex(ranges[s], i));
    }
    return table;
  };

  // Degree test (line_degree_choice.h), per sub-camera and axis. Not applicable when sigma0 is ~0
  // (noise-free data): the start degree. The start-degree table is kept for the sigmas of the
  // selected one (SelectedTableSigma).
  std::vector<TableValue> start_table;
  result.degree_test.start_degree = start_degree;
  result.degree_test.alpha = options.degree_test_alpha;
  if (!options.degree && cov.ok && result.report.sigma0 > 1e-9) {
    result.degree_test.applied = true;
    bool changed = false;
    for (int s = 0; s < n_sub; ++s)
      for (int axis = 0; axis < 2; ++axis) {
        int& degree = axis == 0 ? result.subcameras[s].degree_x : result.subcameras[s].degree_y;
        // The datum sub-camera keeps the start degree: a term dropped there (insignificant, yet
        // real) is a bias the sigmas do not show, and the datum pins its correction where the
        // Legendre terms kept vanish (degree 2: u = +-1/sqrt(3), sigma ~0 there).
        if (s == reference && datum_on_reference()) {
          degree = start_degree;
          continue;
        }
        std::set<int> held = p.fixed_entries[s];
        held.insert(p.datum_entries[s].begin(), p.datum_entries[s].end());
        degree =
            TopDownWaldDegree(sensor.Detectors()[s].data(),
                              cov.BlockCovariance(sensor.DetectorBlocks()[s], 2 * kLineMaxTerms),
                              axis,
                              start_degree,
                              held,
                              options.degree_test_alpha);
        for (int k = degree + 1; k <= start_degree; ++k)
          if (p.fixed_entries[s].insert(axis * kLineMaxTerms + k).second) changed = true;
      }
    if (changed) {
      result.degree_test.reduced = true;
      start_table = detector_table(cov);
      apply_fixed();
      // Fewer terms can remove a gauge direction (e.g. a roll needs x^2 in every sub-camera):
      // the datum follows the reduced problem's null space.
      derive_datum();
      result.report = b.Solve(options.solver);
      cov = result.report.usable ? b.EstimateCovariance(cov_blocks, result.report.sigma0)
                                 : calib::CovarianceReport{};
    }
  } else {
    for (auto& s : result.subcameras) s.degree_x = s.degree_y = start_degree;
  }
  rms_by_subcamera(true);

  // sigma0 in px: the whitened residuals times the median image sigma.
  std::vector<double> sigmas;
  for (const auto& o : observations) sigmas.push_back(o.sigma_px);
  std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
  const double median_sigma_px = sigmas[sigmas.size() / 2];
  result.sigma0_px = result.report.sigma0 * median_sigma_px;
  for (auto& s : result.subcameras) {
    s.across_before_px *= median_sigma_px;
    s.along_before_px *= median_sigma_px;
    s.across_after_px *= median_sigma_px;
    s.along_after_px *= median_sigma_px;
  }

  if (!result.report.converged) {
    result.valid = false;
    result.warnings.push_back({"not_converged",
                               "adjustment",
                               double(result.report.iterations),
                               0,
                               "the adjustment did not converge: " + result.report.message});
  }
  if (result.report.sigma0 > options.max_sigma0) {
    result.valid = false;
    result.warnings.push_back(
        {"sigma0",
         "adjustment",
         result.report.sigma0,
         options.max_sigma0,
         "sigma0 is far above 1: the a-priori sigmas or the model are wrong"});
  }
  if (!cov.ok && result.report.usable) {
    result.valid = false;
    result.warnings.push_back({"covariance",
                               "adjustment",
                               0,
                               0,
                               "no covariance (singular normal matrix?): " + cov.message});
    // Without the datum the singular direction is known: a constant along-track offset of all
    // detectors IS a pitch of the strip (exactly, for a line at y = 0); without a covariance its
    // correlation cannot be computed, so it is named with the value it has in the model.
    if (options.datum == LineDatum::kNone)
      result.warnings.push_back({"offset_vs_pitch",
                                 "detector polynomials",
                                 1.0,
                                 options.correlation_fail,
                                 "ill-posed: no datum and a singular normal matrix: a constant "
                                 "along-track offset of the detectors is a pitch of the strip"});
  }
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

  // Sigmas of the coefficients and the per-detector table.
  auto entry_sigma = [&](BlockId block, int entry) -> std::optional<double> {
    if (!cov.ok) return std::nullopt;
    const auto it = cov.offsets.find(block);
    if (it == cov.offsets.end() || !cov.free[it->second + entry]) return std::nullopt;
    return cov.sigma[it->second + entry];
  };
  for (int s = 0; s < n_sub; ++s) {
    auto& out = result.subcameras[s];
    out.dx_coefficients_mm.assign(sensor.Detectors()[s].begin(),
                                  sensor.Detectors()[s].begin() + kLineMaxTerms);
    out.dy_coefficients_mm.assign(sensor.Detectors()[s].begin() + kLineMaxTerms,
                                  sensor.Detectors()[s].end());
    for (int k = 0; k < kLineMaxTerms; ++k) {
      out.dx_sigma_mm.push_back(entry_sigma(sensor.DetectorBlocks()[s], k));
      out.dy_sigma_mm.push_back(entry_sigma(sensor.DetectorBlocks()[s], kLineMaxTerms + k));
    }
  }
  result.dx_mm.resize(camera.detectors);
  result.dy_mm.resize(camera.detectors);
  result.dx_sigma_mm.resize(camera.detectors);
  result.dy_sigma_mm.resize(camera.detectors);
  result.dx_fit_sigma_mm.resize(camera.detectors);
  result.dy_fit_sigma_mm.resize(camera.detectors);
  const std::vector<TableValue> table = detector_table(cov);
  for (int s = 0; s < n_sub; ++s) {
    for (int axis = 0; axis < 2; ++axis) {
      // No free term beyond the datum's: the correction is fixed (sigma 0), not the datum
      // pseudo-observations' own ~1e-4 px.
      bool estimated = false;
      for (int k = 0; k < kLineMaxTerms; ++k) {
        const int e = axis * kLineMaxTerms + k;
        estimated |= !p.fixed_entries[s].count(e) && !p.datum_entries[s].count(e);
      }
      for (int i = ranges[s].first; i <= ranges[s].second; ++i) {
        const size_t j = axis * size_t(camera.detectors) + i;
        const Eigen::Vector2d base = camera.Correction(i);
        (axis == 0 ? result.dx_mm : result.dy_mm)[i] = base[axis] + table[j].value;
        if (!cov.ok) continue;
        auto& sigma = (axis == 0 ? result.dx_sigma_mm : result.dy_sigma_mm)[i];
        auto& fit_sigma = (axis == 0 ? result.dx_fit_sigma_mm : result.dy_fit_sigma_mm)[i];
        fit_sigma = estimated ? std::sqrt(table[j].variance) : 0.0;
        // After a degree test: at least the start-degree fit's sigma (line_degree_choice.h).
        sigma = start_table.empty() ? *fit_sigma : SelectedTableSigma(table[j], start_table[j]);
      }
    }
  }

  // Error samples (plots): the fitted correction at the measured position minus the residual,
  // i.e. what remains without the detector calibration, in pitches.
  for (size_t k = 0; k < p.image_residuals.size(); ++k) {
    const auto r = b.EvaluateResidual(p.image_residuals[k]);
    if (r.size() != 2) continue;
    const int s = sensor.Terms()[k].subcamera;
    const double u = sensor.Terms()[k].u;
    const Eigen::Vector2d base = camera.Correction(sensor.Terms()[k].detector);
    const double dx =
        base.x() + calib::EvaluatePolynomial(sensor.Detectors()[s].data(), kLineMaxTerms, u);
    const double dy =
        base.y() +
        calib::EvaluatePolynomial(sensor.Detectors()[s].data() + kLineMaxTerms, kLineMaxTerms, u);
    result.error_samples.push_back(
        {sensor.Terms()[k].detector,
         s,
         (dx - r[0] * sensor.Terms()[k].sigma_mm.x()) / camera.pitch_mm,
         (dy - r[1] * sensor.Terms()[k].sigma_mm.y()) / camera.pitch_mm});
  }

  // Spline nodes and per-line corrections with sigmas.
  for (int j = 0; j < n_nodes; ++j) {
    result.node_line.push_back(first_line + (j - 1) * double(spacing));
    result.node_values.push_back(sensor.Nodes()[j]);
    Vector6d sigma = Vector6d::Zero();
    if (cov.ok)
      for (int e = 0; e < 6; ++e) sigma[e] = entry_sigma(sensor.NodeBlocks()[j], e).value_or(0.0);
    result.node_sigma.push_back(sigma);
  }
  for (double line = first_line; line <= last_line + 1e-9; line += 1.0) {
    const calib::SplineSpan span = calib::CubicBSplineWeights(line - first_line, spacing);
    const int j = std::min(span.first_node, n_nodes - 4);
    Vector6d value = Vector6d::Zero();
    Eigen::Matrix<double, 6, 6> var = Eigen::Matrix<double, 6, 6>::Zero();
    for (int m = 0; m < 4; ++m) {
      value += span.weights[m] * sensor.Nodes()[j + m];
      if (!cov.ok) continue;
      for (int n = 0; n < 4; ++n) {
        Eigen::MatrixXd cross;
        if (cov.CrossCovariance(sensor.NodeBlocks()[j + m], sensor.NodeBlocks()[j + n], &cross))
          var += span.weights[m] * span.weights[n] * cross;
      }
    }
    result.lines.push_back(line);
    result.line_corrections.push_back(value);
    result.line_sigma.push_back(var.diagonal().cwiseMax(0.0).cwiseSqrt());
  }
  result.c_mm = sensor.CMm();
  if (options.free_c) result.c_sigma_mm = entry_sigma(sensor.CBlock(), 0);
  // Boresight and lever arm: values, sigmas (null when fixed or not determined).
  result.boresight = options.boresight;
  result.lever_arm = options.lever_arm;
  result.boresight_rad = sensor.MountRad();
  result.lever_arm_m = sensor.LeverArmM();
  auto block_sigma = [&](BlockId block) -> std::optional<Eigen::Vector3d> {
    Eigen::Vector3d sigma;
    for (int e = 0; e < 3; ++e) {
      const auto s = entry_sigma(block, e);
      if (!s) return std::nullopt;
      sigma[e] = *s;
    }
    return sigma;
  };
  if (options.boresight != PlatformParamMode::kFixed)
    result.boresight_sigma_rad = block_sigma(sensor.MountBlock());
  if (options.lever_arm != PlatformParamMode::kFixed)
    result.lever_arm_sigma_m = block_sigma(sensor.LeverArmBlock());
  // Requested parameters in the null space (derive_datum): not determined by the data.
  if (options.datum != LineDatum::kReference)
    for (const std::string& name : result.datum.parameters_in_null_space) {
      if (name == "time_offset") continue;  // below, with its own message
      result.valid = false;
      result.warnings.push_back({name + "_not_determinable",
                                 name,
                                 1.0,
                                 options.correlation_fail,
                                 "ill-posed: " + name +
                                     " lies in the null space of the problem "
                                     "(a gauge direction: its value is the datum's convention, not "
                                     "the data's; datum.gauge_directions says which)"});
    }
  result.time_offset_estimated = options.time_offset;
  result.time_offset_s = sensor.TimeOffsetS();
  if (options.time_offset && (!time_offset_in_null_space || options.datum == LineDatum::kReference))
    result.time_offset_sigma_s = entry_sigma(sensor.TimeOffsetBlock(), 0);
  if (time_offset_in_null_space && options.datum != LineDatum::kReference) {
    result.valid = false;
    result.time_offset_sigma_s.reset();
    result.warnings.push_back({"time_offset_not_determinable",
                               "time offset",
                               1.0,
                               options.correlation_fail,
                               "ill-posed: the time offset lies in the null space (an along-track "
                               "shift v dt the trajectory takes over entirely; the POS priors are "
                               "off)"});
  }

  // Named correlations: a detector polynomial's constant across-track term against the mean roll
  // correction of the strip (offset_vs_roll), its constant along-track term against the mean pitch
  // correction (offset_vs_pitch), its linear across-track term against c (scale_vs_c).
  // Roll is the rotation about the along-track axis: phi when the line lies along object X
  // (kappa ~ 0 or 180 deg), omega when it lies along Y.
  if (cov.ok) {
    double mean_kappa = 0;
    for (const auto& r : pos.records()) mean_kappa += r.opk_rad.z();
    mean_kappa /= double(pos.records().size());
    const bool line_along_x = std::abs(std::cos(mean_kappa)) >= std::abs(std::sin(mean_kappa));
    const int roll = line_along_x ? 4 : 3, pitch = line_along_x ? 3 : 4;
    // Correlation of two linear combinations of entries (block, entry, weight) of the covariance.
    using Combination = std::vector<std::tuple<BlockId, int, double>>;
    auto covariance = [&](const Combination& x, const Combination& y) {
      double sum = 0;
      Eigen::MatrixXd cross;
      for (const auto& [bx, ex, wx] : x)
        for (const auto& [by, ey, wy] : y)
          if (cov.CrossCovariance(bx, by, &cross)) sum += wx * wy * cross(ex, ey);
      return sum;
    };
    // Free and not held by the datum (its entries follow the higher terms).
    auto decides = [&](BlockId block, int entry) {
      for (int s = 0; s < n_sub; ++s)
        if (sensor.DetectorBlocks()[s] == block && p.datum_entries[s].count(entry)) return false;
      return entry_sigma(block, entry).has_value();
    };
    auto mean_free = [&](const std::vector<BlockId>& blocks, int entry) {
      Combination c;
      for (BlockId block : blocks)
        if (decides(block, entry)) c.emplace_back(block, entry, 1.0);
      for (auto& [block, e, w] : c) w = 1.0 / double(c.size());
      return c;
    };
    // Multiple correlation of a combination with a set of entries: how well the best linear
    // combination of the set explains it (1: the set can take it over entirely).
    auto multiple = [&](const Combination& x, const Combination& set) -> double {
      if (x.empty() || set.empty()) return -1;
      const double vx = covariance(x, x);
      if (!(vx > 0)) return -1;
      const int n = int(set.size());
      Eigen::MatrixXd cyy(n, n);
      Eigen::VectorXd cxy(n);
      for (int k = 0; k < n; ++k) {
        cxy[k] = covariance(x, {set[k]});
        for (int m = 0; m < n; ++m) cyy(k, m) = covariance({set[k]}, {set[m]});
      }
      const Eigen::VectorXd solved = cyy.completeOrthogonalDecomposition().solve(cxy);
      return std::sqrt(std::min(1.0, std::max(0.0, cxy.dot(solved) / vx)));
    };
    auto all_free = [&](const std::vector<BlockId>& blocks, int entry) {
      Combination c;
      for (BlockId block : blocks)
        if (decides(block, entry)) c.emplace_back(block, entry, 1.0);
      return c;
    };
    const double offset_roll =
        multiple(mean_free(sensor.DetectorBlocks(), 0), all_free(sensor.NodeBlocks(), roll));
    const double offset_pitch = multiple(mean_free(sensor.DetectorBlocks(), kLineMaxTerms),
                                         all_free(sensor.NodeBlocks(), pitch));
    double scale_c = -1;
    if (options.free_c && entry_sigma(sensor.CBlock(), 0)) {
      Combination set = all_free(sensor.DetectorBlocks(), 1);
      const Combination dz = all_free(sensor.NodeBlocks(), 2);
      set.insert(set.end(), dz.begin(), dz.end());
      scale_c = multiple({{sensor.CBlock(), 0, 1.0}}, set);
    }
    struct Named {
      std::string name;
      double rho;
      std::string meaning;
    };
    std::vector<Named> named = {
        {"offset_vs_roll",
         offset_roll,
         "a constant across-track offset of the detectors is a roll of the strip"},
        {"offset_vs_pitch",
         offset_pitch,
         "a constant along-track offset of the detectors is a pitch of the strip"},
        {"scale_vs_c", scale_c, "c and the detectors' linear term (or the height) are one scale"}};
    // The boresight and lever arm when estimated: multiple correlation of each entry with what
    // can take it over. The camera's x axis is the line (across track): the boresight phi (about
    // y) is its roll, omega its pitch.
    const BlockId mount = sensor.MountBlock(), lever = sensor.LeverArmBlock();
    if (entry_sigma(mount, 0)) {
      const char* angle[] = {"omega", "phi", "kappa"};
      for (int a = 0; a < 3; ++a)
        named.push_back({std::string("boresight_") + angle[a] + "_vs_attitude",
                         multiple({{mount, a, 1.0}}, all_free(sensor.NodeBlocks(), 3 + a)),
                         "a constant boresight angle is a constant attitude correction of the "
                         "trajectory (only the POS prior tells them apart)"});
      named.push_back(
          {"boresight_roll_vs_offset",
           multiple({{mount, 1, 1.0}}, all_free(sensor.DetectorBlocks(), 0)),
           "the boresight roll (phi) is a constant across-track offset of the detectors"});
      named.push_back(
          {"boresight_pitch_vs_offset",
           multiple({{mount, 0, 1.0}}, all_free(sensor.DetectorBlocks(), kLineMaxTerms)),
           "the boresight pitch (omega) is a constant along-track offset of the detectors"});
    }
    // The time offset: v dt is an along-track shift (the nodes' along-track position, its
    // drift included) and, seen from the height, a pitch; only the POS priors separate them.
    if (options.time_offset && !time_offset_in_null_space &&
        entry_sigma(sensor.TimeOffsetBlock(), 0)) {
      Combination along = all_free(sensor.NodeBlocks(), line_along_x ? 1 : 0);
      const Combination pitches = all_free(sensor.NodeBlocks(), pitch);
      along.insert(along.end(), pitches.begin(), pitches.end());
      named.push_back({"time_offset_vs_along_track",
                       multiple({{sensor.TimeOffsetBlock(), 0, 1.0}}, along),
                       "a time offset is an along-track shift v dt (and the attitude change over "
                       "dt): the trajectory's along-track and pitch corrections take it; only the "
                       "POS priors tell them apart"});
      named.push_back({"time_offset_vs_offset",
                       multiple({{sensor.TimeOffsetBlock(), 0, 1.0}},
                                all_free(sensor.DetectorBlocks(), kLineMaxTerms)),
                       "a time offset seen from the height is nearly a constant along-track offset "
                       "of the detectors (a pitch of the camera); only the relief tells them "
                       "apart"});
    }
    if (entry_sigma(lever, 0)) {
      Combination positions;
      for (int e = 0; e < 3; ++e) {
        const Combination c = all_free(sensor.NodeBlocks(), e);
        positions.insert(positions.end(), c.begin(), c.end());
      }
      const char* axis[] = {"x", "y", "z"};
      for (int a = 0; a < 3; ++a)
        named.push_back({std::string("lever_arm_") + axis[a] + "_vs_position",
                         multiple({{lever, a, 1.0}}, positions),
                         "a constant lever arm is a constant position correction of the trajectory "
                         "(along track it is also what a POS time offset does; only the POS prior "
                         "tells them apart)"});
      // With the boresight free too: a lever arm across (along) track seen from the height H is
      // nearly a roll (pitch) of lever / H; only the relief tells them apart.
      const Combination boresight = all_free({mount}, 0), phi = all_free({mount}, 1),
                        kappa = all_free({mount}, 2);
      Combination angles = boresight;
      angles.insert(angles.end(), phi.begin(), phi.end());
      angles.insert(angles.end(), kappa.begin(), kappa.end());
      if (!angles.empty())
        for (int a = 0; a < 3; ++a)
          named.push_back({std::string("lever_arm_") + axis[a] + "_vs_boresight",
                           multiple({{lever, a, 1.0}}, angles),
                           "a lever arm across or along track is nearly a boresight roll or pitch "
                           "(lever / flying height); only the relief tells them apart"});
    }
    for (const auto& [name, rho, meaning] : named) {
      if (rho < 0) continue;
      result.correlations.emplace_back(name, rho);
      if (rho > options.correlation_warn) {
        const bool fail = rho > options.correlation_fail;
        if (fail) result.valid = false;
        const bool own = name.rfind("boresight", 0) == 0 || name.rfind("lever_arm", 0) == 0;
        const bool time = name.rfind("time_offset", 0) == 0;
        result.warnings.push_back({name,
                                   time  ? "time offset"
                                   : own ? "boresight / lever arm"
                                         : "detector polynomials",
                                   rho,
                                   fail ? options.correlation_fail : options.correlation_warn,
                                   std::string(fail ? "ill-posed: " : "") + "correlation " +
                                       FormatNumber(rho, 6) + ": " + meaning});
      }
    }
  }

  // The updated camera: design + the estimated calibration (polynomials when the file had none
  // or had polynomials over the same ranges, else the table).
  result.camera = camera;
  result.camera.c_mm = sensor.CMm();
  result.camera.mount_rad = sensor.MountRad();
  result.camera.lever_arm_m = sensor.LeverArmM();
  bool same_ranges = camera.dx_mm.empty();
  if (!camera.calibration.empty()) {
    same_ranges = int(camera.calibration.size()) == n_sub;
    for (int s = 0; same_ranges && s < n_sub; ++s)
      same_ranges = camera.calibration[s].first == ranges[s].first &&
                    camera.calibration[s].last == ranges[s].second &&
                    camera.calibration[s].dx.size() <= size_t(kLineMaxTerms) &&
                    camera.calibration[s].dy.size() <= size_t(kLineMaxTerms);
  }
  if (same_ranges) {
    std::vector<calib::LinePolynomial> polys(n_sub);
    for (int s = 0; s < n_sub; ++s) {
      polys[s].first = ranges[s].first;
      polys[s].last = ranges[s].second;
      polys[s].dx.assign(sensor.Detectors()[s].begin(),
                         sensor.Detectors()[s].begin() + kLineMaxTerms);
      polys[s].dy.assign(sensor.Detectors()[s].begin() + kLineMaxTerms,
                         sensor.Detectors()[s].end());
      if (!camera.calibration.empty()) {
        for (size_t k = 0; k < camera.calibration[s].dx.size(); ++k)
          polys[s].dx[k] += camera.calibration[s].dx[k];
        for (size_t k = 0; k < camera.calibration[s].dy.size(); ++k)
          polys[s].dy[k] += camera.calibration[s].dy[k];
      }
      while (polys[s].dx.size() > 1 && polys[s].dx.back() == 0.0) polys[s].dx.pop_back();
      while (polys[s].dy.size() > 1 && polys[s].dy.back() == 0.0) polys[s].dy.pop_back();
    }
    result.camera.calibration = polys;
    result.camera.dx_mm.clear();
    result.camera.dy_mm.clear();
  } else {
    result.camera.calibration.clear();
    result.camera.dx_mm = result.dx_mm;
    result.camera.dy_mm = result.dy_mm;
  }
  return result;
}

std::string LineCorrectionsToCsv(const LineCalibrationResult& r) {
  std::string out = "line,dX,dY,dZ,domega,dphi,dkappa,sdX,sdY,sdZ,sdomega,sdphi,sdkappa\n";
  const double deg = 180.0 / M_PI;
  for (size_t k = 0; k < r.lines.size(); ++k) {
    out += FormatNumber(r.lines[k]);
    for (int a = 0; a < 6; ++a)
      out += "," + FormatNumber(r.line_corrections[k][a] * (a < 3 ? 1 : deg), 10);
    for (int a = 0; a < 6; ++a)
      out += "," + FormatNumber(r.line_sigma[k][a] * (a < 3 ? 1 : deg), 6);
    out += "\n";
  }
  return out;
}

nlohmann::json LineCalibrationToJson(const LineCalibrationResult& r) {
  using nlohmann::json;
  auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json j;
  j["kind"] = "pushbroom";
  j["sigma0"] = r.report.sigma0;
  j["sigma0_px"] = r.sigma0_px;
  j.update(calib::SolveStatisticsToJson(r.report));  // redundancy .. seconds, groups
  j["valid"] = r.valid;
  j["n_observations"] = r.n_observations;
  j["n_control"] = r.n_control;
  j["n_ignored_observations"] = r.n_ignored;
  {
    const auto& d = r.datum;
    json directions = json::array();
    for (const auto& g : d.directions)
      directions.push_back({{"name", g.name}, {"fraction", g.fraction}, {"meaning", g.meaning}});
    j["datum"] = {{"mode", LineDatumName(d.mode)},
                  {"null_space_computed", d.null_space_computed},
                  {"rank_defect", d.null_space_computed ? json(d.rank_defect) : json(nullptr)},
                  {"threshold", d.threshold},
                  {"smallest_relative_eigenvalues", d.smallest_relative_eigenvalues},
                  {"n_constraints", d.n_constraints},
                  {"subcamera", d.subcamera},
                  {"blocks", d.blocks},
                  {"gauge_directions", directions},
                  {"gauge_directions_in_table", d.in_table},
                  {"parameters_in_null_space", d.parameters_in_null_space},
                  {"message", d.message}};
  }
  j["time_offset"] = {
      {"estimated", r.time_offset_estimated},
      {"dt_s", r.time_offset_s},
      {"sigma_s", r.time_offset_sigma_s ? json(*r.time_offset_sigma_s) : json(nullptr)}};
  j["c_mm"] = r.c_mm;
  j["c_sigma_mm"] = opt(r.c_sigma_mm);
  const double deg = 180.0 / M_PI;
  auto vector3 = [](const Eigen::Vector3d& v, double scale) {
    return json::array({v.x() * scale, v.y() * scale, v.z() * scale});
  };
  j["boresight"] = {
      {"mode", PlatformParamModeName(r.boresight)},
      {"opk_deg", vector3(r.boresight_rad, deg)},
      {"sigma_deg", r.boresight_sigma_rad ? vector3(*r.boresight_sigma_rad, deg) : json(nullptr)}};
  j["lever_arm"] = {
      {"mode", PlatformParamModeName(r.lever_arm)},
      {"xyz_m", vector3(r.lever_arm_m, 1.0)},
      {"sigma_m", r.lever_arm_sigma_m ? vector3(*r.lever_arm_sigma_m, 1.0) : json(nullptr)}};
  json subs = json::array();
  for (const auto& s : r.subcameras) {
    json js;
    js["id"] = s.id;
    js["first"] = s.first;
    js["last"] = s.last;
    js["n"] = s.n;
    js["degree_x"] = s.degree_x;
    js["degree_y"] = s.degree_y;
    js["rms_before_px"] = {{"across", s.across_before_px}, {"along", s.along_before_px}};
    js["rms_after_px"] = {{"across", s.across_after_px}, {"along", s.along_after_px}};
    js["dx_mm"] = s.dx_coefficients_mm;
    js["dy_mm"] = s.dy_coefficients_mm;
    json sx = json::array(), sy = json::array();
    for (const auto& v : s.dx_sigma_mm) sx.push_back(opt(v));
    for (const auto& v : s.dy_sigma_mm) sy.push_back(opt(v));
    js["dx_sigma_mm"] = sx;
    js["dy_sigma_mm"] = sy;
    subs.push_back(js);
  }
  j["subcameras"] = subs;
  j["degree_test"] = {{"applied", r.degree_test.applied},
                      {"reduced", r.degree_test.reduced},
                      {"start_degree", r.degree_test.start_degree},
                      {"alpha", r.degree_test.alpha},
                      {"table_sigma", r.degree_test.reduced ? "selected" : "fit"}};
  json det = json::array();
  for (size_t i = 0; i < r.dx_mm.size(); ++i)
    det.push_back({{"i", i},
                   {"dx_mm", r.dx_mm[i]},
                   {"dy_mm", r.dy_mm[i]},
                   {"sigma_dx_mm", opt(r.dx_sigma_mm[i])},
                   {"sigma_dy_mm", opt(r.dy_sigma_mm[i])},
                   {"sigma_dx_fit_mm", opt(r.dx_fit_sigma_mm[i])},
                   {"sigma_dy_fit_mm", opt(r.dy_fit_sigma_mm[i])}});
  j["detectors"] = det;
  json nodes = json::array();
  for (size_t k = 0; k < r.node_values.size(); ++k) {
    const auto& v = r.node_values[k];
    const auto& s = r.node_sigma[k];
    nodes.push_back({{"line", r.node_line[k]},
                     {"dX", v[0]},
                     {"dY", v[1]},
                     {"dZ", v[2]},
                     {"domega", v[3] * deg},
                     {"dphi", v[4] * deg},
                     {"dkappa", v[5] * deg},
                     {"sigma",
                      {{"dX", s[0]},
                       {"dY", s[1]},
                       {"dZ", s[2]},
                       {"domega", s[3] * deg},
                       {"dphi", s[4] * deg},
                       {"dkappa", s[5] * deg}}}});
  }
  j["trajectory"] = {{"form", "cubic_bspline"}, {"nodes", nodes}};
  json corr = json::object();
  for (const auto& [name, rho] : r.correlations) corr[name] = rho;
  j["correlations"] = corr;
  j["undetermined"] = r.undetermined;
  j["warnings"] = FindingsToJson(r.warnings);
  return j;
}

}  // namespace aerocal::triangulation
