// BlockAdjustment::ScreenRobustly (block_adjustment.h): after a robust solve, the image
// observations whose standardized residual exceeds the cut, with the points of a suspect ray
// judged on their own (every pair of their rays fitted, the poses and the camera held).
#include "calib/core/median.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/block_adjustment_storage.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace aerocal::triangulation {
namespace {

// Whitened image residuals of `ids` with the point block (values at `xyz`) set to `at`.
std::vector<Eigen::VectorXd> ResidualsWithPointAt(const calib::ProblemBuilder& builder,
                                                  const std::vector<calib::ResidualId>& ids,
                                                  Eigen::Vector3d* xyz,
                                                  const Eigen::Vector3d& at) {
  *xyz = at;
  std::vector<Eigen::VectorXd> out;
  for (calib::ResidualId id : ids) {
    const std::vector<double> v = builder.EvaluateResidual(id);
    out.push_back(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<int>(v.size())));
  }
  return out;
}

// Least squares of the point alone (the poses and the camera held) on the rays `use` of `ids`,
// Gauss-Newton from `start` with a central-difference Jacobian; nullopt when the rays do not
// determine the point.
std::optional<Eigen::Vector3d> FitPoint(const calib::ProblemBuilder& builder,
                                        const std::vector<calib::ResidualId>& ids,
                                        const std::vector<bool>& use,
                                        Eigen::Vector3d* xyz,
                                        Eigen::Vector3d start) {
  constexpr double kStepM = 1e-3;  // central differences of residuals linear at this scale
  std::vector<calib::ResidualId> rays;
  for (size_t i = 0; i < ids.size(); ++i)
    if (use[i]) rays.push_back(ids[i]);
  for (int iteration = 0; iteration < 8; ++iteration) {
    const auto at = ResidualsWithPointAt(builder, rays, xyz, start);
    int m = 0;
    for (const auto& v : at) m += static_cast<int>(v.size());
    Eigen::VectorXd r(m);
    Eigen::MatrixXd j(m, 3);
    for (int c = 0, row = 0; c < static_cast<int>(at.size());
         row += static_cast<int>(at[c].size()), ++c)
      r.segment(row, at[c].size()) = at[c];
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d plus = start, minus = start;
      plus(k) += kStepM;
      minus(k) -= kStepM;
      const auto vp = ResidualsWithPointAt(builder, rays, xyz, plus);
      const auto vm = ResidualsWithPointAt(builder, rays, xyz, minus);
      for (int c = 0, row = 0; c < static_cast<int>(at.size());
           row += static_cast<int>(at[c].size()), ++c)
        j.block(row, k, at[c].size(), 1) = (vp[c] - vm[c]) / (2 * kStepM);
    }
    const Eigen::Matrix3d n = j.transpose() * j;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(n);
    if (!(eig.eigenvalues()(0) > 1e-9 * eig.eigenvalues()(2))) return std::nullopt;
    const Eigen::Vector3d step = -n.ldlt().solve(j.transpose() * r);
    start += step;
    if (step.norm() < 1e-6) break;
  }
  return start;
}

// The fit of a point that most of its rays agree with (|v| / s <= reject on every component; ties
// by the truncated sum of squares): the robust solution's point, and the point fitted to every
// pair of its rays. `ambiguous` when two fits with different sets of rays agree equally well.
struct Agreement {
  std::vector<bool> rays;
  int count = -1;
  bool ambiguous = false;
};

Agreement MostAgreedFit(const calib::ProblemBuilder& builder,
                        const std::vector<calib::ResidualId>& rays,
                        Eigen::Vector3d* xyz,
                        const Eigen::Vector3d& robust,
                        double scale,
                        double reject) {
  const int n = static_cast<int>(rays.size());
  const auto judge = [&](const Eigen::Vector3d& at, std::vector<bool>* agree, double* cost) {
    const auto v = ResidualsWithPointAt(builder, rays, xyz, at);
    int count = 0;
    *cost = 0.0;
    for (int i = 0; i < n; ++i) {
      const double worst = v[i].cwiseAbs().maxCoeff() / scale;
      (*agree)[i] = worst <= reject;
      count += (*agree)[i];
      *cost += std::min(v[i].squaredNorm() / (scale * scale), reject * reject);
    }
    return count;
  };
  Agreement best{std::vector<bool>(n, false)};
  double best_cost = 0.0;
  std::vector<bool> agree(n, false);
  const auto consider = [&](const Eigen::Vector3d& at) {
    double cost = 0.0;
    const int count = judge(at, &agree, &cost);
    if (count > best.count || (count == best.count && cost < best_cost)) {
      best.ambiguous = count == best.count && agree != best.rays;
      best.count = count;
      best_cost = cost;
      best.rays = agree;
    } else if (count == best.count && agree != best.rays) {
      best.ambiguous = true;
    }
  };
  consider(robust);
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      std::vector<bool> pair(n, false);
      pair[a] = pair[b] = true;
      if (const auto fit = FitPoint(builder, rays, pair, xyz, robust)) consider(*fit);
    }
  return best;
}

}  // namespace

