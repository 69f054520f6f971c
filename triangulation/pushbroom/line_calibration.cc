#include "triangulation/pushbroom/line_calibration.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <nlohmann/json.hpp>

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/residuals/line_collinearity.h"
#include "calib/residuals/prior.h"

namespace aerocal::triangulation {
namespace {

using calib::BlockId;
using calib::kLineMaxTerms;
using calib::kLineNodeSize;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr double kMaxPixel = 1e7;
constexpr double kMaxSigmaPx = 1e4;
constexpr char kGroupLineImage[] = "line_image";
constexpr char kGroupPosPrior[] = "pos_prior";

struct Problem {
  calib::ProblemBuilder builder;
  std::vector<BlockId> node_blocks, detector_blocks;
  BlockId c_block = -1, mount_block = -1, lever_block = -1;
  std::vector<Vector6d> nodes;
  std::vector<std::array<double, 2 * kLineMaxTerms>> detector;
  double c = 0;
  Eigen::Vector3d mount, lever;
  std::vector<Eigen::Vector3d> point_values;
  std::vector<calib::ResidualId> image_residuals;
  std::vector<int> residual_subcamera;
  std::vector<double> residual_detector, residual_u;   // per image residual: plots
  std::vector<Eigen::Vector2d> residual_sigma_mm;
  std::vector<std::set<int>> fixed_entries;  // per detector block
};

}  // namespace

void LineCalibrationOptions::Validate() const {
  if (node_spacing_lines < 1)
    throw ConfigError("--node-spacing must be >= 1 line (got " + std::to_string(node_spacing_lines) + ")");
  if (max_degree < 0 || max_degree >= kLineMaxTerms)
    throw ConfigError("--max-degree must be within 0 .. 5 (got " + std::to_string(max_degree) + ")");
  if (degree && (*degree < 0 || *degree >= kLineMaxTerms))
    throw ConfigError("--degree must be within 0 .. 5 (got " + std::to_string(*degree) + ")");
  if (!(degree_test_alpha > 0 && degree_test_alpha < 0.5))
    throw ConfigError("--degree-alpha must be within (0, 0.5) (got " + FormatNumber(degree_test_alpha) + ")");
  if (!(pos_sigma_m > 0) || !(pos_sigma_deg > 0))
    throw ConfigError("--pos-sigma-m and --pos-sigma-deg must be > 0");
  if (min_observations_per_segment < 0)
    throw ConfigError("--min-per-segment must be >= 0");
}

bool ProjectAtLine(const calib::LineCamera& camera, const PosTrajectory& pos, double line,
                    const Eigen::Vector3d& point, Eigen::Vector2d* xy) {
  Eigen::Vector3d center, opk;
  pos.PoseAtLine(line, &center, &opk);
  const Eigen::Matrix3d body = calib::RotationFromOpk(opk);
  const Eigen::Vector3d v = calib::RotationFromOpk(camera.mount_rad).transpose() *
                            body.transpose() * (point - center - body * camera.lever_arm_m);
  if (!(v.z() < 0)) return false;
  *xy = Eigen::Vector2d(-camera.c_mm * v.x() / v.z(), -camera.c_mm * v.y() / v.z());
  return true;
}

void WriteLineObservations(const std::string& path, const std::vector<LineObservation>& observations) {
  std::ostringstream out;
  out << "image,point,col,row,sigma_px\n";
  for (const auto& o : observations)
    out << "strip," << o.point << "," << FormatNumber(o.detector, 17) << ","
        << FormatNumber(o.line, 17) << "," << FormatNumber(o.sigma_px) << "\n";
  WriteFileAtomically(path, out.str());
}

std::vector<LineObservation> ReadLineObservations(const std::string& path, double default_sigma_px) {
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
        ThrowInputError(t.Where(row), "sigma_px must be > 0 and <= " + FormatNumber(kMaxSigmaPx) +
                                          " (got " + FormatNumber(*s) + ")");
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
    throw ConfigError("--reference must be a sub-camera index within 0 .. " + std::to_string(n_sub - 1));
  std::vector<std::string> sub_ids;
  for (int s = 0; s < n_sub; ++s)
    sub_ids.push_back(camera.subcameras.empty() ? std::to_string(s) : camera.subcameras[s].id);

  const double first_line = pos.first_line(), last_line = pos.last_line();
  const int spacing = options.node_spacing_lines;
  const int n_nodes = calib::SplineNodeCount(last_line - first_line, spacing);

  Problem p;
  p.nodes.assign(n_nodes, Vector6d::Zero());
  p.detector.assign(n_sub, {});
  for (auto& d : p.detector) d.fill(0.0);
  p.fixed_entries.assign(n_sub, {});
  p.c = camera.c_mm;
  p.mount = camera.mount_rad;
  p.lever = camera.lever_arm_m;

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

  auto& b = p.builder;
  const char* entry_names[] = {"dX", "dY", "dZ", "domega", "dphi", "dkappa"};
  for (int j = 0; j < n_nodes; ++j)
    p.node_blocks.push_back(b.AddBlock("node" + std::to_string(j), p.nodes[j].data(), kLineNodeSize,
                                       calib::BlockKind::kOther,
                                       {entry_names, entry_names + 6}));
  for (int s = 0; s < n_sub; ++s) {
    std::vector<std::string> names;
    for (int k = 0; k < kLineMaxTerms; ++k) names.push_back("dx" + std::to_string(k));
    for (int k = 0; k < kLineMaxTerms; ++k) names.push_back("dy" + std::to_string(k));
    p.detector_blocks.push_back(b.AddBlock("detector_" + sub_ids[s], p.detector[s].data(),
                                           2 * kLineMaxTerms, calib::BlockKind::kInterior, names));
  }
  p.c_block = b.AddBlock("c", &p.c, 1, calib::BlockKind::kInterior, {"c"});
  p.mount_block = b.AddBlock("mount", p.mount.data(), 3, calib::BlockKind::kOther, {"omega", "phi", "kappa"});
  p.lever_block = b.AddBlock("lever_arm", p.lever.data(), 3, calib::BlockKind::kOther, {"x", "y", "z"});
  if (!options.free_c) b.FixBlock(p.c_block);
  b.FixBlock(p.mount_block);
  b.FixBlock(p.lever_block);

  std::vector<BlockId> point_blocks(control.size());
  for (size_t k = 0; k < control.size(); ++k) {
    point_blocks[k] = b.AddBlock("point_" + control[k]->id, p.point_values[k].data(), 3,
                                 calib::BlockKind::kGroundPoint, {"X", "Y", "Z"});
    const Eigen::Vector3d& v = *control[k]->xyz_m;
    const Eigen::Vector3d& s = control[k]->sigma_m;
    b.AddResidual(calib::kGroupControl,
                  calib::PriorCostFunction::Create({v.x(), v.y(), v.z()}, {s.x(), s.y(), s.z()}),
                  {point_blocks[k]}, "control " + control[k]->id);
  }

  // Image observations.
  std::vector<int> per_segment(n_nodes, 0);
  std::vector<int> per_node(n_nodes, 0);
  for (const auto& o : observations) {
    const SourceRef where{observations_file, o.source_line};
    const auto it = point_index.find(o.point);
    if (it == point_index.end()) {
      ++result.n_ignored;
      continue;
    }
    if (!(o.detector >= -0.5 && o.detector <= camera.detectors - 0.5))
      ThrowInputError(where, "col (detector) must be within -0.5 .. " +
                                 FormatNumber(camera.detectors - 0.5) + " (got " +
                                 FormatNumber(o.detector) + ")");
    if (!pos.CoversLine(o.line))
      ThrowInputError(where, "row (scan line) " + FormatNumber(o.line) +
                                 " is outside the POS trajectory (lines " + FormatNumber(first_line) +
                                 " .. " + FormatNumber(last_line) + ")");
    int s = 0;
    const long nearest = std::lround(std::max(0.0, std::min<double>(o.detector, camera.detectors - 1)));
    for (int r = 0; r < n_sub; ++r)
      if (nearest >= ranges[r].first && nearest <= ranges[r].second) s = r;
    const double u = ranges[s].second > ranges[s].first
                         ? (2.0 * o.detector - ranges[s].first - ranges[s].second) /
                               double(ranges[s].second - ranges[s].first)
                         : 0.0;
    Eigen::Vector3d pos_center, pos_opk;
    pos.PoseAtLine(o.line, &pos_center, &pos_opk);
    // Whitening in detectors and lines: the local detector spacing in the virtual focal plane and
    // the image motion of one line (at the POS pose and the file's camera).
    const double h = 0.01;
    const double ic = std::max(ranges[s].first + h, std::min(ranges[s].second - h, o.detector));
    const double dx_di =
        ranges[s].second > ranges[s].first
            ? std::abs(camera.DesignPosition(ic + h).x() - camera.DesignPosition(ic - h).x()) / (2 * h)
            : camera.pitch_mm;
    double dy_dt = 0;
    {
      const double t0 = pos.CoversLine(o.line - 0.5) ? o.line - 0.5 : o.line;
      const double t1 = pos.CoversLine(o.line + 0.5) ? o.line + 0.5 : o.line;
      Eigen::Vector2d y0, y1;
      if (t1 > t0 && ProjectAtLine(camera, pos, t0, *control[it->second]->xyz_m, &y0) &&
          ProjectAtLine(camera, pos, t1, *control[it->second]->xyz_m, &y1))
        dy_dt = std::abs(y1.y() - y0.y()) / (t1 - t0);
    }
    if (!(dy_dt > 1e-3 * camera.pitch_mm)) dy_dt = camera.pitch_mm;
    const Eigen::Vector2d sigma_xy_mm(o.sigma_px * std::max(dx_di, 1e-3 * camera.pitch_mm),
                                      o.sigma_px * dy_dt);
    const double t = std::max(0.0, o.line - first_line);
    const calib::SplineSpan span = calib::CubicBSplineWeights(t, spacing);
    const int j = std::min(span.first_node, n_nodes - 4);
    ++per_segment[j];
    for (int m = 0; m < 4; ++m) ++per_node[j + m];
    const auto id = b.AddResidual(
        kGroupLineImage,
        calib::LineCollinearityResidual::Create(camera.DetectorPosition(o.detector), u, span,
                                                pos_opk, pos_center, sigma_xy_mm),
        {p.node_blocks[j], p.node_blocks[j + 1], p.node_blocks[j + 2], p.node_blocks[j + 3],
         p.detector_blocks[s], p.c_block, p.mount_block, p.lever_block, point_blocks[it->second]},
        "point " + o.point);
    p.image_residuals.push_back(id);
    p.residual_subcamera.push_back(s);
    p.residual_detector.push_back(o.detector);
    p.residual_u.push_back(u);
    p.residual_sigma_mm.push_back(sigma_xy_mm);
    // The start must be a valid geometry (the point in front of the camera).
    if (b.EvaluateResidual(id).empty())
      ThrowInputError(where, "point " + o.point + " lies behind the camera at line " +
                                 FormatNumber(o.line) + " with the POS and the file's camera");
  }
  result.n_observations = int(p.image_residuals.size());
  result.n_control = int(control.size());
  if (p.image_residuals.empty())
    throw InputError(observations_file + ": no observation of a control point (" +
                     std::to_string(result.n_ignored) + " observations of other points ignored)");

  // POS priors on the node values.
  const Eigen::Vector3d sigma_center =
      pos.MedianCenterSigma().value_or(Eigen::Vector3d::Constant(options.pos_sigma_m));
  const Eigen::Vector3d sigma_opk = pos.MedianOpkSigma().value_or(
      Eigen::Vector3d::Constant(options.pos_sigma_deg * M_PI / 180.0));
  if (options.pos_prior)
    for (int j = 0; j < n_nodes; ++j)
      b.AddResidual(kGroupPosPrior,
                    calib::PriorCostFunction::Create(
                        {0, 0, 0, 0, 0, 0},
                        {sigma_center.x(), sigma_center.y(), sigma_center.z(), sigma_opk.x(),
                         sigma_opk.y(), sigma_opk.z()}),
                    {p.node_blocks[j]}, "pos node " + std::to_string(j));

  // Too few points per line: per spline segment; a node no observation reaches is undetermined
  // without the POS prior (it is then fixed at 0 and the result is not valid).
  for (int j = 0; j + 3 < n_nodes; ++j) {
    const double a = first_line + j * spacing, z = std::min(last_line, a + spacing - 1);
    if (a > last_line) break;
    if (per_segment[j] < options.min_observations_per_segment)
      result.warnings.push_back({"few_points_per_line",
                                 "lines " + FormatNumber(a) + " .. " + FormatNumber(z),
                                 double(per_segment[j]), double(options.min_observations_per_segment),
                                 "only " + std::to_string(per_segment[j]) +
                                     " observations between two spline nodes: the per-line "
                                     "corrections there rest on the POS prior"});
  }
  for (int j = 0; j < n_nodes; ++j)
    if (per_node[j] == 0 && !options.pos_prior) {
      b.FixBlock(p.node_blocks[j]);
      result.valid = false;
      result.warnings.push_back({"few_points_per_line", "node " + std::to_string(j), 0, 1,
                                 "no observation reaches spline node " + std::to_string(j) +
                                     " and there is no POS prior: its correction is not determined"});
    }

  // Fixed detector entries: above the degree, and the datum.
  const int start_degree = options.degree.value_or(options.max_degree);
  auto apply_fixed = [&]() {
    for (int s = 0; s < n_sub; ++s) {
      std::vector<int> fixed(p.fixed_entries[s].begin(), p.fixed_entries[s].end());
      for (int e : fixed) p.detector[s][e] = 0.0;
      b.FreeBlock(p.detector_blocks[s]);
      if (!fixed.empty()) b.FixEntries(p.detector_blocks[s], fixed);
    }
  };
  for (int s = 0; s < n_sub; ++s) {
    for (int k = start_degree + 1; k < kLineMaxTerms; ++k) {
      p.fixed_entries[s].insert(k);
      p.fixed_entries[s].insert(kLineMaxTerms + k);
    }
    if (options.reference_datum && s == reference)
      for (int e : {0, 1, kLineMaxTerms, kLineMaxTerms + 1}) p.fixed_entries[s].insert(e);
  }
  apply_fixed();

  // Reprojection before: at the POS and the file's camera.
  auto rms_by_subcamera = [&](bool after) {
    std::vector<double> sx(n_sub, 0), sy(n_sub, 0);
    std::vector<int> n(n_sub, 0);
    for (size_t k = 0; k < p.image_residuals.size(); ++k) {
      const auto r = b.EvaluateResidual(p.image_residuals[k]);
      if (r.size() != 2) continue;
      const int s = p.residual_subcamera[k];
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

  std::vector<BlockId> cov_blocks = p.node_blocks;
  cov_blocks.insert(cov_blocks.end(), p.detector_blocks.begin(), p.detector_blocks.end());
  cov_blocks.push_back(p.c_block);

  result.report = b.Solve(options.solver);
  calib::CovarianceReport cov;
  if (result.report.usable) cov = b.EstimateCovariance(cov_blocks, result.report.sigma0);

  // Degree test (Wald, from the top): the smallest degree whose higher free coefficients are
  // jointly insignificant. Not applicable when sigma0 is ~0 (noise-free data): the start degree.
  if (!options.degree && cov.ok && result.report.sigma0 > 1e-9) {
    bool changed = false;
    for (int s = 0; s < n_sub; ++s)
      for (int axis = 0; axis < 2; ++axis) {
        const int base = axis * kLineMaxTerms;
        const Eigen::MatrixXd q = cov.BlockCovariance(p.detector_blocks[s], 2 * kLineMaxTerms);
        // Top-down: drop the highest free coefficient while it is insignificant (Wald, one
        // degree of freedom) in the model without the terms already dropped. The estimate and
        // variance of that reduced model come from this fit's covariance (restricted least
        // squares: b_e - Q_eB Q_BB^-1 b_B, Q_ee - Q_eB Q_BB^-1 Q_Be), so one solve serves every step.
        const double z = calib::NormalCriticalValue(options.degree_test_alpha);
        std::vector<int> dropped;
        int chosen = start_degree;
        for (; chosen >= 0; --chosen) {
          const int e = base + chosen;
          if (p.fixed_entries[s].count(e)) continue;  // fixed (datum): does not decide
          double beta = p.detector[s][e], var = q(e, e);
          if (!dropped.empty()) {
            const int nb = int(dropped.size());
            Eigen::MatrixXd qbb(nb, nb);
            Eigen::VectorXd qeb(nb), bb(nb);
            for (int k = 0; k < nb; ++k) {
              qeb[k] = q(e, dropped[k]);
              bb[k] = p.detector[s][dropped[k]];
              for (int m = 0; m < nb; ++m) qbb(k, m) = q(dropped[k], dropped[m]);
            }
            const Eigen::LDLT<Eigen::MatrixXd> ldlt(qbb);
            beta -= qeb.dot(ldlt.solve(bb));
            var -= qeb.dot(ldlt.solve(qeb));
          }
          if (!(var > 0) || !(beta * beta / var < z * z)) break;
          dropped.push_back(e);
        }
        // chosen: the highest kept term; -1 when every free term was dropped (no correction).
        for (int k = chosen + 1; k <= start_degree; ++k)
          if (p.fixed_entries[s].insert(base + k).second) changed = true;
        (axis == 0 ? result.subcameras[s].degree_x : result.subcameras[s].degree_y) = chosen;
      }
    if (changed) {
      apply_fixed();
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
    result.warnings.push_back({"not_converged", "adjustment", double(result.report.iterations), 0,
                               "the adjustment did not converge: " + result.report.message});
  }
  if (result.report.sigma0 > options.max_sigma0) {
    result.valid = false;
    result.warnings.push_back({"sigma0", "adjustment", result.report.sigma0, options.max_sigma0,
                               "sigma0 is far above 1: the a-priori sigmas or the model are wrong"});
  }
  if (!cov.ok && result.report.usable) {
    result.valid = false;
    result.warnings.push_back({"covariance", "adjustment", 0, 0,
                               "no covariance (singular normal matrix?): " + cov.message});
  }
  result.undetermined = cov.undetermined;
  if (!cov.undetermined.empty()) {
    result.valid = false;
    result.warnings.push_back({"undetermined", cov.undetermined.front(),
                               double(cov.undetermined.size()), 0,
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
    out.dx_coefficients_mm.assign(p.detector[s].begin(), p.detector[s].begin() + kLineMaxTerms);
    out.dy_coefficients_mm.assign(p.detector[s].begin() + kLineMaxTerms, p.detector[s].end());
    for (int k = 0; k < kLineMaxTerms; ++k) {
      out.dx_sigma_mm.push_back(entry_sigma(p.detector_blocks[s], k));
      out.dy_sigma_mm.push_back(entry_sigma(p.detector_blocks[s], kLineMaxTerms + k));
    }
  }
  result.dx_mm.resize(camera.detectors);
  result.dy_mm.resize(camera.detectors);
  result.dx_sigma_mm.resize(camera.detectors);
  result.dy_sigma_mm.resize(camera.detectors);
  for (int s = 0; s < n_sub; ++s) {
    const Eigen::MatrixXd q =
        cov.ok ? cov.BlockCovariance(p.detector_blocks[s], 2 * kLineMaxTerms) : Eigen::MatrixXd();
    for (int i = ranges[s].first; i <= ranges[s].second; ++i) {
      const double u = ranges[s].second > ranges[s].first
                           ? (2.0 * i - ranges[s].first - ranges[s].second) /
                                 double(ranges[s].second - ranges[s].first)
                           : 0.0;
      const Eigen::Vector2d base = camera.Correction(i);
      result.dx_mm[i] = base.x() + calib::EvaluatePolynomial(p.detector[s].data(), kLineMaxTerms, u);
      result.dy_mm[i] = base.y() + calib::EvaluatePolynomial(p.detector[s].data() + kLineMaxTerms,
                                                             kLineMaxTerms, u);
      if (cov.ok)
        for (int axis = 0; axis < 2; ++axis) {
          Eigen::VectorXd g = Eigen::VectorXd::Zero(2 * kLineMaxTerms);
          double power = 1.0;
          for (int k = 0; k < kLineMaxTerms; ++k, power *= u) g[axis * kLineMaxTerms + k] = power;
          const double var = g.dot(q * g);
          (axis == 0 ? result.dx_sigma_mm : result.dy_sigma_mm)[i] = std::sqrt(std::max(0.0, var));
        }
    }
  }

  // Error samples (plots): the fitted correction at the measured position minus the residual,
  // i.e. what remains without the detector calibration, in pitches.
  for (size_t k = 0; k < p.image_residuals.size(); ++k) {
    const auto r = b.EvaluateResidual(p.image_residuals[k]);
    if (r.size() != 2) continue;
    const int s = p.residual_subcamera[k];
    const double u = p.residual_u[k];
    const Eigen::Vector2d base = camera.Correction(p.residual_detector[k]);
    const double dx = base.x() + calib::EvaluatePolynomial(p.detector[s].data(), kLineMaxTerms, u);
    const double dy =
        base.y() + calib::EvaluatePolynomial(p.detector[s].data() + kLineMaxTerms, kLineMaxTerms, u);
    result.error_samples.push_back({p.residual_detector[k], s,
                                    (dx - r[0] * p.residual_sigma_mm[k].x()) / camera.pitch_mm,
                                    (dy - r[1] * p.residual_sigma_mm[k].y()) / camera.pitch_mm});
  }

  // Spline nodes and per-line corrections with sigmas.
  for (int j = 0; j < n_nodes; ++j) {
    result.node_line.push_back(first_line + (j - 1) * double(spacing));
    result.node_values.push_back(p.nodes[j]);
    Vector6d sigma = Vector6d::Zero();
    if (cov.ok)
      for (int e = 0; e < 6; ++e) sigma[e] = entry_sigma(p.node_blocks[j], e).value_or(0.0);
    result.node_sigma.push_back(sigma);
  }
  for (double line = first_line; line <= last_line + 1e-9; line += 1.0) {
    const calib::SplineSpan span = calib::CubicBSplineWeights(line - first_line, spacing);
    const int j = std::min(span.first_node, n_nodes - 4);
    Vector6d value = Vector6d::Zero();
    Eigen::Matrix<double, 6, 6> var = Eigen::Matrix<double, 6, 6>::Zero();
    for (int m = 0; m < 4; ++m) {
      value += span.weights[m] * p.nodes[j + m];
      if (!cov.ok) continue;
      for (int n = 0; n < 4; ++n) {
        Eigen::MatrixXd cross;
        if (cov.CrossCovariance(p.node_blocks[j + m], p.node_blocks[j + n], &cross))
          var += span.weights[m] * span.weights[n] * cross;
      }
    }
    result.lines.push_back(line);
    result.line_corrections.push_back(value);
    result.line_sigma.push_back(var.diagonal().cwiseMax(0.0).cwiseSqrt());
  }
  result.c_mm = p.c;
  if (options.free_c) result.c_sigma_mm = entry_sigma(p.c_block, 0);

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
    auto mean_free = [&](const std::vector<BlockId>& blocks, int entry) {
      Combination c;
      for (BlockId block : blocks)
        if (entry_sigma(block, entry)) c.emplace_back(block, entry, 1.0);
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
        if (entry_sigma(block, entry)) c.emplace_back(block, entry, 1.0);
      return c;
    };
    const double offset_roll = multiple(mean_free(p.detector_blocks, 0), all_free(p.node_blocks, roll));
    const double offset_pitch =
        multiple(mean_free(p.detector_blocks, kLineMaxTerms), all_free(p.node_blocks, pitch));
    double scale_c = -1;
    if (options.free_c && entry_sigma(p.c_block, 0)) {
      Combination set = all_free(p.detector_blocks, 1);
      const Combination dz = all_free(p.node_blocks, 2);
      set.insert(set.end(), dz.begin(), dz.end());
      scale_c = multiple({{p.c_block, 0, 1.0}}, set);
    }
    const std::pair<const char*, double> named[] = {
        {"offset_vs_roll", offset_roll}, {"offset_vs_pitch", offset_pitch}, {"scale_vs_c", scale_c}};
    for (const auto& [name, rho] : named) {
      if (rho < 0) continue;
      result.correlations.emplace_back(name, rho);
      if (rho > options.correlation_warn) {
        const bool fail = rho > options.correlation_fail;
        if (fail) result.valid = false;
        result.warnings.push_back(
            {name, "detector polynomials", rho, fail ? options.correlation_fail : options.correlation_warn,
             std::string(fail ? "ill-posed: " : "") + "correlation " + FormatNumber(rho, 6) +
                 (std::string(name) == "scale_vs_c"
                      ? ": c and the detectors' linear term (or the height) are one scale"
                      : std::string(name) == "offset_vs_roll"
                            ? ": a constant across-track offset of the detectors is a roll of the strip"
                            : ": a constant along-track offset of the detectors is a pitch of the strip")});
      }
    }
  }

  // The updated camera: design + the estimated calibration (polynomials when the file had none
  // or had polynomials over the same ranges, else the table).
  result.camera = camera;
  result.camera.c_mm = p.c;
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
      polys[s].dx.assign(p.detector[s].begin(), p.detector[s].begin() + kLineMaxTerms);
      polys[s].dy.assign(p.detector[s].begin() + kLineMaxTerms, p.detector[s].end());
      if (!camera.calibration.empty()) {
        for (size_t k = 0; k < camera.calibration[s].dx.size(); ++k) polys[s].dx[k] += camera.calibration[s].dx[k];
        for (size_t k = 0; k < camera.calibration[s].dy.size(); ++k) polys[s].dy[k] += camera.calibration[s].dy[k];
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
    for (int a = 0; a < 6; ++a) out += "," + FormatNumber(r.line_corrections[k][a] * (a < 3 ? 1 : deg), 10);
    for (int a = 0; a < 6; ++a) out += "," + FormatNumber(r.line_sigma[k][a] * (a < 3 ? 1 : deg), 6);
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
  j["redundancy"] = r.report.redundancy;
  j["iterations"] = r.report.iterations;
  j["converged"] = r.report.converged;
  j["valid"] = r.valid;
  j["n_observations"] = r.n_observations;
  j["n_control"] = r.n_control;
  j["n_ignored_observations"] = r.n_ignored;
  j["c_mm"] = r.c_mm;
  j["c_sigma_mm"] = opt(r.c_sigma_mm);
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
  json det = json::array();
  for (size_t i = 0; i < r.dx_mm.size(); ++i)
    det.push_back({{"i", i}, {"dx_mm", r.dx_mm[i]}, {"dy_mm", r.dy_mm[i]},
                   {"sigma_dx_mm", opt(r.dx_sigma_mm[i])}, {"sigma_dy_mm", opt(r.dy_sigma_mm[i])}});
  j["detectors"] = det;
  json nodes = json::array();
  const double deg = 180.0 / M_PI;
  for (size_t k = 0; k < r.node_values.size(); ++k) {
    const auto& v = r.node_values[k];
    const auto& s = r.node_sigma[k];
    nodes.push_back({{"line", r.node_line[k]},
                     {"dX", v[0]}, {"dY", v[1]}, {"dZ", v[2]},
                     {"domega", v[3] * deg}, {"dphi", v[4] * deg}, {"dkappa", v[5] * deg},
                     {"sigma", {{"dX", s[0]}, {"dY", s[1]}, {"dZ", s[2]}, {"domega", s[3] * deg},
                                {"dphi", s[4] * deg}, {"dkappa", s[5] * deg}}}});
  }
  j["trajectory"] = {{"form", "cubic_bspline"}, {"nodes", nodes}};
  json corr = json::object();
  for (const auto& [name, rho] : r.correlations) corr[name] = rho;
  j["correlations"] = corr;
  j["undetermined"] = r.undetermined;
  json warnings = json::array();
  for (const auto& w : r.warnings)
    warnings.push_back({{"name", w.name}, {"subject", w.subject}, {"value", w.value},
                        {"limit", w.limit}, {"message", w.message}});
  j["warnings"] = warnings;
  json groups = json::array();
  for (const auto& g : r.report.groups)
    groups.push_back({{"name", g.name}, {"n", g.n_observations}, {"rms", g.rms}});
  j["groups"] = groups;
  return j;
}

}  // namespace aerocal::triangulation
