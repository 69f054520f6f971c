// The effect of suspects on the results (issue 28, "validity judged by effect"): a suspicion that
// no test can resolve (failing control surveys the test cannot tell apart) is decisive only when
// it matters. The problem is re-solved with the suspects left out, and every parameter whose sigma
// the covariance at the full solution gives (free interior and platform parameters, exterior
// orientations) is compared, in its own sigmas: |x_without - x_with| / sigma_x. That is the
// leave-out form of external reliability (Baarda: the effect of an undetected error on the
// parameters), measured instead of bounded, so it holds for a group and in non-linear problems.
#pragma once

#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjustment_result.h"

#include <vector>

namespace aerocal::triangulation {

/// Leaves `suspects` out of `builder`, re-solves, measures the change of every free entry of
/// `blocks` in its sigma from `cov` (rotation blocks as omega, phi, kappa), then restores the
/// residuals and every value: the builder ends in the state it started in. The free entries of
/// `calibrated` (interior, platform) are listed one by one and decide (max_sigmas): a calibration
/// is judged by what it calibrates; without any (a conventional run) every entry of `blocks`
/// decides. The largest change over all of `blocks` is kept apart (max_all_sigmas).
/// `limit_sigmas` is recorded for SuspectEffect::Matters(). Not computed (Matters() true) without
/// a covariance or when the re-solve fails.
SuspectEffect EffectOfLeavingOut(calib::ProblemBuilder& builder,
                                 const std::vector<calib::ResidualId>& suspects,
                                 const calib::CovarianceReport& cov,
                                 const std::vector<calib::BlockId>& blocks,
                                 const std::vector<calib::BlockId>& calibrated,
                                 const calib::SolverOptions& solver,
                                 double limit_sigmas);

}  // namespace aerocal::triangulation
