#include "stitch/adjustment/stitch_adjustment.h"

#include "calib/core/error.h"
#include "calib/core/median.h"
#include "calib/core/numeric_jacobian.h"
#include "calib/problem/data_snooping.h"
#include "calib/residuals/stitching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

namespace aerocal::stitch {
namespace {

using calib::MappingModel;

constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();  // a sigma not computed

bool IsBase(const StitchOptions& options, const std::string& id) {
  return std::find(options.base_ids.begin(), options.base_ids.end(), id) != options.base_ids.end();
}

/// The model a sub-image is adjusted with: its own (file) model for a base, `model` otherwise.
MappingModel ModelOf(const calib::SubimageMapping& s, MappingModel model, bool base) {
  return base ? s.model : model;
}

/// Rays of a tie that are not excluded.
std::vector<TieRay> ActiveRays(const calib::Camera& camera,
                               const TieMeasurement& tie,
                               const std::set<ObservationKey>& excluded) {
  std::vector<TieRay> rays;
  for (const TieRay& ray : tie.rays)
    if (!excluded.count({tie.point, camera.subimages[ray.subimage].id})) rays.push_back(ray);
  return rays;
}

/// d(U, V)/d(conditioned params) at conditioned input uv (central differences; exact for the
/// linear models up to rounding).
Eigen::MatrixXd VirtualJacobian(MappingModel model,
                                const std::vector<double>& params,
                                const Eigen::Vector2d& uv_conditioned) {
  return NumericJacobian(
      [&](const std::vector<double>& p) {
        Eigen::Vector2d out;
        calib::VisitMappingModel(model, [&](auto m) {
          decltype(m)::Apply(p.data(), uv_conditioned.data(), out.data());
        });
        return out;
      },
      params);
}

}  // namespace

double CornerPrecision::sigma_px() const { return std::hypot(sigma_U_px, sigma_V_px); }

void StitchOptions::Validate(const calib::Camera& camera) const {
  for (const auto& id : base_ids)
    if (camera.SubimageIndex(id) < 0)
      throw ConfigError("--base: sub-image '" + id + "' is not in the camera");
  if (!(snooping_alpha > 0 && snooping_alpha < 1))
    throw ConfigError("snooping alpha must be in (0, 1) (got " + std::to_string(snooping_alpha) +
                      ")");
}

std::string FindUnderdetermined(const calib::Camera& camera,
                                const FrameMeasurements& frame,
                                MappingModel model,
                                const StitchOptions& options,
                                const std::set<ObservationKey>& excluded) {
  // One pass over the measurements: points per sub-image (equations), and what anchors each
  // sub-image to the datum (base, reference point) or ties it to its neighbours.
  const size_t n = camera.subimages.size();
  std::vector<int> points(n, 0);
  std::vector<bool> reached(n, false);  // becomes: connected to the datum
  std::vector<std::set<int>> neighbours(n);
  for (size_t k = 0; k < n; ++k) reached[k] = IsBase(options, camera.subimages[k].id);
  for (const auto& ref : frame.references)
    if (!excluded.count({ref.point, camera.subimages[ref.subimage].id})) {
      ++points[ref.subimage];
      reached[ref.subimage] = true;
    }
  for (const auto& tie : frame.ties) {
    const auto rays = ActiveRays(camera, tie, excluded);
    if (rays.size() < 2) continue;
    for (const TieRay& ray : rays) {
      ++points[ray.subimage];
      for (const TieRay& other : rays)
        if (other.subimage != ray.subimage) neighbours[ray.subimage].insert(other.subimage);
    }
  }
  const int needed = calib::MappingParamCount(model);
  for (size_t k = 0; k < n; ++k) {
    const auto& s = camera.subimages[k];
    if (IsBase(options, s.id) || 2 * points[k] >= needed) continue;
    return "frame " + frame.frame + ", sub-image " + s.id + ": " + std::to_string(points[k]) +
           " points give " + std::to_string(2 * points[k]) + " equations for the " +
           std::to_string(needed) + " " + std::string(calib::MappingModelName(model)) +
           " parameters";
  }
  // Enough equations are not enough: a free sub-image must reach the datum through tie points,
  // else its mapping floats (a rank defect of the normal equations the count cannot see).
  std::vector<int> queue;
  for (size_t k = 0; k < n; ++k)
    if (reached[k]) queue.push_back(static_cast<int>(k));
  while (!queue.empty()) {
    const int k = queue.back();
    queue.pop_back();
    for (int m : neighbours[k])
      if (!reached[m]) {
        reached[m] = true;
        queue.push_back(m);
      }
  }
  for (size_t k = 0; k < n; ++k)
    if (!reached[k])
      return "frame " + frame.frame + ", sub-image " + camera.subimages[k].id +
             ": no chain of tie points connects it to a base sub-image or a reference point, so "
             "its mapping has no datum (add ties in its overlaps, reference points, or --base)";
  return "";
}

namespace {

// The robust start of AdjustFrame: observations far outside a Cauchy-loss solution.
std::vector<RejectedObservation> RobustOutliers(const calib::Camera& camera,
                                                const FrameMeasurements& frame,
                                                MappingModel model,
                                                const StitchOptions& options,
                                                const std::set<ObservationKey>& excluded) {
  StitchOptions robust = options;
  robust.robust_start = false;
  robust.data_snooping = false;
  robust.loss.kind = calib::LossKind::kCauchy;
  robust.loss.scale = options.robust_scale_sigma;
  const FrameAdjustment start = AdjustFrame(camera, frame, model, robust, excluded);
  std::vector<double> abs_w;
  for (const auto& v : start.residuals)
    for (int k = 0; k < 2; ++k) abs_w.push_back(std::abs(v.v_px(k)) / v.sigma_px);
  std::vector<RejectedObservation> out;
  if (abs_w.empty()) return out;
  std::nth_element(abs_w.begin(), abs_w.begin() + abs_w.size() / 2, abs_w.end());
  // Only the obvious: the scale is never below the a-priori sigma, so a pessimistic sigma does
  // not turn the robust cut into a finer test than data snooping (which decides the rest).
  const double scale = std::max(1.0, 1.4826 * abs_w[abs_w.size() / 2]);
  for (const auto& v : start.residuals) {
    const double w = v.v_px.norm() / v.sigma_px / scale;
    if (!std::isfinite(w) || w > options.robust_reject_sigma)
      out.push_back({v.point, v.subimage, v.reference, w, v.v_px});
  }
  return out;
}

/// What the robust start leaves out before the adjustment proper.
struct RobustStart {
  std::set<ObservationKey> excluded;          // the caller's plus the robust start's
  std::vector<RejectedObservation> rejected;  // the robust start's gross errors
  std::string note;                           // why they were kept after all, if they were
};

RobustStart ApplyRobustStart(const calib::Camera& camera,
                             const FrameMeasurements& frame,
                             MappingModel model,
                             const StitchOptions& options,
                             const std::set<ObservationKey>& excluded_in) {
  RobustStart out{excluded_in, {}, ""};
  if (!(options.robust_start && options.data_snooping)) return out;
  out.rejected = RobustOutliers(camera, frame, model, options, out.excluded);
  std::set<ObservationKey> more = out.excluded;
  for (const auto& r : out.rejected) more.insert({r.point, r.subimage});
  if (!out.rejected.empty() && !FindUnderdetermined(camera, frame, model, options, more).empty()) {
    out.note = "frame " + frame.frame + ": the robust start found " +
               std::to_string(out.rejected.size()) +
               " gross error(s) but leaving them out would under-determine the " +
               std::string(calib::MappingModelName(model)) + " model: kept for data snooping";
    out.rejected.clear();
  } else {
    out.excluded = std::move(more);
  }
  return out;
}

/// Residual bookkeeping: what each residual observes.
struct Observed {
  std::string point;
  int subimage;
  bool reference;
  double sigma_px;
};

/// One frame's problem: a mapping block per sub-image and a 2D point per tie. The parameter
/// memory lives here; `builder` (declared last, destroyed first) points into it.
struct FrameProblem {
  std::vector<MappingModel> models;
  std::vector<calib::MappingConditioning> conditioning;
  std::vector<std::vector<double>> values;  // conditioned parameters, solver memory
  std::vector<bool> base;
  std::vector<calib::BlockId> blocks;
  std::vector<Eigen::Vector2d> tie_positions;
  std::map<calib::ResidualId, Observed> observed;
  int n_ties = 0;
  calib::ProblemBuilder builder;
};

void AddMappingBlocks(const calib::Camera& camera,
                      MappingModel model,
                      const StitchOptions& options,
                      FrameProblem& p) {
  const size_t n_sub = camera.subimages.size();
  p.models.resize(n_sub);
  p.conditioning.resize(n_sub);
  p.values.resize(n_sub);
  p.base.resize(n_sub);
  p.blocks.resize(n_sub);
  for (size_t k = 0; k < n_sub; ++k) {
    const auto& s = camera.subimages[k];
    p.base[k] = IsBase(options, s.id);
    p.models[k] = ModelOf(s, model, p.base[k]);
    p.conditioning[k] =
        calib::MappingConditioning::ForSubimage(p.models[k], s.width_px, s.height_px);
    // Start (and, for a base, hold) at the camera file's mapping expressed in the model.
    const std::vector<double> plain = calib::ParamsFromHomography(
        p.models[k], calib::HomographyFromParams(s.model, s.params.data()));
    p.values[k] = calib::ConditionedFromPlain(p.models[k], p.conditioning[k], plain);
    p.blocks[k] = p.builder.AddBlock("mapping " + s.id,
                                     p.values[k].data(),
                                     static_cast<int>(p.values[k].size()),
                                     calib::BlockKind::kMapping);
    if (p.base[k]) p.builder.FixBlock(p.blocks[k]);
  }
}

void AddReferences(const calib::Camera& camera,
                   const FrameMeasurements& frame,
                   const std::set<ObservationKey>& excluded,
                   FrameProblem& p) {
  for (const auto& ref : frame.references) {
    const auto& s = camera.subimages[ref.subimage];
    if (excluded.count({ref.point, s.id})) continue;
    const int k = ref.subimage;
    auto cost = calib::VisitMappingModel(p.models[k], [&](auto m) {
      return calib::StitchReferenceResidual<decltype(m)>::Create(
          p.conditioning[k], ref.uv, ref.virtual_px, ref.sigma_px);
    });
    const auto id = p.builder.AddResidual(
        calib::kGroupStitchReference,
        std::move(cost),
        {p.blocks[k]},
        "frame " + frame.frame + " reference " + ref.point + " sub-image " + s.id);
    p.observed[id] = {ref.point, k, true, ref.sigma_px};
  }
}

/// A 2D point per tie with two or more active rays, started at the mean of its rays' virtual
/// positions, and one residual per ray.
void AddTies(const calib::Camera& camera,
             const FrameMeasurements& frame,
             const std::set<ObservationKey>& excluded,
             const StitchOptions& options,
             FrameProblem& p) {
  p.tie_positions.reserve(frame.ties.size());  // block memory must not move
  for (const auto& tie : frame.ties) {
    const auto rays = ActiveRays(camera, tie, excluded);
    if (rays.size() < 2) continue;
    Eigen::Vector2d start = Eigen::Vector2d::Zero();
    for (const TieRay& ray : rays) start += camera.subimages[ray.subimage].VirtualFromSub(ray.uv);
    p.tie_positions.push_back(start / static_cast<double>(rays.size()));
    const auto point_block = p.builder.AddBlock("tie " + tie.point,
                                                p.tie_positions.back().data(),
                                                2,
                                                calib::BlockKind::kTiePoint2d,
                                                {"U", "V"});
    ++p.n_ties;
    for (const TieRay& ray : rays) {
      const int k = ray.subimage;
      auto cost = calib::VisitMappingModel(p.models[k], [&](auto m) {
        return calib::StitchTieResidual<decltype(m)>::Create(
            p.conditioning[k], ray.uv, ray.sigma_px);
      });
      const auto id = p.builder.AddResidual(
          calib::kGroupStitchTie,
          std::move(cost),
          {p.blocks[k], point_block},
          "frame " + frame.frame + " tie " + tie.point + " sub-image " + camera.subimages[k].id,
          options.loss);
      p.observed[id] = {tie.point, k, false, ray.sigma_px};
    }
  }
}

/// Solves, with data snooping when asked (its rejections appended to `rejected`).
calib::SolveReport SolveFrame(const calib::Camera& camera,
                              const StitchOptions& options,
                              FrameProblem& p,
                              std::vector<RejectedObservation>& rejected) {
  if (!options.data_snooping) return p.builder.Solve(options.solver);
  calib::SnoopingOptions snooping;
  snooping.groups = {calib::kGroupStitchReference, calib::kGroupStitchTie};
  snooping.critical_value =
      std::max(3.29,
               calib::NormalCriticalValue(options.snooping_alpha /
                                          std::max(1, p.builder.NumObservations())));
  snooping.max_rejections = 200;
  const calib::SnoopingOutcome snooped =
      calib::SolveWithDataSnooping(p.builder, options.solver, snooping);
  for (const auto& r : snooped.rejected) {
    const Observed& o = p.observed.at(r.id);
    rejected.push_back({o.point,
                        camera.subimages[o.subimage].id,
                        o.reference,
                        r.w_max,
                        Eigen::Vector2d(r.v[0], r.v[1]) * o.sigma_px});
  }
  return snooped.report;
}

void CopySolveStatistics(const calib::SolveReport& report, FrameAdjustment& out) {
  out.converged = report.converged;
  out.iterations = report.iterations;
  out.sigma0 = report.sigma0;
  out.vtpv = report.vtpv;
  out.redundancy = report.redundancy;
  out.n_observations = report.n_observations;
  out.n_unknowns = report.n_unknowns;
  out.diagnostics = report.diagnostics;
}

/// sigma0 in px: sigma0 times the median a-priori sigma of the observations still active.
double Sigma0Px(double sigma0, const FrameProblem& p) {
  std::vector<double> active_sigmas;
  for (const auto& [id, o] : p.observed)
    if (p.builder.IsActive(id)) active_sigmas.push_back(o.sigma_px);
  return sigma0 * Median(active_sigmas);
}

/// Residuals of the clean adjustment, in px: estimated minus observed.
std::vector<PointResidual> ActiveResiduals(const calib::Camera& camera, const FrameProblem& p) {
  std::vector<PointResidual> out;
  for (const auto& [id, o] : p.observed) {
    if (!p.builder.IsActive(id)) continue;
    const std::vector<double> r = p.builder.EvaluateResidual(id);
    out.push_back({o.point,
                   camera.subimages[o.subimage].id,
                   o.reference,
                   Eigen::Vector2d(r[0], r[1]) * o.sigma_px,
                   o.sigma_px});
  }
  return out;
}

/// Covariance of the free mappings (scaled by sigma0^2). A solution that overflowed (absurd
/// input that passed the readers' bounds) must not reach the covariance's SVD, which does not
/// survive non-finite or overflowing entries: a named failure (not converged, exit 3) instead.
calib::CovarianceReport FreeMappingCovariance(const std::string& frame_id,
                                              const calib::SolveReport& report,
                                              FrameProblem& p,
                                              FrameAdjustment& out) {
  std::vector<calib::BlockId> free_blocks;
  for (size_t k = 0; k < p.blocks.size(); ++k)
    if (!p.base[k]) free_blocks.push_back(p.blocks[k]);
  bool finite = std::isfinite(report.sigma0) && std::abs(report.sigma0) < 1e150;
  for (const auto& v : p.values)
    for (double x : v) finite = finite && std::isfinite(x) && std::abs(x) < 1e150;
  for (const auto& t : p.tie_positions)
    finite = finite && t.allFinite() && t.cwiseAbs().maxCoeff() < 1e150;
  calib::CovarianceReport covariance;
  if (finite) {
    covariance = p.builder.EstimateCovariance(free_blocks, std::max(report.sigma0, 0.0));
  } else {
    out.converged = false;
    covariance.ok = false;
    covariance.message = "frame " + frame_id +
                         ": numerical failure in the adjustment (non-finite or overflowing "
                         "values): no covariance, results not usable";
  }
  return covariance;
}

/// Sub-image k's estimate in plain form, its covariance propagated from the conditioned
/// parameters (C_plain = J C J^T) and to the four corners' virtual positions (G C G^T).
SubimageEstimate EstimateSubimage(const calib::SubimageMapping& s,
                                  size_t k,
                                  const FrameProblem& p,
                                  const calib::CovarianceReport& covariance) {
  const int n = static_cast<int>(p.values[k].size());
  const MappingModel model = p.models[k];
  const calib::MappingConditioning& conditioning = p.conditioning[k];
  SubimageEstimate e;
  e.id = s.id;
  e.model = model;
  e.base = p.base[k];
  e.params = calib::PlainFromConditioned(model, conditioning, p.values[k]);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  if (!p.base[k] && covariance.ok) c = covariance.BlockCovariance(p.blocks[k], n);
  const Eigen::MatrixXd j = calib::PlainFromConditionedJacobian(model, conditioning, p.values[k]);
  e.covariance = j * c * j.transpose();
  for (int i = 0; i < n; ++i) e.sigma.push_back(std::sqrt(std::max(0.0, e.covariance(i, i))));
  const double corner_u[4] = {0.0, s.width_px - 1.0, 0.0, s.width_px - 1.0};
  const double corner_v[4] = {0.0, 0.0, s.height_px - 1.0, s.height_px - 1.0};
  calib::SubimageMapping estimated = s;
  estimated.model = model;
  estimated.params = e.params;
  for (int i = 0; i < 4; ++i) {
    CornerPrecision& corner = e.corners[i];
    corner.uv = {corner_u[i], corner_v[i]};
    corner.virtual_px = estimated.VirtualFromSub(corner.uv);
    const Eigen::Vector2d uvc((corner_u[i] - conditioning.cu) / conditioning.scale,
                              (corner_v[i] - conditioning.cv) / conditioning.scale);
    const Eigen::MatrixXd g = VirtualJacobian(model, p.values[k], uvc);
    const Eigen::Matrix2d cov_uv = g * c * g.transpose();
    corner.sigma_U_px = std::sqrt(std::max(0.0, cov_uv(0, 0)));
    corner.sigma_V_px = std::sqrt(std::max(0.0, cov_uv(1, 1)));
    e.max_corner_sigma_px = std::max(e.max_corner_sigma_px, corner.sigma_px());
  }
  if (!p.base[k] && !covariance.ok) {
    // No precision could be computed: say so (null in JSON), never report zero sigmas.
    std::fill(e.sigma.begin(), e.sigma.end(), kUnknown);
    for (CornerPrecision& corner : e.corners) corner.sigma_U_px = corner.sigma_V_px = kUnknown;
    e.max_corner_sigma_px = kUnknown;
  }
  return e;
}

}  // namespace

FrameAdjustment AdjustFrame(const calib::Camera& camera,
                            const FrameMeasurements& frame,
                            MappingModel model,
                            const StitchOptions& options,
                            const std::set<ObservationKey>& excluded_in) {
  const std::string refusal = FindUnderdetermined(camera, frame, model, options, excluded_in);
  if (!refusal.empty()) throw InputError(refusal);
  RobustStart robust = ApplyRobustStart(camera, frame, model, options, excluded_in);

  FrameProblem p;
  AddMappingBlocks(camera, model, options, p);
  AddReferences(camera, frame, robust.excluded, p);
  AddTies(camera, frame, robust.excluded, options, p);

  FrameAdjustment out;
  out.frame = frame.frame;
  out.model = model;
  out.n_ties = p.n_ties;
  out.n_references = static_cast<int>(frame.references.size());
  out.n_single_ray_points = frame.single_ray_points;

  const calib::SolveReport report = SolveFrame(camera, options, p, out.rejected);
  // Gross errors of the robust start first (found before any model was compared).
  out.rejected.insert(out.rejected.begin(), robust.rejected.begin(), robust.rejected.end());
  CopySolveStatistics(report, out);
  if (!robust.note.empty()) out.diagnostics.push_back(robust.note);
  out.sigma0_px = Sigma0Px(out.sigma0, p);
  out.residuals = ActiveResiduals(camera, p);

  const calib::CovarianceReport covariance = FreeMappingCovariance(frame.frame, report, p, out);
  out.covariance_ok = covariance.ok;
  if (!covariance.ok) out.diagnostics.push_back(covariance.message);
  for (size_t k = 0; k < camera.subimages.size(); ++k) {
    SubimageEstimate e = EstimateSubimage(camera.subimages[k], k, p, covariance);
    out.max_corner_sigma_px = std::max(out.max_corner_sigma_px, e.max_corner_sigma_px);
    out.subimages.push_back(std::move(e));
  }
  if (!covariance.ok) out.max_corner_sigma_px = kUnknown;
  return out;
}

calib::Camera CameraWithEstimates(const calib::Camera& camera, const FrameAdjustment& adjustment) {
  calib::Camera out = camera;
  for (const auto& e : adjustment.subimages) {
    const int k = out.SubimageIndex(e.id);
    out.subimages[k].model = e.model;
    out.subimages[k].params = e.params;
  }
  return out;
}

}  // namespace aerocal::stitch
