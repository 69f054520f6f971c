// BlockAdjustment::Snoop (block_adjustment.h): data snooping of the image groups the kinds' terms
// came in and of the control surveys, with the datum guard as its veto, and the outcome written
// into the result (the snooping summary, each tested observation, the rejected ones).
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/block_adjustment_storage.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace aerocal::triangulation {
namespace {

// The automatic rejection cap (AdjustOptions::max_rejections 0): 10 % of the tested image
// observations, at least this many.
constexpr int kMinAutomaticCap = 100;

// The test of one observation as the result reports it (redundancy, w, MDB in sigmas and px).
ObservationTest TestOf(const calib::TestedObservation& x, double sigma_px) {
  ObservationTest t;
  t.tested = true;
  for (int k = 0; k < 2 && k < static_cast<int>(x.v.size()); ++k) {
    t.redundancy(k) = x.redundancy[k];
    t.w(k) = x.w[k];
    t.mdb_sigma(k) = x.mdb_sigma[k];
    t.mdb_px(k) = x.mdb_sigma[k] * sigma_px;
  }
  t.group_size = x.group_size;
  t.verdict = calib::VerdictName(x.verdict);
  t.reason = x.reason;
  return t;
}

}  // namespace

calib::SnoopingOutcome BlockAdjustment::Snoop(AdjustmentResult* result) {
  // The datum guard: no control point below two rays, no exposure below three points (unless
  // GNSS and IMU priors hold it). Counts of the active rays, kept up to date on every approval.
  Storage& st = *storage_;
  std::vector<int> point_rays(st.points.size(), 0), image_rays(st.exposures.size(), 0);
  for (const auto& [id, index] : st.observation_of_residual)
    if (builder_.IsActive(id)) {
      ++point_rays[st.point_of_observation[index]];
      ++image_rays[st.exposure_of_observation[index]];
    }
  calib::SnoopingOptions snooping = SnoopingSettings(image_rays);
  snooping.veto = DatumVeto(&point_rays, &image_rays);
  const calib::SolveReport first = result->solve;
  calib::SnoopingOutcome out =
      calib::SolveWithDataSnooping(builder_, options_.solver, snooping, &first);
  for (const auto& x : out.left_out) {
    const auto it = st.control_of_residual.find(x.id);
    if (it != st.control_of_residual.end())
      st.survey_left_out[it->second.first].emplace_back(it->second.second, x.w_full);
  }
  result->solve = out.report;
  if (out.solves > 0) {
    result->solve.iterations += first.iterations;  // the first solve, before snooping
    result->solve.initial_cost = first.initial_cost;
  }
  result->snooping.max_rejections = snooping.max_rejections;
  SummariseSnooping(out, &result->snooping);
  RecordTested(out, &result->snooping);
  RecordRejected(out, result);
  return out;
}

calib::SnoopingOptions BlockAdjustment::SnoopingSettings(const std::vector<int>& image_rays) const {
  calib::SnoopingOptions snooping;
  // The image groups the kinds' terms came in (AddImageResiduals), and the control surveys.
  snooping.groups.assign(storage_->snooped_groups.begin(), storage_->snooped_groups.end());
  snooping.groups.push_back(calib::kGroupControl);
  snooping.report_only_groups = {calib::kGroupControl};
  snooping.alpha = options_.snooping_alpha;
  snooping.critical_value = options_.snooping_critical_value;
  snooping.power = options_.snooping_power;
  snooping.min_redundancy = options_.min_redundancy;
  snooping.group_correlation = options_.group_correlation;
  int tested_images = 0;
  for (int n : image_rays) tested_images += n;
  snooping.max_rejections = options_.max_rejections > 0
                                ? options_.max_rejections
                                : std::max(kMinAutomaticCap, tested_images / 10);
  snooping.model_error_sigma0 = options_.model_error_sigma0;
  snooping.leave_out_report_only = options_.leave_out_failing_control;
  return snooping;
}

std::function<std::string(const std::vector<calib::ResidualId>&)> BlockAdjustment::DatumVeto(
    std::vector<int>* point_rays, std::vector<int>* image_rays) const {
  // Without GNSS centres the surveys hold the datum: at least three plan and three height
  // surveys stay.
  bool gnss = false;
  for (const auto& state : storage_->exposures)
    gnss |= options_.use_eo_priors && state.exposure->center_sigma_m.has_value();
  return [this, point_rays, image_rays, gnss](const std::vector<calib::ResidualId>& ids) {
    const Storage& st = *storage_;
    std::map<std::string, std::pair<int, int>> kept_leaving;  // by component: active, leaving
    for (const auto& [id, survey] : st.control_of_residual) {
      auto& [surveys, leaving] = kept_leaving[survey.second];
      surveys += builder_.IsActive(id);
      leaving += std::find(ids.begin(), ids.end(), id) != ids.end();
    }
    for (const auto& [component, count] : kept_leaving)
      if (count.second > 0 && !gnss && count.first - count.second < 3)
        return "leaving out the survey would leave " + std::to_string(count.first - count.second) +
               " control point(s) with a " + component +
               " survey and no GNSS centres: the datum needs 3";
    // Keyed by point index (id order) and by exposure rank (image id order): the first veto
    // found is the one named.
    std::map<PointIndex, int> lose_point;
    std::map<int, int> lose_image;
    for (calib::ResidualId id : ids) {
      const auto it = st.observation_of_residual.find(id);
      if (it == st.observation_of_residual.end()) continue;
      ++lose_point[st.point_of_observation[it->second]];
      ++lose_image[st.exposure_rank[st.exposure_of_observation[it->second]]];
    }
    for (const auto& [point, n] : lose_point) {
      if (st.points[point].Control() && (*point_rays)[point] - n < 2)
        return "control point " + st.point_ids[point] + " would keep " +
               std::to_string((*point_rays)[point] - n) +
               " ray(s): its rays are kept, check its measurements";
    }
    for (const auto& [rank, n] : lose_image) {
      const ExposureIndex image = st.exposure_order[rank];
      const Exposure& e = *st.exposures[image].exposure;
      const bool held = options_.use_eo_priors && e.center_sigma_m && e.opk_sigma_rad;
      if (!held && (*image_rays)[image] - n < 3)
        return "image " + e.image + " would keep " + std::to_string((*image_rays)[image] - n) +
               " point(s) and be under-determined";
    }
    for (const auto& [point, n] : lose_point) (*point_rays)[point] -= n;
    for (const auto& [rank, n] : lose_image) (*image_rays)[st.exposure_order[rank]] -= n;
    return std::string();
  };
}

void BlockAdjustment::SummariseSnooping(const calib::SnoopingOutcome& out, SnoopingSummary* s) {
  s->run = true;
  s->alpha = out.alpha;
  s->alpha0 = out.alpha0;
  s->critical_value = out.critical_value;
  s->power = out.power;
  s->delta0 = out.delta0;
  s->delta0_joint = out.delta0_joint;
  s->min_redundancy = out.min_redundancy;
  s->group_correlation = out.group_correlation;
  s->reference_sigma = out.reference_sigma;
  s->cofactor_method = out.cofactor_method;
  s->cofactors_ok = out.cofactors_ok;
  s->cofactor_message = out.cofactor_message;
  s->n_tested_components = out.n_tested_components;
  s->rounds = out.rounds;
  s->cap_reached = out.cap_reached;
  s->remaining_above_critical = out.remaining_above_critical;
  s->model_error_suspected = out.model_error_suspected;
  s->model_error_evidence = out.model_error_evidence;
  s->findings = out.findings;
  s->unresolved_reason = out.unresolved_reason;
  for (const auto& x : out.unresolved) {
    storage_->unresolved_ids.push_back(x.id);
    UnresolvedSurvey u;
    u.survey = x.label;
    u.w = x.w_full;
    u.redundancy = *std::min_element(x.redundancy.begin(), x.redundancy.end());
    for (double v : x.v) u.residual_sigma = std::max(u.residual_sigma, std::abs(v));
    s->unresolved_surveys.push_back(u);
  }
  s->seconds_testing = out.seconds_testing;
  if (out.model_error_suspected) s->suggestion = SelfCalibrationSuggestion();
}

std::string BlockAdjustment::SelfCalibrationSuggestion() const {
  int control = 0;
  for (const auto& state : storage_->points) control += state.block >= 0 && state.Control();
  if (!options_.free_interior.empty())
    return "the run already self-calibrates: check the camera model, the control survey and the "
           "a-priori sigmas";
  if (storage_->exposures.size() >= 3 && (control >= 3 || !storage_->free_network))
    return "self-calibration with --self-calibration auto (it frees only what this block "
           "determines and what is significant, and names what it holds) may absorb it: the "
           "block has " +
           std::to_string(storage_->exposures.size()) + " exposures and " +
           std::to_string(control) + " control point(s)";
  return "the block is too weak to self-calibrate: more control or GNSS is needed";
}

void BlockAdjustment::RecordTested(const calib::SnoopingOutcome& out, SnoopingSummary* s) {
  for (const auto& x : out.tested) {
    const auto it = storage_->observation_of_residual.find(x.id);
    const bool image = it != storage_->observation_of_residual.end();
    if (image) {
      const ObservationTest t = TestOf(x, storage_->observations[it->second].sigma_px);
      storage_->tests[x.id] = t;
      s->n_weakly_controlled += t.redundancy.minCoeff() < options_.min_redundancy;
      s->n_untestable += t.redundancy.minCoeff() < 1e-6;
      s->n_in_groups += t.group_size > 1;
    }
    if (x.verdict == calib::SnoopingVerdict::kAccepted) continue;
    FlaggedObservation f;
    f.what = image ? Describe(x.id) : x.label;
    f.verdict = calib::VerdictName(x.verdict);
    f.reason = x.reason;
    f.w = x.verdict == calib::SnoopingVerdict::kWeaklyControlled ? x.w_weak : x.w_max;
    if (x.component >= 0) {
      f.redundancy = x.redundancy[x.component];
      f.mdb_sigma = x.mdb_sigma[x.component];
    }
    f.group_size = x.group_size;
    s->flagged.push_back(f);
  }
}

void BlockAdjustment::RecordRejected(const calib::SnoopingOutcome& out, AdjustmentResult* result) {
  for (const auto& x : out.rejected) {
    const auto it = storage_->observation_of_residual.find(x.id);
    if (it == storage_->observation_of_residual.end()) continue;
    const auto& o = storage_->observations[it->second];
    RejectedObservation r;
    r.image = o.image;
    r.point = o.point;
    r.measured_px = o.pixel;
    storage_->sensor_of_observation[it->second]->Annotate(o, &r);
    r.w = x.w_max;
    if (x.v.size() == 2) r.residual_px = Eigen::Vector2d(x.v[0], x.v[1]) * o.sigma_px;
    r.test = TestOf(x, o.sigma_px);
    for (calib::ResidualId member : x.correlated) {
      const auto m = storage_->observation_of_residual.find(member);
      if (m != storage_->observation_of_residual.end())
        r.group.push_back(storage_->observations[m->second].image);
    }
    storage_->tests[x.id] = r.test;
    result->rejected.push_back(r);
  }
}

}  // namespace aerocal::triangulation