std::vector<BlockAdjustment::Screened> BlockAdjustment::ScreenRobustly(double reject) {
  std::vector<calib::ResidualId> ids;
  for (const auto& [id, index] : storage_->observation_of_residual)
    if (builder_.IsActive(id) && builder_.ResidualGroup(id) == calib::kGroupImage)
      ids.push_back(id);
  const calib::ObservationCofactors cof = builder_.ComputeObservationCofactors(ids, false);
  std::vector<double> scaled;  // |v| / sqrt(r) of the testable components
  std::map<calib::ResidualId, std::vector<double>> values;
  for (calib::ResidualId id : ids) {
    values[id] = builder_.EvaluateResidual(id);
    const auto& r = cof.redundancy.at(id);
    for (size_t k = 0; k < r.size(); ++k)
      if (r[k] > 1e-6) scaled.push_back(std::abs(values[id][k]) / std::sqrt(r[k]));
  }
  std::vector<Screened> out;
  if (scaled.empty()) return out;
  const double scale = std::max(1e-12, 1.4826 * Median(scaled));
  std::map<calib::ResidualId, double> w_of;
  std::map<PointIndex, std::vector<calib::ResidualId>> rays_of_point;  // by point (id order)
  for (calib::ResidualId id : ids) {
    const auto& r = cof.redundancy.at(id);
    const auto& v = values.at(id);
    double w = 0.0;
    for (size_t k = 0; k < r.size(); ++k)
      if (r[k] > 1e-6) w = std::max(w, std::abs(v[k]) / (scale * std::sqrt(r[k])));
    w_of[id] = w;
    rays_of_point[storage_->point_of_observation[storage_->observation_of_residual.at(id)]]
        .push_back(id);
  }
  std::map<calib::ResidualId, double> judged;  // per-point verdicts: the ray's |v| / s there
  for (const auto& [point, rays] : rays_of_point)
    JudgeRaysOfPoint(point, rays, w_of, scale, reject, &judged);
  for (calib::ResidualId id : ids) {
    const auto by_point = judged.find(id);
    const double w = by_point != judged.end() ? by_point->second : w_of.at(id);
    if (w <= reject) continue;
    const auto& v = values.at(id);
    const size_t index = storage_->observation_of_residual.at(id);
    const ImageObservation& o = storage_->observations.at(index);
    out.push_back(
        {o, storage_->source_of_observation[index], Eigen::Vector2d(v[0], v[1]) * o.sigma_px, w});
  }
  return out;
}

// A point of three or more rays with a ray beyond `reject` is judged on its own, the poses and
// the camera held at the robust solution: the Cauchy solution can settle a point on its
// blunder and one good ray (a local minimum), which makes the good rays look like the gross
// errors. The point is fitted to every pair of its rays; the fit that most rays agree with
// (MostAgreedFit), refitted to those rays, judges every ray by its residual there. When two fits
// with different sets of rays agree equally well, the rays cannot be told apart here: none is
// excluded, and the final adjustment's snooping judges them with their correlated group. A
// control point keeps the one-pass cut, except when every one of its rays is beyond it: then its
// survey is the suspect (a wrong survey makes all its good rays look like gross errors), and the
// rays go to the final adjustment, which tests the survey first.
void BlockAdjustment::JudgeRaysOfPoint(PointIndex point,
                                       const std::vector<calib::ResidualId>& rays,
                                       const std::map<calib::ResidualId, double>& w_of,
                                       double scale,
                                       double reject,
                                       std::map<calib::ResidualId, double>* judged) {
  Storage::PointState& state = storage_->points[point];
  const int n = static_cast<int>(rays.size());
  bool suspect = false;
  for (calib::ResidualId id : rays) suspect |= w_of.at(id) > reject;
  if (!suspect) return;
  if (state.Control()) {  // every ray beyond the cut: its survey is suspect, not its rays
    bool all = n >= 2;
    for (calib::ResidualId id : rays) all &= w_of.at(id) > reject;
    if (all)
      for (calib::ResidualId id : rays) (*judged)[id] = 0.0;  // the final adjustment tests both
    return;
  }
  if (n < 3) return;
  Eigen::Vector3d* xyz = &state.xyz;
  const Eigen::Vector3d robust = *xyz;
  const Agreement best = MostAgreedFit(builder_, rays, xyz, robust, scale, reject);
  if (!best.ambiguous && best.count >= 2) {
    if (const auto fit = FitPoint(builder_, rays, best.rays, xyz, robust)) {
      const auto v = ResidualsWithPointAt(builder_, rays, xyz, *fit);
      for (int i = 0; i < n; ++i) (*judged)[rays[i]] = v[i].cwiseAbs().maxCoeff() / scale;
    }
  } else {
    for (calib::ResidualId id : rays) (*judged)[id] = 0.0;  // left to the final snooping
  }
  *xyz = robust;
}

}  // namespace aerocal::triangulation
