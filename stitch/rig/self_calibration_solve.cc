// Solve of the self-calibrating rig stitching (self_calibration_problem.h): data snooping with the
// standard-position veto, the covariance of the increments and offsets, the stop's effect, the dT
// correlations, the per-head results and the rules that make the run not valid.
#include "calib/core/stopwatch.h"
#include "calib/core/string_printf.h"
#include "calib/problem/data_snooping.h"
#include "stitch/rig/self_calibration_problem.h"

#include <algorithm>
#include <cmath>

namespace aerocal::stitch::internal {

bool TieAlive(const RigStitchProblem& p,
              const TieKey& key,
              const std::set<calib::ResidualId>& removed) {
  int left = 0;
  for (calib::ResidualId id : p.residuals_of_tie.at(key))
    left += p.builder.IsActive(id) && !removed.count(id);
  return left >= 2;
}

namespace {

// The veto of the snooping: a removal that would leave a standard position of an exposure without
// any tie is refused (the paper's rule against over-rejection); the reason is kept.
std::string VetoRemoval(RigStitchProblem& p, const std::vector<calib::ResidualId>& ids) {
  const std::set<calib::ResidualId> removed(ids.begin(), ids.end());
  for (calib::ResidualId id : ids) {
    const auto it = p.tie_of_residual.find(id);
    if (it == p.tie_of_residual.end()) continue;
    const auto pos = p.position_of.find(it->second);
    if (pos == p.position_of.end()) continue;
    const int i = it->second.first;
    bool any = false;
    for (const TieKey& other : p.position_ties[{i, pos->second}])
      any |= TieAlive(p, other, removed);
    if (!any) {
      const std::string reason = "standard position " + p.positions[pos->second].name +
                                 " of exposure " + p.exposures[i].image +
                                 " would lose all its ties (removing " +
                                 p.builder.ResidualLabel(id) + ")";
      p.result.stop_reasons.push_back(reason);
      return reason;
    }
  }
  return "";
}

}  // namespace

std::vector<calib::ResidualId> SolveWithSnooping(RigStitchProblem& p) {
  auto& result = p.result;
  std::vector<calib::ResidualId> kept_against_test;  // vetoed removals: the stop's suspects
  if (p.options.snooping) {
    calib::SnoopingOptions snooping;
    snooping.groups = {kGroupRigStitchTie};
    snooping.alpha = p.options.alpha;
    snooping.veto = [&p](const std::vector<calib::ResidualId>& ids) { return VetoRemoval(p, ids); };
    const calib::SnoopingOutcome outcome =
        calib::SolveWithDataSnooping(p.builder, p.options.solver, snooping);
    result.report = outcome.report;
    result.profile.solves = outcome.solves;
    result.profile.iterations = outcome.solve_iterations;
    result.profile.snooping_rounds = outcome.rounds;
    result.profile.solve_s = outcome.seconds_solving;
    result.profile.testing_s = outcome.seconds_testing;
    for (const auto& r : outcome.rejected) result.rejected.push_back(r.label);
    for (const auto& t : outcome.tested)
      if (t.verdict == calib::SnoopingVerdict::kVetoed) {
        result.stopped = true;
        kept_against_test.push_back(t.id);
      }
    for (const auto& f : outcome.findings)
      result.warnings.push_back({"data_snooping", "ties", NAN, NAN, f});
  } else {
    result.report = p.builder.Solve(p.options.solver);
    result.profile.solves = 1;
    result.profile.iterations = result.report.iterations;
    result.profile.solve_s = result.report.seconds;
  }
  std::sort(result.stop_reasons.begin(), result.stop_reasons.end());
  result.stop_reasons.erase(std::unique(result.stop_reasons.begin(), result.stop_reasons.end()),
                            result.stop_reasons.end());
  result.sigma0 = result.report.sigma0;
  result.redundancy = result.report.redundancy;
  return kept_against_test;
}

namespace {

// The increments of the non-reference heads and their free time offsets (each once).
std::vector<calib::BlockId> IncrementsAndOffsets(const RigStitchProblem& p) {
  std::vector<calib::BlockId> wanted;
  for (int i = 0; i < p.n_exposures; ++i)
    for (int k = 0; k < p.n_heads; ++k)
      if (k != p.reference) {
        wanted.push_back(p.increment[i][k]);
        if (!p.builder.IsBlockFixed(p.dt[i][k]) &&
            std::find(wanted.begin(), wanted.end(), p.dt[i][k]) == wanted.end())
          wanted.push_back(p.dt[i][k]);
      }
  return wanted;
}

// The largest |rho| of each free dT with an angle of its head (each exposure for line mode); a dT
// beyond the threshold is not determinable.
void DtCorrelations(RigStitchProblem& p) {
  const auto& cov = p.cov;
  std::map<calib::BlockId, DtCorrelation> worst;
  if (cov.ok)
    for (int i = 0; i < p.n_exposures; ++i)
      for (int k = 0; k < p.n_heads; ++k) {
        const calib::BlockId dt = p.dt[i][k], increment = p.increment[i][k];
        if (k == p.reference || p.builder.IsBlockFixed(dt)) continue;
        const int row_dt = cov.offsets.at(dt);
        for (int a = 0; a < 3; ++a) {
          const double rho = cov.Correlation(row_dt, cov.offsets.at(increment) + a);
          DtCorrelation& w = worst[dt];
          if (w.dt.empty() || std::abs(rho) > std::abs(w.rho))
            w = {p.builder.BlockName(dt),
                 p.builder.BlockName(increment) + "." + kIncrementAngleNames[a],
                 rho};
        }
      }
  for (const auto& [block, w] : worst) {
    p.result.dt_correlations.push_back(w);
    if (std::abs(w.rho) > p.options.correlation_threshold) {
      p.undetermined_dt.insert(block);
      p.result.dt_determinable = false;
    }
  }
}

}  // namespace

void EstimatePrecision(RigStitchProblem& p, const std::vector<calib::ResidualId>& kept) {
  auto& result = p.result;
  const std::vector<calib::BlockId> wanted = IncrementsAndOffsets(p);
  Stopwatch stage;
  p.cov = p.builder.EstimateCovariance(
      wanted, std::max(result.sigma0, 1e-300), p.options.correlation_threshold);
  result.profile.covariance_s = stage.Seconds();
  if (!p.cov.ok)
    result.warnings.push_back(
        {"covariance", "increments and time offsets", NAN, NAN, "covariance: " + p.cov.message});
  stage.Restart();
  if (result.stopped)  // what the rig's calibration becomes without the ties kept against the test
    result.stop_effect = calib::EffectOfLeavingOut(
        p.builder, kept, p.cov, wanted, wanted, p.options.solver, p.options.suspect_effect_limit);
  result.profile.effect_s = stage.Seconds();
  DtCorrelations(p);
}

namespace {

// Head k at exposure i: its increment and dT with their sigmas (a dT not determinable has none).
RigStitchHead HeadResult(const RigStitchProblem& p, int i, int k) {
  RigStitchHead h;
  h.head = p.heads[k].id;
  h.reference = k == p.reference;
  const double* e = p.builder.BlockValues(p.increment[i][k]);
  h.increment_rad = Eigen::Vector3d(e[0], e[1], e[2]);
  const double dt_value = *p.builder.BlockValues(p.dt[i][k]);
  h.dt_fitted_s = dt_value;
  if (!h.reference && p.cov.ok) h.increment_sigma_rad = p.cov.BlockSigma(p.increment[i][k], 3);
  if (h.reference || p.result.dt_held) {
    h.dt_s = dt_value;
  } else if (!p.undetermined_dt.count(p.dt[i][k])) {
    h.dt_s = dt_value;
    if (p.cov.ok) h.dt_sigma_s = p.cov.BlockSigma(p.dt[i][k], 1)[0];
  }
  return h;
}

}  // namespace

std::vector<RigExposure> CollectHeads(RigStitchProblem& p) {
  std::vector<RigExposure> refined = p.poses;
  for (int i = 0; i < p.n_exposures; ++i) {
    RigStitchExposureResult er;
    er.image = p.exposures[i].image;
    for (int k = 0; k < p.n_heads; ++k) {
      const RigStitchHead h = HeadResult(p, i, k);
      refined[i].increment_rad[k] = h.increment_rad;
      refined[i].dt_s[k] = h.dt_fitted_s;
      er.heads.push_back(h);
    }
    p.result.exposures.push_back(er);
  }
  return refined;
}

void JudgeRun(RigStitchProblem& p) {
  auto& result = p.result;
  if (!result.report.converged)
    result.failures.push_back("the adjustment did not converge (" + result.report.termination +
                              ": " + result.report.message + ")");
  if (!p.cov.ok)
    result.failures.push_back("covariance not computable (singular): " + p.cov.message);
  if (!(result.sigma0 <= p.options.max_sigma0))
    result.failures.push_back(
        StringPrintf("sigma0 %.3g is above %.3g: the tie sigmas or the rig model are wrong",
                     result.sigma0,
                     p.options.max_sigma0));
  // A stop is judged by its effect: invalid when it matters, else a warning (issue 28 part 2).
  for (const auto& reason : result.stop_reasons) {
    const std::string message =
        "snooping stopped: " + reason + "; " + result.stop_effect.Describe();
    if (result.stop_effect.Matters())
      result.failures.push_back(message);
    else
      result.warnings.push_back({"snooping_stopped",
                                 reason,
                                 NAN,
                                 NAN,
                                 message + "; the tie is kept and the result stands: check it"});
  }
}

}  // namespace aerocal::stitch::internal
