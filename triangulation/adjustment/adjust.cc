// Adjust(): one adjustment, or with a robust start a Cauchy-loss adjustment whose solution and
// gross-error screening start the clean one (see AdjustOptions::robust_start). The robust start
// runs when asked, or by default when the first solve's residuals call for it
// (AdjustOptions::auto_robust_start).
#include "calib/core/csv.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/kept_adjustment.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <unordered_map>

namespace aerocal::triangulation {
namespace {

// The used exposures and the cameras of a result by id, looked up once per run (ids are strings
// only at this boundary: the result is what the next adjustment starts from).
struct SolutionIndex {
  explicit SolutionIndex(const AdjustmentResult& r) {
    for (const auto& e : r.exposures)
      if (e.used) exposure[e.image] = &e;
    for (const auto& c : r.cameras) camera[c.id] = &c;
  }
  std::unordered_map<std::string, const ExposureEstimate*> exposure;
  std::unordered_map<std::string, const CameraEstimate*> camera;
};

// Whitened residual of `o` at the solution of `r`, the result of `adjustment` (issue 28: built by
// the sensor kind and the camera's own model, as the solve builds it, never the 10-parameter
// functor on another model's block); nullopt when its exposure was not used there, its point is
// not in that solution or the ray misses.
std::optional<Eigen::Vector2d> ResidualAt(BlockAdjustment& adjustment,
                                          const AdjustmentResult& r,
                                          const SolutionIndex& solution,
                                          const ImageObservation& o) {
  if (!solution.exposure.count(o.image) || !r.points_m.count(o.point)) return std::nullopt;
  return adjustment.ResidualAtCurrentValues(o);
}

// The solution of `r` becomes the starting values of `project`: exterior orientation of the
// exposures it used, interior of every camera, tie point coordinates. Surveyed coordinates stay
// the survey.
void StartFromSolution(const AdjustmentResult& r, Project* project) {
  const SolutionIndex solution(r);
  for (auto& e : project->exposures) {
    const auto s = solution.exposure.find(e.image);
    if (s == solution.exposure.end()) continue;
    e.center_m = s->second->center_m;
    e.opk_rad = s->second->opk_rad;
  }
  for (const auto& c : r.cameras) project->cameras.at(c.id).interior = c.estimated;
  for (auto& p : project->points)
    if (p.role == PointRole::kTie && r.points_m.count(p.id)) p.xyz_m = r.points_m.at(p.id);
}

// The adjustment without a robust start; nullopt when its first solve calls for one (then
// `reason` and `gross_share` say why).
std::optional<AdjustmentResult> PlainAdjustment(const Project& project,
                                                const AdjustOptions& options,
                                                Progress* progress,
                                                KeptAdjustment* keep,
                                                std::string* reason,
                                                double* gross_share) {
  // Kept: the adjustment refers to its project, so a kept one is built on a copy the keeper owns.
  auto copy = keep ? std::make_unique<const Project>(project) : nullptr;
  auto adjustment = std::make_unique<BlockAdjustment>(keep ? *copy : project, options);
  adjustment->StopWhenRobustStartNeeded(options.auto_robust_start);
  AdjustmentResult plain = adjustment->Run(progress);
  if (!plain.robust_start_needed) {
    if (keep) *keep = {std::move(copy), std::move(adjustment)};
    return plain;
  }
  *gross_share = plain.snooping.gross_share;
  *reason = FormatNumber(100 * *gross_share, 3) + " % of the image components above " +
            FormatNumber(options.robust_trigger_w, 3) + " sigma in the first solve";
  return std::nullopt;
}

// 1. Robust (Cauchy) adjustment, then the observations far outside its solution, judged with
//    redundancy numbers. `next` is the project without them, started from the robust solution.
std::vector<BlockAdjustment::Screened> RobustScreening(const Project& project,
                                                       const AdjustOptions& options,
                                                       Progress* progress,
                                                       Project* next) {
  AdjustOptions robust = options;
  robust.data_snooping = false;
  robust.estimate_covariance = false;
  calib::LossOptions loss;
  loss.kind = calib::LossKind::kCauchy;
  loss.scale = options.robust_scale_sigma;
  AdjustmentResult start;
  std::vector<BlockAdjustment::Screened> screened;
  {
    BlockAdjustment adjustment(project, robust, {}, loss);
    start = adjustment.Run(progress);
    screened = adjustment.ScreenRobustly(options.robust_reject_sigma);
  }
  std::vector<bool> excluded(project.observations.size(), false);
  for (const auto& s : screened) excluded[s.source] = true;
  *next = project;
  next->observations.clear();
  for (size_t i = 0; i < project.observations.size(); ++i)
    if (!excluded[i]) next->observations.push_back(project.observations[i]);
  // The robust solution becomes the starting values; surveyed coordinates stay the survey.
  StartFromSolution(start, next);
  return screened;
}

// The screened observations after the clean solution: those still excluded and how many went
// back.
struct Readmission {
  std::vector<BlockAdjustment::Screened> still_excluded;
  int readmitted = 0;  // fit the clean solution
  int retested = 0;    // on points the clean solution does not hold: left to snooping
};

// 2. Clean solution without the excluded observations; those that fit it are re-admitted:
//    |v| / sigma at a solution they did not influence below the critical value (their
//    w would be smaller still: the prediction's variance exceeds sigma^2). The excluded rays
//    of a point the clean solution does not hold (all or all but one of its rays excluded)
//    cannot be judged there: they go back to the final adjustment, whose snooping tests them
//    with redundancy numbers and rejects the blunder, or the point's correlated group when no
//    test can tell its rays apart (a robust cut would drop the point's good rays with it, or
//    name an arbitrary ray of a two-ray point).
Readmission ReadmitFitting(const std::vector<BlockAdjustment::Screened>& screened,
                           const AdjustOptions& options,
                           Progress* progress,
                           Project* next) {
  AdjustOptions clean_options = options;
  clean_options.data_snooping = false;
  clean_options.estimate_covariance = false;
  BlockAdjustment clean_adjustment(*next, clean_options);
  const AdjustmentResult clean = clean_adjustment.Run(progress);
  const int components = 2 * static_cast<int>(next->observations.size());
  const double critical =
      options.snooping_critical_value > 0
          ? options.snooping_critical_value
          : std::max(3.29,
                     calib::NormalCriticalValue(options.snooping_alpha / std::max(1, components)));
  const double scale = std::max(1.0, clean.sigma0);
  Readmission out;
  const SolutionIndex clean_solution(clean);
  std::vector<ImageObservation> back;  // into `next` only once clean_adjustment is done with it
  for (const auto& s : screened) {
    const bool undetermined = !clean.points_m.count(s.observation.point);
    const auto v = ResidualAt(clean_adjustment, clean, clean_solution, s.observation);
    if (undetermined || (v && v->cwiseAbs().maxCoeff() / scale < critical)) {
      back.push_back(s.observation);
      ++(undetermined ? out.retested : out.readmitted);
    } else {
      out.still_excluded.push_back(s);
    }
  }
  next->observations.insert(next->observations.end(), back.begin(), back.end());
  StartFromSolution(clean, next);
  return out;
}

// The observations the robust start still excludes: rejected ("robust start") and unused
// residuals of the final result.
void AddRobustRejections(const std::vector<BlockAdjustment::Screened>& still_excluded,
                         AdjustmentResult* result) {
  std::vector<RejectedObservation> pre_rejected;
  for (const auto& s : still_excluded) {
    RejectedObservation r;
    r.image = s.observation.image;
    r.point = s.observation.point;
    r.measured_px = s.observation.pixel;
    r.residual_px = s.residual_px;
    r.w = s.w;
    r.by = "robust start";
    r.group = {s.observation.image};
    pre_rejected.push_back(r);
    ObservationResidual v;
    v.image = s.observation.image;
    v.point = s.observation.point;
    v.measured_px = s.observation.pixel;
    v.residual_px = Eigen::Vector2d(s.residual_px.x(), -s.residual_px.y());
    v.sigma_px = s.observation.sigma_px;
    v.used = false;
    result->residuals.push_back(v);
  }
  result->rejected.insert(result->rejected.begin(), pre_rejected.begin(), pre_rejected.end());
}

// The robust start's counts and its note in the final result.
void RecordRobustStart(const AdjustOptions& options,
                       const std::string& reason,
                       double gross_share,
                       int excluded,
                       const Readmission& readmission,
                       AdjustmentResult* result) {
  result->snooping.robust_start = true;
  result->snooping.robust_start_reason = reason;
  result->snooping.gross_share = gross_share;
  result->snooping.robust_excluded = excluded;
  result->snooping.robust_readmitted = readmission.readmitted;
  result->snooping.robust_retested = readmission.retested;
  result->notes.push_back(
      "started from a robust (Cauchy, " + FormatNumber(options.robust_scale_sigma, 3) +
      " sigma) adjustment (" + reason + "): " + std::to_string(excluded) +
      " observation(s) beyond " + FormatNumber(options.robust_reject_sigma, 3) +
      " robust w excluded, " + std::to_string(readmission.readmitted) +
      " re-admitted because they fit the clean solution, " + std::to_string(readmission.retested) +
      " on points the clean solution could not hold left to snooping");
}

}  // namespace

int AdjustStages(const AdjustOptions& options) {
  return (options.robust_start ? 3 : 1) * BlockAdjustment::kRunStages;
}

AdjustmentResult Adjust(const Project& project,
                        const AdjustOptions& options,
                        Progress* progress,
                        KeptAdjustment* keep) {
  std::string reason = "--robust-start";
  double gross_share = 0.0;
  if (!options.robust_start)
    if (auto plain = PlainAdjustment(project, options, progress, keep, &reason, &gross_share))
      return std::move(*plain);
  Project next;
  const auto screened = RobustScreening(project, options, progress, &next);
  const Readmission readmission = ReadmitFitting(screened, options, progress, &next);

  // 3. The final adjustment with snooping and covariance.
  AdjustOptions final_options = options;
  final_options.robust_start = false;
  auto final_project = keep ? std::make_unique<const Project>(next) : nullptr;
  auto adjustment = std::make_unique<BlockAdjustment>(keep ? *final_project : next, final_options);
  AdjustmentResult result = adjustment->Run(progress);
  if (keep) *keep = {std::move(final_project), std::move(adjustment)};
  for (auto& c : result.cameras) c.initial = project.cameras.at(c.id).interior;
  AddRobustRejections(readmission.still_excluded, &result);
  RecordRobustStart(
      options, reason, gross_share, static_cast<int>(screened.size()), readmission, &result);
  return result;
}

}  // namespace aerocal::triangulation
