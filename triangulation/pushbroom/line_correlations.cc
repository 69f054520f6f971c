// The named correlations of a line-camera calibration (line_calibration_run.h): a detector
// polynomial's constant across-track term against the mean roll correction of the strip
// (offset_vs_roll), its constant along-track term against the mean pitch correction
// (offset_vs_pitch), its linear across-track term against c (scale_vs_c); the boresight, the time
// offset and the lever arm against what can take them over. Each is the multiple correlation of a
// combination of entries with a set of entries: how well the best linear combination of the set
// explains it (1: the set can take it over entirely).
#include "calib/core/csv.h"
#include "triangulation/pushbroom/line_calibration_run.h"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace aerocal::triangulation::internal {
namespace {

using calib::BlockId;
using calib::kLineMaxTerms;

// A linear combination of covariance entries: (block, entry, weight).
using Combination = std::vector<std::tuple<BlockId, int, double>>;

Combination Join(Combination a, const Combination& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// The covariance algebra of the named correlations at the run's covariance.
class CorrelationAlgebra {
 public:
  explicit CorrelationAlgebra(const LineRun& run) : run_(run) {}

  double Covariance(const Combination& x, const Combination& y) const {
    double sum = 0;
    Eigen::MatrixXd cross;
    for (const auto& [bx, ex, wx] : x)
      for (const auto& [by, ey, wy] : y)
        if (run_.cov.CrossCovariance(bx, by, &cross)) sum += wx * wy * cross(ex, ey);
    return sum;
  }
  // Free and not held by the datum (its entries follow the higher terms).
  bool Decides(BlockId block, int entry) const {
    for (int s = 0; s < run_.n_sub; ++s)
      if (run_.sensor.DetectorBlocks()[s] == block && run_.datum_entries[s].count(entry))
        return false;
    return EntrySigma(run_, block, entry).has_value();
  }
  // The entry of every block that decides it, weight 1.
  Combination AllFree(const std::vector<BlockId>& blocks, int entry) const {
    Combination c;
    for (BlockId block : blocks)
      if (Decides(block, entry)) c.emplace_back(block, entry, 1.0);
    return c;
  }
  // Their mean.
  Combination MeanFree(const std::vector<BlockId>& blocks, int entry) const {
    Combination c = AllFree(blocks, entry);
    for (auto& [block, e, w] : c) w = 1.0 / double(c.size());
    return c;
  }
  // Multiple correlation of x with the set; -1 when it cannot be computed.
  double Multiple(const Combination& x, const Combination& set) const {
    if (x.empty() || set.empty()) return -1;
    const double vx = Covariance(x, x);
    if (!(vx > 0)) return -1;
    const int n = int(set.size());
    Eigen::MatrixXd cyy(n, n);
    Eigen::VectorXd cxy(n);
    for (int k = 0; k < n; ++k) {
      cxy[k] = Covariance(x, {set[k]});
      for (int m = 0; m < n; ++m) cyy(k, m) = Covariance({set[k]}, {set[m]});
    }
    const Eigen::VectorXd solved = cyy.completeOrthogonalDecomposition().solve(cxy);
    return std::sqrt(std::min(1.0, std::max(0.0, cxy.dot(solved) / vx)));
  }

 private:
  const LineRun& run_;
};

struct Named {
  std::string name;
  double rho;
  std::string meaning;
};

// The strip's axes: roll is the rotation about the along-track axis, phi when the line lies along
// object X (kappa ~ 0 or 180 deg), omega when it lies along Y; the node entries of each.
struct StripAxes {
  bool line_along_x;
  int roll, pitch;
};
StripAxes AxesOfStrip(const PosTrajectory& pos) {
  double mean_kappa = 0;
  for (const auto& r : pos.records()) mean_kappa += r.opk_rad.z();
  mean_kappa /= double(pos.records().size());
  const bool line_along_x = std::abs(std::cos(mean_kappa)) >= std::abs(std::sin(mean_kappa));
  return {line_along_x, line_along_x ? 4 : 3, line_along_x ? 3 : 4};
}

std::vector<Named> DetectorCorrelations(const LineRun& run,
                                        const CorrelationAlgebra& algebra,
                                        const StripAxes& axes) {
  const LineScanCamera& sensor = run.sensor;
  const auto& detectors = sensor.DetectorBlocks();
  const auto& nodes = sensor.NodeBlocks();
  const double offset_roll =
      algebra.Multiple(algebra.MeanFree(detectors, 0), algebra.AllFree(nodes, axes.roll));
  const double offset_pitch = algebra.Multiple(algebra.MeanFree(detectors, kLineMaxTerms),
                                               algebra.AllFree(nodes, axes.pitch));
  double scale_c = -1;
  if (run.options.free_c && EntrySigma(run, sensor.CBlock(), 0))
    scale_c = algebra.Multiple({{sensor.CBlock(), 0, 1.0}},
                               Join(algebra.AllFree(detectors, 1), algebra.AllFree(nodes, 2)));
  return {
      {"offset_vs_roll",
       offset_roll,
       "a constant across-track offset of the detectors is a roll of the strip"},
      {"offset_vs_pitch",
       offset_pitch,
       "a constant along-track offset of the detectors is a pitch of the strip"},
      {"scale_vs_c", scale_c, "c and the detectors' linear term (or the height) are one scale"}};
}

// The boresight when estimated: multiple correlation of each angle with what can take it over.
// The camera's x axis is the line (across track): the boresight phi (about y) is its roll, omega
// its pitch.
void BoresightCorrelations(const LineRun& run,
                           const CorrelationAlgebra& algebra,
                           std::vector<Named>* named) {
  const LineScanCamera& sensor = run.sensor;
  const BlockId mount = sensor.MountBlock();
  if (!EntrySigma(run, mount, 0)) return;
  const char* angle[] = {"omega", "phi", "kappa"};
  for (int a = 0; a < 3; ++a)
    named->push_back(
        {std::string("boresight_") + angle[a] + "_vs_attitude",
         algebra.Multiple({{mount, a, 1.0}}, algebra.AllFree(sensor.NodeBlocks(), 3 + a)),
         "a constant boresight angle is a constant attitude correction of the "
         "trajectory (only the POS prior tells them apart)"});
  named->push_back(
      {"boresight_roll_vs_offset",
       algebra.Multiple({{mount, 1, 1.0}}, algebra.AllFree(sensor.DetectorBlocks(), 0)),
       "the boresight roll (phi) is a constant across-track offset of the detectors"});
  named->push_back(
      {"boresight_pitch_vs_offset",
       algebra.Multiple({{mount, 0, 1.0}}, algebra.AllFree(sensor.DetectorBlocks(), kLineMaxTerms)),
       "the boresight pitch (omega) is a constant along-track offset of the detectors"});
}

// The time offset: v dt is an along-track shift (the nodes' along-track position, its drift
// included) and, seen from the height, a pitch; only the POS priors separate them.
void TimeOffsetCorrelations(const LineRun& run,
                            const CorrelationAlgebra& algebra,
                            const StripAxes& axes,
                            std::vector<Named>* named) {
  const LineScanCamera& sensor = run.sensor;
  const BlockId dt = sensor.TimeOffsetBlock();
  if (!run.options.time_offset || run.time_offset_in_null_space || !EntrySigma(run, dt, 0)) return;
  const Combination along = Join(algebra.AllFree(sensor.NodeBlocks(), axes.line_along_x ? 1 : 0),
                                 algebra.AllFree(sensor.NodeBlocks(), axes.pitch));
  named->push_back({"time_offset_vs_along_track",
                    algebra.Multiple({{dt, 0, 1.0}}, along),
                    "a time offset is an along-track shift v dt (and the attitude change over "
                    "dt): the trajectory's along-track and pitch corrections take it; only the "
                    "POS priors tell them apart"});
  named->push_back(
      {"time_offset_vs_offset",
       algebra.Multiple({{dt, 0, 1.0}}, algebra.AllFree(sensor.DetectorBlocks(), kLineMaxTerms)),
       "a time offset seen from the height is nearly a constant along-track offset "
       "of the detectors (a pitch of the camera); only the relief tells them "
       "apart"});
}

// The lever arm against the trajectory's positions and, with the boresight free too, against the
// boresight: a lever arm across (along) track seen from the height H is nearly a roll (pitch) of
// lever / H; only the relief tells them apart.
void LeverArmCorrelations(const LineRun& run,
                          const CorrelationAlgebra& algebra,
                          std::vector<Named>* named) {
  const LineScanCamera& sensor = run.sensor;
  const BlockId lever = sensor.LeverArmBlock(), mount = sensor.MountBlock();
  if (!EntrySigma(run, lever, 0)) return;
  Combination positions;
  for (int e = 0; e < 3; ++e) positions = Join(positions, algebra.AllFree(sensor.NodeBlocks(), e));
  const char* axis[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a)
    named->push_back({std::string("lever_arm_") + axis[a] + "_vs_position",
                      algebra.Multiple({{lever, a, 1.0}}, positions),
                      "a constant lever arm is a constant position correction of the trajectory "
                      "(along track it is also what a POS time offset does; only the POS prior "
                      "tells them apart)"});
  const Combination angles = Join(Join(algebra.AllFree({mount}, 0), algebra.AllFree({mount}, 1)),
                                  algebra.AllFree({mount}, 2));
  if (angles.empty()) return;
  for (int a = 0; a < 3; ++a)
    named->push_back({std::string("lever_arm_") + axis[a] + "_vs_boresight",
                      algebra.Multiple({{lever, a, 1.0}}, angles),
                      "a lever arm across or along track is nearly a boresight roll or pitch "
                      "(lever / flying height); only the relief tells them apart"});
}

// Each computed correlation in the result; above the warning level a warning by name, above the
// failure level the result is not valid.
void WarnCorrelations(LineRun& run, const std::vector<Named>& named) {
  const auto& options = run.options;
  auto& result = run.result;
  for (const auto& [name, rho, meaning] : named) {
    if (rho < 0) continue;
    result.correlations.emplace_back(name, rho);
    if (!(rho > options.correlation_warn)) continue;
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

}  // namespace

void NameCorrelations(LineRun& run) {
  if (!run.cov.ok) return;
  const CorrelationAlgebra algebra(run);
  const StripAxes axes = AxesOfStrip(run.pos);
  std::vector<Named> named = DetectorCorrelations(run, algebra, axes);
  BoresightCorrelations(run, algebra, &named);
  TimeOffsetCorrelations(run, algebra, axes, &named);
  LeverArmCorrelations(run, algebra, &named);
  WarnCorrelations(run, named);
}

}  // namespace aerocal::triangulation::internal
