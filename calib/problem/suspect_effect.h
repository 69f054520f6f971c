// The effect of suspects on the results (issue 28, "validity judged by effect"): a suspicion that
// no test can resolve (failing control surveys the test cannot tell apart) is decisive only when
// it matters. The problem is re-solved with the suspects left out, and every parameter whose sigma
// the covariance at the full solution gives (free interior and platform parameters, exterior
// orientations) is compared, in its own sigmas: |x_without - x_with| / sigma_x. That is the
// leave-out form of external reliability (Baarda: the effect of an undetected error on the
// parameters), measured instead of bounded, so it holds for a group and in non-linear problems.
// Shared by every adjustment that snoops (the block adjustment, calibration, the rig stitching):
// one rule, one JSON form ("unresolved_effect" / "stop_effect").
#pragma once

#include "calib/problem/problem_builder.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::calib {

/// The effect of suspects that no test could resolve: every parameter with a sigma re-estimated
/// without them, the change in that parameter's sigmas. The result keeps the solution with every
/// suspect; the effect on what the run calibrates decides whether it is valid (the caller's limit).
struct SuspectEffect {
  bool computed = false;
  std::string message;  // why it could not be computed (no covariance, the re-solve failed)
  double limit_sigmas = 0;
  /// The decision: the largest |change| / sigma over the calibrated parameters (free interior and
  /// platform, rig increments), over every parameter when the run calibrates none (conventional).
  double max_sigmas = 0;
  std::string parameter;      // where it is largest ("camera cam1.c", "image 0012 centre.Z")
  double max_all_sigmas = 0;  // the largest over every parameter, exterior orientations included
  std::string parameter_all;
  struct Change {
    std::string parameter;
    double change = 0, sigma = 0;  // the parameter's units (table units, m, rad)
  };
  std::vector<Change> calibrated;  // every calibrated parameter
  bool Matters() const { return !computed || max_sigmas > limit_sigmas; }
  /// "leaving them out moves P by N of its sigmas (limit L, --suspect-effect-limit)", or why the
  /// effect is unknown.
  std::string Describe() const;
};

/// The JSON form: computed, limit_sigmas, max_sigmas, parameter, max_all_sigmas, parameter_all,
/// matters, message, calibrated[] (parameter, change, sigma, sigmas); null where unknown.
nlohmann::json SuspectEffectJson(const SuspectEffect& effect);

/// Leaves `suspects` out of `builder`, re-solves, measures the change of every free entry of
/// `blocks` in its sigma from `cov` (rotation blocks as omega, phi, kappa), then restores the
/// residuals and every value: the builder ends in the state it started in. The free entries of
/// `calibrated` (interior, platform) are listed one by one and decide (max_sigmas): a calibration
/// is judged by what it calibrates; without any (a conventional run) every entry of `blocks`
/// decides. The largest change over all of `blocks` is kept apart (max_all_sigmas).
/// `limit_sigmas` is recorded for SuspectEffect::Matters(). Not computed (Matters() true) without
/// a covariance or when the re-solve fails.
SuspectEffect EffectOfLeavingOut(ProblemBuilder& builder,
                                 const std::vector<ResidualId>& suspects,
                                 const CovarianceReport& cov,
                                 const std::vector<BlockId>& blocks,
                                 const std::vector<BlockId>& calibrated,
                                 const SolverOptions& solver,
                                 double limit_sigmas);

}  // namespace aerocal::calib
