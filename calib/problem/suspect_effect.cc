#include "calib/problem/suspect_effect.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"

#include <algorithm>
#include <cmath>

namespace aerocal::calib {
namespace {

// A block's values as the covariance reports them: omega, phi, kappa (rad) for a rotation
// quaternion, near `near` (its values before), else the values themselves.
Eigen::VectorXd ReportedValues(const ProblemBuilder& builder,
                               BlockId b,
                               const Eigen::Vector3d& near) {
  const double* v = builder.BlockValues(b);
  if (builder.BlockKindOf(b) == BlockKind::kRotation)
    return OpkFromQuaternionNear(Eigen::Vector4d(v[0], v[1], v[2], v[3]), near);
  return Eigen::Map<const Eigen::VectorXd>(v, builder.BlockSize(b));
}

nlohmann::json Finite(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

}  // namespace

std::string SuspectEffect::Describe() const {
  if (!computed) return "their effect cannot be judged: " + message;
  return "leaving them out moves " + parameter + " by " + FormatNumber(max_sigmas, 2) +
         " of its sigmas (limit " + FormatNumber(limit_sigmas, 3) + ", --suspect-effect-limit)";
}

nlohmann::json SuspectEffectJson(const SuspectEffect& e) {
  nlohmann::json j = {{"computed", e.computed},
                      {"limit_sigmas", e.limit_sigmas},
                      {"max_sigmas", e.computed ? Finite(e.max_sigmas) : nlohmann::json()},
                      {"parameter", e.parameter},
                      {"max_all_sigmas", e.computed ? Finite(e.max_all_sigmas) : nlohmann::json()},
                      {"parameter_all", e.parameter_all},
                      {"matters", e.Matters()}};
  if (!e.message.empty()) j["message"] = e.message;
  j["calibrated"] = nlohmann::json::array();
  for (const auto& c : e.calibrated)
    j["calibrated"].push_back(
        {{"parameter", c.parameter},
         {"change", c.change},
         {"sigma", Finite(c.sigma)},
         {"sigmas", c.sigma > 0 ? Finite(std::abs(c.change) / c.sigma) : nlohmann::json()}});
  return j;
}

SuspectEffect EffectOfLeavingOut(ProblemBuilder& builder,
                                 const std::vector<ResidualId>& suspects,
                                 const CovarianceReport& cov,
                                 const std::vector<BlockId>& blocks,
                                 const std::vector<BlockId>& calibrated,
                                 const SolverOptions& solver,
                                 double limit_sigmas) {
  SuspectEffect effect;
  effect.limit_sigmas = limit_sigmas;
  if (!cov.ok) {
    effect.message = "no covariance at the solution: the effect cannot be judged";
    return effect;
  }
  std::vector<Eigen::VectorXd> before;
  for (BlockId b : blocks) before.push_back(ReportedValues(builder, b, Eigen::Vector3d::Zero()));
  const std::vector<double> state = builder.ValuesSnapshot();
  for (ResidualId id : suspects) builder.RemoveResidual(id);
  const SolveReport without = builder.Solve(solver);
  std::vector<Eigen::VectorXd> after;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const bool rotation = builder.BlockKindOf(blocks[i]) == BlockKind::kRotation;
    after.push_back(
        ReportedValues(builder,
                       blocks[i],
                       rotation ? Eigen::Vector3d(before[i].head<3>()) : Eigen::Vector3d::Zero()));
  }
  for (ResidualId id : suspects) builder.RestoreResidual(id);
  builder.RestoreValues(state);
  if (!without.usable) {
    effect.message =
        "the block without the suspects has no usable solution (" + without.termination + ")";
    return effect;
  }
  effect.computed = true;
  SuspectEffect::Change all_worst;
  double all_max = -1.0;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const BlockId b = blocks[i];
    if (builder.IsBlockFixed(b) || !cov.offsets.count(b)) continue;
    const Eigen::VectorXd sigma = cov.BlockSigma(b, static_cast<int>(before[i].size()));
    const bool listed = std::find(calibrated.begin(), calibrated.end(), b) != calibrated.end();
    for (int k = 0; k < before[i].size(); ++k) {
      if (!(sigma(k) > 0)) continue;  // fixed entry (sigma 0) or unknown (NaN)
      const double change = after[i](k) - before[i](k);
      const std::string name = cov.names.at(cov.offsets.at(b) + k);
      if (listed) effect.calibrated.push_back({name, change, sigma(k)});
      const double sigmas = std::abs(change) / sigma(k);
      if (sigmas > all_max) {
        all_max = sigmas;
        all_worst = {name, change, sigma(k)};
      }
    }
  }
  effect.max_all_sigmas = std::max(all_max, 0.0);
  effect.parameter_all = all_worst.parameter;
  // The decision: the calibrated parameters, when the run calibrates any.
  effect.max_sigmas = effect.max_all_sigmas;
  effect.parameter = effect.parameter_all;
  if (!effect.calibrated.empty()) {
    effect.max_sigmas = 0.0;
    for (const auto& c : effect.calibrated)
      if (std::abs(c.change) / c.sigma >= effect.max_sigmas) {
        effect.max_sigmas = std::abs(c.change) / c.sigma;
        effect.parameter = c.parameter;
      }
  }
  return effect;
}

}  // namespace aerocal::calib
