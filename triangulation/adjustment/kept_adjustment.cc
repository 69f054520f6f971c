// CovarianceOfNamed: names -> parameter blocks and entries, one EstimateCovariance over all pairs
// of the named blocks, the joint matrix gathered from its blocks.
#include "triangulation/adjustment/kept_adjustment.h"

#include "calib/camera/camera_model.h"
#include "calib/core/error.h"

#include <cmath>
#include <set>

namespace aerocal::triangulation {
namespace {

using calib::BlockId;

constexpr double kRadToDeg = 180.0 / M_PI;

// One row of the joint matrix: an entry of a builder block, scaled from the block's report units
// (the builder reports rotations in rad) to the result's (deg).
struct Row {
  BlockId block = -1;
  int entry = 0;
  double scale = 1.0;
  std::string name;
};

// The text after `prefix` in `name` into `rest`; false when `name` does not start with it.
bool StripPrefix(const std::string& name, const std::string& prefix, std::string* rest) {
  if (name.rfind(prefix, 0) != 0) return false;
  *rest = name.substr(prefix.size());
  return true;
}

void AddCameraRows(BlockAdjustment& adjustment,
                   const AdjustmentResult& result,
                   const std::string& name,
                   const std::string& what,
                   std::vector<Row>* rows) {
  // "ID" or "ID.NAME": camera ids may hold dots, so the longest id of the result that matches.
  const CameraEstimate* camera = nullptr;
  std::string parameter;
  for (const auto& c : result.cameras) {
    const bool whole = what == c.id;
    const bool one = what.rfind(c.id + ".", 0) == 0;
    if ((whole || one) && (!camera || c.id.size() > camera->id.size())) {
      camera = &c;
      parameter = whole ? "" : what.substr(c.id.size() + 1);
    }
  }
  const BlockId block = camera ? adjustment.InteriorBlock(camera->id) : -1;
  if (block < 0) throw ConfigError("covariance: '" + name + "': no camera of that id");
  const auto table = calib::CameraModelParams(camera->model);
  bool found = false;
  for (size_t k = 0; k < table.size(); ++k)
    if (parameter.empty() || parameter == table[k].name) {
      rows->push_back({block,
                       static_cast<int>(k),
                       1.0,
                       "camera " + camera->id + "." + std::string(table[k].name)});
      found = true;
    }
  if (!found)
    throw ConfigError("covariance: '" + name + "': the camera's model " +
                      std::string(calib::CameraModelName(camera->model)) + " has no parameter '" +
                      parameter + "'");
}

void AddExposureRows(BlockAdjustment& adjustment,
                     const AdjustmentResult& result,
                     const std::string& name,
                     const std::string& image,
                     std::vector<Row>* rows) {
  bool used = false;
  for (const auto& e : result.exposures)
    if (e.image == image) used = e.used && e.center_sigma_m.has_value();
  const BlockId center = adjustment.CenterBlock(image), angles = adjustment.RotationBlock(image);
  if (!used || center < 0 || angles < 0)
    throw ConfigError("covariance: '" + name +
                      "': no adjusted exposure of that id (unknown, or left out: see notes)");
  const char* axes[] = {"X", "Y", "Z"};
  const char* angle_names[] = {"omega", "phi", "kappa"};
  for (int k = 0; k < 3; ++k) rows->push_back({center, k, 1.0, name + "." + axes[k]});
  for (int k = 0; k < 3; ++k) rows->push_back({angles, k, kRadToDeg, name + "." + angle_names[k]});
}

void AddPointRows(BlockAdjustment& adjustment,
                  const AdjustmentResult& result,
                  const std::string& name,
                  const std::string& point,
                  std::vector<Row>* rows) {
  const BlockId block = adjustment.PointBlock(point);
  if (!result.points_m.count(point) || block < 0)
    throw ConfigError("covariance: '" + name +
                      "': no adjusted point of that id (unknown, or left out: see notes)");
  const char* axes[] = {"X", "Y", "Z"};
  for (int k = 0; k < 3; ++k) rows->push_back({block, k, 1.0, name + "." + axes[k]});
}

}  // namespace

NamedCovariance CovarianceOfNamed(BlockAdjustment& adjustment,
                                  const AdjustmentResult& result,
                                  const std::vector<std::string>& names) {
  std::vector<Row> rows;
  for (const std::string& name : names) {
    std::string rest;
    if (StripPrefix(name, "camera ", &rest))
      AddCameraRows(adjustment, result, name, rest, &rows);
    else if (StripPrefix(name, "exposure ", &rest))
      AddExposureRows(adjustment, result, name, rest, &rows);
    else if (StripPrefix(name, "point ", &rest))
      AddPointRows(adjustment, result, name, rest, &rows);
    else
      throw ConfigError("covariance: '" + name +
                        "': name 'camera ID[.PARAMETER]', 'exposure ID' or 'point ID'");
  }
  // Each named block once, every pair of them (no cross_blocks: all pairs are computed).
  std::vector<BlockId> blocks;
  std::set<BlockId> seen;
  for (const Row& r : rows)
    if (seen.insert(r.block).second) blocks.push_back(r.block);
  calib::ProblemBuilder& builder = adjustment.builder();
  const calib::CovarianceReport cov = builder.EstimateCovariance(blocks, result.sigma0);
  if (!cov.ok) throw ConfigError("covariance: not computed: " + cov.message);
  NamedCovariance out;
  const int n = static_cast<int>(rows.size());
  out.matrix = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    out.names.push_back(rows[i].name);
    for (int k = 0; k < n; ++k) {
      Eigen::MatrixXd c;  // a fixed block's pairs are not computed: zero, as its fixed entries
      if (cov.CrossCovariance(rows[i].block, rows[k].block, &c))
        out.matrix(i, k) = c(rows[i].entry, rows[k].entry) * rows[i].scale * rows[k].scale;
    }
  }
  // The builder's blocks (a, b) and (b, a) are one matrix and its transpose: symmetric up to the
  // rounding of the rotation's conversion; made exactly symmetric, as a covariance is.
  out.matrix = 0.5 * (out.matrix + out.matrix.transpose()).eval();
  return out;
}

}  // namespace aerocal::triangulation
