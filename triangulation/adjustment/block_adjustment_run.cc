// BlockAdjustment::Run: the solve, data snooping, covariance and the typed result, in named steps
// (the block itself is built in block_adjustment.cc).
#include "calib/core/csv.h"
#include "calib/core/log.h"
#include "calib/core/median.h"
#include "calib/core/stopwatch.h"
#include "calib/core/string_printf.h"
#include "calib/problem/suspect_effect.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/block_adjustment_storage.h"
#include "triangulation/adjustment/determinability.h"
#include "triangulation/adjustment/plausibility.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <utility>

namespace aerocal::triangulation {
namespace {

using calib::BlockId;

// The determinability of the interior and of the free platform parameters, by name.
void AddDeterminability(const calib::CovarianceReport& cov,
                        double correlation_threshold,
                        AdjustmentResult* result) {
  result->determinability = AssessDeterminability(cov, "camera ", correlation_threshold);
  if (!cov.ok) return;
  result->interior_correlation_names = cov.interior_names;
  result->interior_correlation = cov.interior_correlation;
  const Determinability platform = AssessDeterminability(cov, "platform ", correlation_threshold);
  for (const auto& w : platform.warnings) result->determinability.warnings.push_back(w);
  for (const auto& h : platform.high_correlations)
    result->determinability.high_correlations.push_back(h);
}

// A free network has the arbitrary datum of its starting values: its check points can only say
// something about the block's shape, after a 7-parameter similarity (Helmert) transformation onto
// their survey (Umeyama's closed form).
void CompareCheckPointsAfterHelmert(AdjustmentResult* result) {
  const int n = static_cast<int>(result->check_points.size());
  Eigen::Matrix3Xd adjusted(3, n), surveyed(3, n);
  for (int i = 0; i < n; ++i) {
    adjusted.col(i) = result->check_points[i].adjusted_m;
    surveyed.col(i) = result->check_points[i].surveyed_m;
  }
  const Eigen::Matrix4d helmert = Eigen::umeyama(adjusted, surveyed, true);
  for (auto& d : result->check_points) {
    d.adjusted_m = helmert.topLeftCorner<3, 3>() * d.adjusted_m + helmert.topRightCorner<3, 1>();
    d.difference_m = d.adjusted_m - d.surveyed_m;
  }
  result->notes.push_back(
      "free network: check points compared after a 7-parameter similarity transformation fitted "
      "to their " +
      std::to_string(n) + " surveyed positions (scale " +
      std::to_string(helmert.topLeftCorner<3, 3>().col(0).norm()) +
      "); the RMSE measures the block's shape and is optimistic by the 7 fitted parameters");
}

// Honest outcome: what makes this run untrustworthy, by name.
void InvalidateWhereUntrustworthy(const AdjustOptions& options,
                                  const calib::CovarianceReport& cov,
                                  AdjustmentResult* result) {
  if (!result->solve.converged)
    result->Invalidate("the adjustment did not converge (" + result->solve.termination + ")");
  if (result->snooping.cap_reached)
    result->Invalidate("data snooping reached the rejection cap of " +
                       std::to_string(result->snooping.max_rejections) + " with " +
                       std::to_string(result->snooping.remaining_above_critical) +
                       " candidate(s) left above the critical value");
  if (options.data_snooping && result->snooping.run && !result->snooping.cofactors_ok)
    result->Invalidate("data snooping could not test: " + result->snooping.cofactor_message);
  if (result->sigma0 > options.max_sigma0)
    result->Invalidate("sigma0 " + FormatNumber(result->sigma0, 3) + " is above the limit " +
                       FormatNumber(options.max_sigma0, 3) + " (max_sigma0)");
  if (options.estimate_covariance && !cov.ok)
    result->Invalidate("no covariance: " + cov.message);
  else if (!result->determinability.undetermined.empty())
    result->Invalidate("singular: " + std::to_string(result->determinability.undetermined.size()) +
                       " parameter(s) not determinable (" +
                       result->determinability.undetermined.front() + ", ...)");
}

// One warning per control point whose survey snooping left out (its rays are kept).
void AddControlBlunderWarnings(AdjustmentResult* result) {
  for (const auto& left : result->control_left_out) {
    const PointDifference& d = left.difference;
    const double w = std::max(0.0, left.LargestW().value_or(0.0));
    const std::string parts = left.ComponentNames();
    result->warnings.push_back(
        {kWarningControlBlunder,
         d.point,
         w,
         result->snooping.critical_value,
         StringPrintf(
             "suspected control blunder: the survey of control point %s (its %s) disagrees "
             "with its %d rays (w = %.1f > %.2f; survey - block X %.3f Y %.3f Z %.3f m) "
             "and every other survey fits without it: it is left out of the adjustment, its "
             "rays are kept; check its survey",
             d.point.c_str(),
             parts.c_str(),
             d.rays,
             w,
             result->snooping.critical_value,
             -d.difference_m.x(),
             -d.difference_m.y(),
             -d.difference_m.z())});
  }
}

}  // namespace

AdjustmentResult BlockAdjustment::Run(Progress* progress) {
  const auto advance = [&] {
    if (progress) progress->Advance();
  };
  AdjustmentResult result;
  const Stopwatch run_time;
  result.free_interior = options_.free_interior;
  result.frame = project_.frame.description;
  result.datum = storage_->datum;
  result.notes = storage_->notes;
  // Likely unit mistakes of the inputs: said before the solve (a long run should not hide one
  // until its end) and listed first among the result's warnings.
  const std::vector<ResultWarning> plausibility = PlausibilityWarnings(project_);
  for (const ResultWarning& w : plausibility)
    LogWarning(w.name + ": " + w.subject + ": " + w.message);

  // Stage 1 (self-calibration only): exterior orientation and points with the interior fixed.
  if (!options_.free_interior.empty()) {
    const CovarianceBlocks interior = CovarianceBlocksOf(false);
    for (BlockId b : interior.all) builder_.FixBlock(b);
    builder_.Solve(options_.solver);
    for (BlockId b : interior.all) builder_.FreeBlock(b);
  }
  advance();
  result.solve = builder_.Solve(options_.solver);
  // More than robust_trigger_share of the image components above robust_trigger_w sigmas are
  // gross errors a least-squares start cannot survive.
  result.snooping.gross_share = GrossShare();
  if (stop_for_robust_start_ && options_.auto_robust_start && !options_.robust_start &&
      result.snooping.gross_share > options_.robust_trigger_share) {
    result.robust_start_needed = true;
    return result;
  }
  result.timing.solve_s = run_time.Seconds();
  calib::SnoopingOutcome snooped;
  const Stopwatch snooping_time;
  if (options_.data_snooping) snooped = Snoop(&result);
  result.timing.snooping_s = snooping_time.Seconds();
  result.timing.testing_s = snooped.seconds_testing;
  if (!snooped.rejected.empty()) DropSingleRayPoints(&result);

  CollectResiduals(&result);
  SetSigma0Units(&result);
  const CovarianceBlocks blocks = CovarianceBlocksOf(true);
  advance();
  const Stopwatch covariance_time;
  const calib::CovarianceReport cov = EstimateCovariance(blocks, result);
  result.timing.covariance_s = covariance_time.Seconds();
  advance();
  AddDeterminability(cov, options_.correlation_threshold, &result);
  result.platform = PlatformResult(cov);
  CollectCameras(cov, &result);
  CollectExposures(cov, &result);
  CollectPoints(&result);
  if (storage_->free_network && result.check_points.size() >= 3)
    CompareCheckPointsAfterHelmert(&result);
  result.control = ComputePointStatistics(result.control_points);
  result.check = ComputePointStatistics(result.check_points);
  if (result.snooping.run) ClassifyUncontrolled(options_.min_redundancy, &result);
  for (const auto& d : result.solve.diagnostics) result.notes.push_back(d);
  InvalidateWhereUntrustworthy(options_, cov, &result);
  result.warnings = plausibility;
  for (auto& w : GroupRmsWarnings(result.solve)) result.warnings.push_back(std::move(w));
  AddControlBlunderWarnings(&result);
  if (!result.snooping.unresolved_surveys.empty()) JudgeUnresolvedSurveys(cov, blocks, &result);
  result.timing.total_s = run_time.Seconds();
  return result;
}

double BlockAdjustment::GrossShare() const {
  int n = 0, gross = 0;
  for (const auto& [id, index] : storage_->observation_of_residual)
    if (builder_.IsActive(id))
      for (double v : builder_.EvaluateResidual(id)) {
        ++n;
        gross += std::abs(v) > options_.robust_trigger_w;
      }
  return n > 0 ? static_cast<double>(gross) / n : 0.0;
}

// A point left with a single ray after rejections is no longer determined: drop its last
// observation (it carried no redundancy) and solve once more for honest statistics.
void BlockAdjustment::DropSingleRayPoints(AdjustmentResult* result) {
  std::vector<std::vector<calib::ResidualId>> active_rays(storage_->points.size());
  for (const auto& [id, index] : storage_->observation_of_residual)
    if (builder_.IsActive(id)) active_rays[storage_->point_of_observation[index]].push_back(id);
  bool dropped = false;
  for (PointIndex p = 0; p < static_cast<PointIndex>(storage_->points.size()); ++p) {
    auto& state = storage_->points[p];
    if (state.block < 0) continue;
    const std::string& id = storage_->point_ids[p];
    const auto& ids = active_rays[p];
    state.rays = static_cast<int>(ids.size());
    if (state.Control() || state.rays != 1) continue;
    builder_.RemoveResidual(ids.front());
    state.rays = 0;
    dropped = true;
    storage_->notes.push_back("point " + id +
                              " keeps one ray after the rejections and is left out");
  }
  if (dropped) result->solve = builder_.Solve(options_.solver);
  result->notes = storage_->notes;
}

// Residuals of every image observation (whitened r = (ideal - projected) / sigma in photo space,
// x right and y up; in (col, row) pixels that is (r_x, -r_y) sigma). Reserved: grown by doubling
// it was the largest allocation at the peak heap (heaptrack, 600 exposures).
void BlockAdjustment::CollectResiduals(AdjustmentResult* result) const {
  result->residuals.reserve(result->residuals.size() + storage_->observation_of_residual.size());
  for (const auto& [id, index] : storage_->observation_of_residual) {
    const auto& o = storage_->observations[index];
    ObservationResidual v;
    v.image = o.image;
    v.point = o.point;
    v.measured_px = o.pixel;
    storage_->sensor_of_observation[index]->Annotate(o, &v);
    v.sigma_px = o.sigma_px;
    v.used = builder_.IsActive(id);
    const std::vector<double> r = v.used ? builder_.EvaluateResidual(id) : std::vector<double>{};
    if (r.size() == 2) v.residual_px = Eigen::Vector2d(r[0], -r[1]) * o.sigma_px;
    const auto test = storage_->tests.find(id);
    if (test != storage_->tests.end()) v.test = test->second;
    result->residuals.push_back(std::move(v));
  }
}

// Statistics in the units of the image measurements (CONVENTIONS.md "Statistics"), over every
// active image observation, virtual or raw: the median a-priori sigma in px, and in um with each
// observation's own camera pixel size (blocks may mix cameras).
void BlockAdjustment::SetSigma0Units(AdjustmentResult* result) const {
  std::vector<double> image_sigmas, image_sigmas_um;
  for (const auto& [id, index] : storage_->observation_of_residual) {
    if (!builder_.IsActive(id)) continue;
    const ImageObservation& o = storage_->observations[index];
    image_sigmas.push_back(o.sigma_px);
    image_sigmas_um.push_back(
        o.sigma_px *
        storage_->exposures[storage_->exposure_of_observation[index]].camera->pixel_size_mm *
        1000.0);
  }
  result->sigma0 = result->solve.sigma0;
  result->sigma0_px = result->sigma0 * Median(image_sigmas);
  result->sigma0_um = result->sigma0 * Median(image_sigmas_um);
}

// The interior blocks; with `with_exterior` the covariance's blocks: interior and exterior
// orientation, interior x everything (so c ~ Z0 and x0 ~ X0 / phi show), exterior blocks only
// with themselves (cheap for large blocks); the platform parameters x everything (lever arm ~
// centres, time offset ~ X0).
BlockAdjustment::CovarianceBlocks BlockAdjustment::CovarianceBlocksOf(bool with_exterior) const {
  CovarianceBlocks blocks;
  for (CameraIndex k = 0; k < storage_->index.NumCameras(); ++k)
    blocks.all.push_back(storage_->frame.InteriorBlock(k));
  if (!with_exterior) return blocks;
  blocks.cross = blocks.all;
  for (BlockId b : {storage_->lever_block, storage_->time_block, storage_->boresight_block})
    if (b >= 0) {
      blocks.all.push_back(b);
      if (!builder_.IsBlockFixed(b)) blocks.cross.push_back(b);
    }
  for (ExposureIndex k : storage_->exposure_order) {
    blocks.all.push_back(storage_->exposures[k].opk_block);
    blocks.all.push_back(storage_->exposures[k].center_block);
  }
  return blocks;
}

calib::CovarianceReport BlockAdjustment::EstimateCovariance(const CovarianceBlocks& blocks,
                                                            const AdjustmentResult& result) {
  calib::CovarianceReport cov;
  if (!options_.estimate_covariance)
    cov.message = "covariance not estimated (option)";
  else if (result.solve.usable && result.solve.redundancy > 0)
    cov = builder_.EstimateCovariance(
        blocks.all, result.sigma0, options_.correlation_threshold, blocks.cross);
  else
    cov.message = "no covariance: the adjustment has no usable solution or no redundancy";
  return cov;
}

void BlockAdjustment::CollectCameras(const calib::CovarianceReport& cov,
                                     AdjustmentResult* result) const {
  for (CameraIndex k = 0; k < storage_->index.NumCameras(); ++k) {
    const std::string& id = storage_->index.CameraId(k);
    const calib::Camera& camera = project_.cameras.at(id);
    const std::vector<calib::ParamInfo> table = camera.Params();
    const int n = static_cast<int>(table.size());
    CameraEstimate c;
    c.id = id;
    c.model = camera.model;
    c.initial = camera.interior;
    c.estimated = storage_->frame.Interior(k);
    c.sigma = calib::InteriorParams::ForModel(camera.model);
    c.free = calib::ParamVector<bool>::ForModel(camera.model);
    for (int i = 0; i < n; ++i)
      c.free[i] = std::find(options_.free_interior.begin(),
                            options_.free_interior.end(),
                            std::string(table[i].name)) != options_.free_interior.end();
    if (cov.ok) {
      const Eigen::VectorXd s = cov.BlockSigma(storage_->frame.InteriorBlock(k), n);
      for (int i = 0; i < n; ++i) c.sigma[i] = c.free[i] ? s(i) : 0.0;
    }
    result->cameras.push_back(c);
  }
}

void BlockAdjustment::CollectExposures(const calib::CovarianceReport& cov,
                                       AdjustmentResult* result) const {
  std::vector<bool> used_images(storage_->exposures.size(), false);
  for (const auto& [id, index] : storage_->observation_of_residual)
    if (builder_.IsActive(id)) used_images[storage_->exposure_of_observation[index]] = true;
  for (ExposureIndex k : storage_->exposure_order) {
    const auto& state = storage_->exposures[k];
    const std::string& image = state.exposure->image;
    ExposureEstimate e;
    e.image = image;
    e.center_m = state.center;
    e.opk_rad = calib::OpkFromQuaternionNear(state.rotation, state.exposure->opk_rad);
    const Exposure& x = *state.exposure;
    e.used = used_images[k] || (options_.use_eo_priors && x.center_sigma_m && x.opk_sigma_rad);
    if (cov.ok && e.used) {
      e.center_sigma_m = cov.BlockSigma(state.center_block, 3);
      e.opk_sigma_rad = cov.BlockSigma(state.opk_block, 3);
      if (std::isnan(e.opk_sigma_rad->x()))
        result->notes.push_back(
            "image " + image +
            ": phi is 90 deg (gimbal lock), omega and kappa are not separable "
            "(only their sum or difference is): their sigmas are unknown (null)");
    }
    result->exposures.push_back(e);
  }
}

// The adjusted points (two rays or control), and the surveyed ones against their survey: control,
// check, or left out by snooping.
void BlockAdjustment::CollectPoints(AdjustmentResult* result) const {
  for (PointIndex p = 0; p < static_cast<PointIndex>(storage_->points.size()); ++p) {
    const auto& state = storage_->points[p];
    const std::string& id = storage_->point_ids[p];
    const bool control = state.Control();
    if (state.block < 0 || (state.rays < 2 && !control)) continue;
    result->points_m[id] = state.xyz;
    if (!state.ground || state.ground->role == PointRole::kTie || !state.ground->xyz_m) continue;
    PointDifference d;
    d.point = id;
    d.surveyed_m = *state.ground->xyz_m;
    d.adjusted_m = state.xyz;
    d.difference_m = state.xyz - d.surveyed_m;
    d.rays = state.rays;
    const auto left_out = storage_->survey_left_out.find(p);
    if (left_out != storage_->survey_left_out.end()) {
      result->control_left_out.push_back({d, left_out->second});
      continue;
    }
    (state.ground->role == PointRole::kControl ? result->control_points : result->check_points)
        .push_back(d);
  }
}

// Surveys that fail their test but cannot be left out. Judged by their effect (issue 28): invalid
// only when leaving the suspects out moves a parameter by more than the limit in its sigmas.
void BlockAdjustment::JudgeUnresolvedSurveys(const calib::CovarianceReport& cov,
                                             const CovarianceBlocks& blocks,
                                             AdjustmentResult* result) {
  SuspectEffect& effect = result->snooping.unresolved_effect;
  effect = calib::EffectOfLeavingOut(builder_,
                                     storage_->unresolved_ids,
                                     cov,
                                     blocks.all,
                                     blocks.cross,
                                     options_.solver,
                                     options_.suspect_effect_limit);
  std::string names;
  double w = 0.0;
  for (const auto& u : result->snooping.unresolved_surveys) {
    names += (names.empty() ? "" : ", ") + u.survey;
    w = std::max(w, u.w);
  }
  const std::string impact = effect.Describe();
  const std::string message =
      "control survey blunder not resolved: " + names + " fail the survey test (w up to " +
      FormatNumber(w, 3) + " > " + FormatNumber(result->snooping.critical_value, 3) +
      ") and none can be left out: " + result->snooping.unresolved_reason + "; " + impact +
      (effect.Matters() ? "; every survey is kept, the block is bent to fit them: check these "
                          "surveys"
                        : "; every survey is kept and the result stands: check these surveys");
  result->warnings.push_back(
      {kWarningControlBlunderUnresolved, names, w, result->snooping.critical_value, message});
  if (effect.Matters()) result->Invalidate(message);
}

}  // namespace aerocal::triangulation
