// The datum of a line-camera calibration (line_calibration.h, module README "Datum"): the null
// space of the problem as configured, the gauge functions of the detector table it holds, the
// requested parameters it reaches, and the constraints of the gauge or reference datum.
#include "calib/residuals/prior.h"
#include "triangulation/pushbroom/line_calibration_run.h"

#include <Eigen/SVD>

#include <algorithm>

namespace aerocal::triangulation::internal {
namespace {

using calib::BlockId;
using calib::kLineMaxTerms;

// Sigma of the datum pseudo-observations (LineDatumResidual), px: tight against a table sigma of
// ~1e-3 .. 1e-2 px, loose enough for the normal matrix (its weight ~ that of an angle).
constexpr double kDatumSigmaPx = 1e-4;

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

// Whether the null space reaches `block` (a requested parameter the data do not determine).
bool InNullSpace(const calib::NullSpaceReport& null_space, BlockId block) {
  const auto it = null_space.scaled.find(block);
  return it != null_space.scaled.end() && it->second.rows() > 0 && it->second.cols() > 0 &&
         Eigen::JacobiSVD<Eigen::MatrixXd>(it->second).singularValues()(0) > kDatumReach;
}

// The candidates of the gauge datum, in order: the reference sub-camera's polynomial block, then
// (only if the gauge does not reach it fully) the mount, lever arm, c and the spline nodes.
std::vector<BlockId> DatumCandidates(const LineRun& run) {
  const LineScanCamera& sensor = run.sensor;
  std::vector<BlockId> candidates = {sensor.DetectorBlocks()[run.reference],
                                     sensor.MountBlock(),
                                     sensor.LeverArmBlock(),
                                     sensor.CBlock()};
  candidates.insert(candidates.end(), sensor.NodeBlocks().begin(), sensor.NodeBlocks().end());
  return candidates;
}

// The datum's report from the null space: rank defect, eigenvalues, the gauge functions named,
// and the parameters asked for that it reaches. A parameter the user asked to estimate that lies
// in the null space is not determined by the data (a datum only sets it by convention): named,
// the result is not valid. E.g. the time offset or the lever arm without POS priors (a constant
// along-track shift / position of the trajectory), c (the focal plane's scale), the boresight (a
// rotation of the table).
void ReportNullSpace(LineRun& run, const calib::NullSpaceReport& null_space) {
  auto& d = run.result.datum;
  const LineScanCamera& sensor = run.sensor;
  d.null_space_computed = null_space.ok;
  d.message = null_space.message;
  d.threshold = run.options.gauge_threshold;
  d.rank_defect = null_space.rank_defect;
  d.smallest_relative_eigenvalues = null_space.smallest_relative_eigenvalues;
  NameGaugeDirections(null_space, run.camera, sensor, run.ranges, &d);
  run.time_offset_in_null_space = InNullSpace(null_space, sensor.TimeOffsetBlock());
  d.parameters_in_null_space.clear();
  const std::pair<BlockId, const char*> own[] = {{sensor.CBlock(), "c"},
                                                 {sensor.MountBlock(), "boresight"},
                                                 {sensor.LeverArmBlock(), "lever_arm"}};
  for (const auto& [block, name] : own)
    if (InNullSpace(null_space, block)) d.parameters_in_null_space.push_back(name);
  if (run.time_offset_in_null_space) d.parameters_in_null_space.push_back("time_offset");
}

}  // namespace

// The null space of the problem as configured, without a datum, is always computed and reported;
// the gauge mode constrains exactly its directions, the reference mode its four functions.
void DeriveDatum(LineRun& run) {
  auto& b = run.builder;
  auto& d = run.result.datum;
  if (run.datum_residual >= 0) b.RemoveResidual(run.datum_residual);
  run.datum_residual = -1;
  d.mode = run.options.datum;
  d.subcamera = run.sub_ids[run.reference];
  const calib::NullSpaceReport null_space = b.NullSpace(run.options.gauge_threshold);
  ReportNullSpace(run, null_space);
  const std::string label = "datum " + run.sub_ids[run.reference];
  if (run.options.datum == LineDatum::kGauge && null_space.ok)
    run.datum_residual = AddGaugeDatum(b, null_space, DatumCandidates(run), label, &d);
  if (run.options.datum == LineDatum::kReference) {
    const BlockId block = run.sensor.DetectorBlocks()[run.reference];
    d.n_constraints = 4;
    d.blocks = {b.BlockName(block)};
    run.datum_residual =
        b.AddResidual(kGroupLineDatum,
                      LineDatumResidual::Create(kDatumSigmaPx * run.camera.pitch_mm),
                      {block},
                      label);
  }
}

bool DatumOnReference(const LineRun& run) {
  const auto& blocks = run.result.datum.blocks;
  const std::string name = run.builder.BlockName(run.sensor.DetectorBlocks()[run.reference]);
  return std::find(blocks.begin(), blocks.end(), name) != blocks.end();
}

}  // namespace aerocal::triangulation::internal
