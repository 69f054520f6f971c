#include "triangulation/joint/joint_adjustment.h"
#include "calib/core/median.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <set>

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/prior.h"
#include "calib/residuals/stitching.h"
#include "stitch/adjustment/frame_measurements.h"
#include "stitch/adjustment/stitch_adjustment.h"
#include "stitch/simulation/stitch_simulator.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/forward_intersection.h"

namespace aerocal::triangulation {
namespace {

using calib::BlockId;
using calib::MappingModel;
using calib::ResidualId;

struct MappingBlock {
  std::string camera, subimage, exposure;
  MappingModel model = MappingModel::kAffine;
  calib::MappingConditioning conditioning;
  std::vector<double> initial_plain;
  std::vector<double> values;  // conditioned, the block memory
  BlockId block = -1;
  bool base = false;
};

// Residuals of one exposure's stitching measurements, for its precision after the joint solution.
struct FrameStitchResiduals {
  std::vector<ResidualId> residuals;
  int ties = 0;
  std::vector<double> sigmas_px;
};

std::vector<std::string> MappingEntryNames(MappingModel model) {
  std::vector<std::string> names;
  for (int i = 0; i < calib::MappingParamCount(model); ++i) names.push_back("p" + std::to_string(i));
  return names;
}

// The mapping of `s` under `model`, plain form: exact towards a richer model; towards a simpler
// one the entries `model` has of the homography about the sub-image centre (the centre keeps its
// place).
std::vector<double> ConvertedParams(const calib::SubimageMapping& s, MappingModel model) {
  if (model == s.model) return s.params;
  Eigen::Matrix3d centre = Eigen::Matrix3d::Identity(), uncentre = Eigen::Matrix3d::Identity();
  centre(0, 2) = 0.5 * (s.width_px - 1);
  centre(1, 2) = 0.5 * (s.height_px - 1);
  uncentre.topRightCorner<2, 1>() = -centre.topRightCorner<2, 1>();
  const std::vector<double> about_centre =
      calib::ParamsFromHomography(model, calib::HomographyFromParams(s.model, s.params.data()) * centre);
  return calib::ParamsFromHomography(model, calib::HomographyFromParams(model, about_centre.data()) * uncentre);
}

}  // namespace

std::string MappingScopeName(MappingScope scope) {
  return scope == MappingScope::kPerFlight ? "per-flight" : "per-exposure";
}

MappingScope ParseMappingScope(const std::string& text) {
  if (text == "per-flight") return MappingScope::kPerFlight;
  if (text == "per-exposure") return MappingScope::kPerExposure;
  throw ConfigError("--joint-stitching must be per-flight or per-exposure (got '" + text + "')");
}

std::optional<calib::MappingModel> ParseJointModel(const std::string& text) {
  if (text == "auto") return std::nullopt;
  if (const auto model = calib::ParseMappingModel(text)) return model;
  throw ConfigError("--joint-model must be translation, conformal, affine, projective or auto (got '" + text +
                    "')");
}

void JointOptions::Validate(const Project& project) const {
  adjust.Validate();
  if (!(stitch_sigma_px > 0)) throw ConfigError("stitch sigma must be > 0 px");
  bool any_subimage = false;
  for (const auto& o : project.observations) any_subimage |= !o.subimage.empty();
  if (!any_subimage)
    throw ConfigError(project.observations_file +
                      ": the joint adjustment needs observations in raw sub-image pixels "
                      "(the 'subimage' form of observations.csv)");
  for (const auto& [id, camera] : project.cameras) {
    if (camera.subimages.empty()) continue;
    for (const auto& base : base_ids)
      if (camera.SubimageIndex(base) < 0)
        throw ConfigError("base sub-image '" + base + "' is not a sub-image of camera " + id);
    if (base_ids.empty() && camera.reference_points.empty())
      ThrowInputError({project.camera_files.at(id), 1},
                      "camera " + id + " has neither base sub-images (--base) nor reference points: "
                      "the focal plane has no datum");
  }
}

JointResult AdjustJoint(const Project& project, const JointOptions& options) {
  options.Validate(project);
  BlockAdjustment adjustment(project, options.adjust, SubimageObservations::kLeaveToCaller);
  calib::ProblemBuilder& builder = adjustment.builder();

  // Mapping blocks, created on first use.
  std::deque<MappingBlock> mappings;
  std::map<std::tuple<std::string, std::string, std::string>, MappingBlock*> mapping_index;
  auto mapping_for = [&](const std::string& camera_id, const std::string& subimage,
                         const std::string& image) -> MappingBlock& {
    const std::string exposure = options.scope == MappingScope::kPerExposure ? image : "";
    const auto key = std::make_tuple(camera_id, subimage, exposure);
    if (auto it = mapping_index.find(key); it != mapping_index.end()) return *it->second;
    const calib::Camera& camera = project.cameras.at(camera_id);
    const calib::SubimageMapping& s = camera.subimages[camera.SubimageIndex(subimage)];
    MappingBlock& m = mappings.emplace_back();
    m.camera = camera_id;
    m.subimage = subimage;
    m.exposure = exposure;
    m.base = std::find(options.base_ids.begin(), options.base_ids.end(), subimage) != options.base_ids.end();
    m.model = options.model && !m.base ? *options.model : s.model;
    m.conditioning = calib::MappingConditioning::ForSubimage(m.model, s.width_px, s.height_px);
    m.initial_plain = ConvertedParams(s, m.model);
    m.values = calib::ConditionedFromPlain(m.model, m.conditioning, m.initial_plain);
    m.block = builder.AddBlock("mapping " + camera_id + " " + subimage + (exposure.empty() ? "" : " " + exposure),
                               m.values.data(), static_cast<int>(m.values.size()),
                               calib::BlockKind::kMapping, MappingEntryNames(m.model));
    if (m.base) builder.FixBlock(m.block);
    mapping_index[key] = &m;
    return m;
  };

  // Starting coordinates of points seen only in sub-image observations: rays through the camera
  // file's mappings, intersected.
  double height_sum = 0.0;
  int height_n = 0;
  for (const auto& p : project.points)
    if (p.xyz_m && p.role != PointRole::kCheck) {  // never the check survey
      height_sum += p.xyz_m->z();
      ++height_n;
    }
  const double fallback_height = height_n > 0 ? height_sum / height_n : 0.0;
  std::map<std::string, std::vector<ImageRay>> rays;
  for (const auto& o : project.observations) {
    const Exposure& e = *project.FindExposure(o.image);
    const calib::Camera& camera = project.cameras.at(e.camera);
    const Eigen::Vector2d pixel =
        o.subimage.empty() ? o.pixel : camera.subimages[camera.SubimageIndex(o.subimage)].VirtualFromSub(o.pixel);
    rays[o.point].push_back(RayFromPixel(camera, e.opk_rad, e.center_m, pixel));
  }
  for (const auto& o : project.observations) {
    if (o.subimage.empty()) continue;
    const Exposure& e = *project.FindExposure(o.image);
    BlockId point = adjustment.PointBlock(o.point);
    if (point < 0) {
      const GroundPoint* ground = project.FindPoint(o.point);
      const auto& point_rays = rays[o.point];
      const bool control = ground && ground->role == PointRole::kControl;
      if (point_rays.size() < 2 && !control) continue;
      Eigen::Vector3d start;
      if (ground && ground->xyz_m && ground->role != PointRole::kCheck)
        start = *ground->xyz_m;
      else if (auto x = IntersectRays(point_rays))
        start = *x;
      else
        start = IntersectWithHeight(point_rays, fallback_height);
      point = adjustment.AddPoint(o.point, start);
      if (control) {
        const Eigen::Vector3d& xyz = *ground->xyz_m;
        const Eigen::Vector3d& s = ground->sigma_m;
        builder.AddResidual(calib::kGroupControl,
                            calib::PriorCostFunction::Create({xyz.x(), xyz.y(), xyz.z()}, {s.x(), s.y(), s.z()}),
                            {point}, "control " + o.point);
      }
    }
    const calib::Camera& camera = project.cameras.at(e.camera);
    MappingBlock& m = mapping_for(e.camera, o.subimage, o.image);
    const calib::PixelFrame frame{camera.pixel_size_mm, camera.width_px, camera.height_px};
    auto cost = calib::VisitMappingModel(m.model, [&](auto model) {
      return calib::SubimageCollinearityResidual<decltype(model)>::Create(frame, m.conditioning, o.pixel,
                                                                           o.sigma_px);
    });
    const ResidualId id = builder.AddResidual(
        calib::kGroupSubimage, std::move(cost),
        {m.block, adjustment.InteriorBlock(e.camera), adjustment.RotationBlock(o.image),
         adjustment.CenterBlock(o.image), point},
        "image " + o.image + " sub-image " + o.subimage + " point " + o.point);
    adjustment.RegisterCallerObservation(id, o);
  }

  // Per-exposure stitching measurements.
  JointResult result;
  result.scope = options.scope;
  std::map<std::string, FrameStitchResiduals> frame_residuals;
  std::deque<Eigen::Vector2d> tie_points;
  if (options.use_stitching && !project.stitching_file.empty()) {
    const auto rows = stitch::ReadStitchObservations(project.stitching_file, options.stitch_sigma_px);
    std::map<std::string, std::vector<stitch::StitchObservation>> rows_by_camera;
    for (const auto& row : rows) {
      const Exposure* e = project.FindExposure(row.frame);
      if (!e) continue;  // stitching of an exposure not in the block
      rows_by_camera[e->camera].push_back(row);
    }
    for (const auto& [camera_id, camera_rows] : rows_by_camera) {
      const calib::Camera& camera = project.cameras.at(camera_id);
      stitch::StitchOptions stitch_options;
      stitch_options.base_ids = options.base_ids;
      for (const auto& frame : stitch::GroupByFrame(camera, camera_rows, project.stitching_file)) {
        ExposureStitching stats;
        stats.image = frame.frame;
        // Before: the exposure's own stitching adjustment with the joint model (or the camera
        // file's richest), the caller's when it has it.
        if (const auto it = options.stitching_sigma0_before_px.find(frame.frame);
            it != options.stitching_sigma0_before_px.end()) {
          stats.sigma0_before_px = it->second;
        } else {
          try {
            MappingModel model = MappingModel::kTranslation;
            for (const auto& s : camera.subimages)
              if (static_cast<int>(s.model) > static_cast<int>(model)) model = s.model;
            if (options.model) model = *options.model;
            const auto alone = stitch::AdjustFrame(camera, frame, model, stitch_options);
            if (alone.converged) stats.sigma0_before_px = alone.sigma0_px;
          } catch (const Error&) {
            // under-determined alone: no "before" figure
          }
        }
        FrameStitchResiduals& fr = frame_residuals[frame.frame];
        for (const auto& ref : frame.references) {
          MappingBlock& m = mapping_for(camera_id, camera.subimages[ref.subimage].id, frame.frame);
          auto cost = calib::VisitMappingModel(m.model, [&](auto model) {
            return calib::StitchReferenceResidual<decltype(model)>::Create(m.conditioning, ref.uv, ref.virtual_px,
                                                                          ref.sigma_px);
          });
          fr.residuals.push_back(builder.AddResidual(calib::kGroupStitchReference, std::move(cost), {m.block},
                                                     "frame " + frame.frame + " reference " + ref.point));
          fr.sigmas_px.push_back(ref.sigma_px);
        }
        for (const auto& tie : frame.ties) {
          Eigen::Vector2d start = Eigen::Vector2d::Zero();
          for (const auto& ray : tie.rays) start += camera.subimages[ray.subimage].VirtualFromSub(ray.uv);
          Eigen::Vector2d& p = tie_points.emplace_back(start / static_cast<double>(tie.rays.size()));
          const BlockId pb = builder.AddBlock("stitch tie " + frame.frame + " " + tie.point, p.data(), 2,
                                              calib::BlockKind::kTiePoint2d, {"U", "V"});
          ++fr.ties;
          for (const auto& ray : tie.rays) {
            MappingBlock& m = mapping_for(camera_id, camera.subimages[ray.subimage].id, frame.frame);
            auto cost = calib::VisitMappingModel(m.model, [&](auto model) {
              return calib::StitchTieResidual<decltype(model)>::Create(m.conditioning, ray.uv, ray.sigma_px);
            });
            fr.residuals.push_back(builder.AddResidual(calib::kGroupStitchTie, std::move(cost), {m.block, pb},
                                                       "frame " + frame.frame + " tie " + tie.point + " sub-image " +
                                                           camera.subimages[ray.subimage].id));
            fr.sigmas_px.push_back(ray.sigma_px);
          }
        }
        result.stitching.push_back(stats);
      }
    }
  }

  // (sigma0 in px and um comes over every image observation, virtual and raw: the raw ones are
  // registered with the adjustment.)
  result.adjustment = adjustment.Run();
  const double sigma0 = result.adjustment.sigma0;
  result.datum = options.base_ids.empty()
                     ? "reference points (maker-surveyed virtual positions) fix the focal plane"
                     : "base sub-images keep their camera-file mapping:";
  for (const auto& b : options.base_ids) result.datum += " " + b;
  result.mapping_model = options.model ? std::string(calib::MappingModelName(*options.model)) : "camera file";
  result.mapping_model_reason =
      !options.model_reason.empty() ? options.model_reason
      : options.model               ? "given by the caller"
                                    : "each sub-image keeps its camera-file model";

  // Mapping estimates with sigmas (plain form) and their correlations with the interior.
  std::vector<BlockId> blocks;
  for (const auto& m : mappings) blocks.push_back(m.block);
  std::vector<std::string> interior_names;
  for (const auto& [id, camera] : project.cameras) {
    (void)camera;
    blocks.push_back(adjustment.InteriorBlock(id));
  }
  const calib::CovarianceReport covariance =
      builder.EstimateCovariance(blocks, sigma0, options.adjust.correlation_threshold);
  result.mapping_covariance_ok = covariance.ok;
  std::map<BlockId, calib::SubimageMapping> refined;  // per mapping block, plain form
  for (const auto& m : mappings) {
    MappingEstimate estimate;
    estimate.camera = m.camera;
    estimate.subimage = m.subimage;
    estimate.exposure = m.exposure;
    estimate.model = m.model;
    estimate.base = m.base;
    estimate.initial = m.initial_plain;
    estimate.params = calib::PlainFromConditioned(m.model, m.conditioning, m.values);
    estimate.sigma.assign(m.values.size(), 0.0);
    if (covariance.ok && !m.base) {
      const int n = static_cast<int>(m.values.size());
      const Eigen::MatrixXd j = calib::PlainFromConditionedJacobian(m.model, m.conditioning, m.values);
      const Eigen::MatrixXd c = j * covariance.BlockCovariance(m.block, n) * j.transpose();
      for (int i = 0; i < n; ++i) estimate.sigma[i] = std::sqrt(std::max(0.0, c(i, i)));
    }
    refined[m.block].model = m.model;
    refined[m.block].params = estimate.params;
    result.mappings.push_back(estimate);
  }
  // Residuals of raw sub-image observations, placed in the virtual image by the refined mapping
  // (every such observation created its mapping block above).
  for (auto& v : result.adjustment.residuals) {
    if (v.subimage.empty()) continue;
    const MappingBlock& m = mapping_for(project.FindExposure(v.image)->camera, v.subimage, v.image);
    v.measured_px = refined.at(m.block).VirtualFromSub(v.subimage_px);
  }
  for (const auto& h : covariance.high_correlations) {
    const bool a_mapping = h.a.rfind("mapping ", 0) == 0, b_mapping = h.b.rfind("mapping ", 0) == 0;
    if (a_mapping != b_mapping) result.mapping_interior_correlations.push_back(h);
  }

  // Stitching precision after: each exposure's stitching residuals in the joint solution.
  int free_mapping_params = 0;
  for (const auto& m : mappings)
    if (!m.base && m.exposure.empty()) free_mapping_params += static_cast<int>(m.values.size());
  const double shared_per_frame =
      frame_residuals.empty() ? 0.0 : static_cast<double>(free_mapping_params) / frame_residuals.size();
  for (auto& stats : result.stitching) {
    const FrameStitchResiduals& fr = frame_residuals[stats.image];
    double vtpv = 0.0;
    int n = 0;
    for (ResidualId id : fr.residuals) {
      if (!builder.IsActive(id)) continue;
      for (double v : builder.EvaluateResidual(id)) {
        vtpv += v * v;
        ++n;
      }
    }
    double unknowns = 2.0 * fr.ties + shared_per_frame;
    if (options.scope == MappingScope::kPerExposure)
      for (const auto& m : mappings)
        if (!m.base && m.exposure == stats.image) unknowns += static_cast<double>(m.values.size());
    stats.n_observations = n;
    if (n > unknowns) stats.sigma0_after_px = std::sqrt(vtpv / (n - unknowns)) * Median(fr.sigmas_px);
  }
  return result;
}

nlohmann::json JointResultToJson(const JointResult& result) {
  nlohmann::json j = AdjustmentToJson(result.adjustment);
  j["mapping_scope"] = MappingScopeName(result.scope);
  j["mapping_model"] = result.mapping_model;
  j["mapping_model_reason"] = result.mapping_model_reason;
  j["datum"] = result.datum;
  j["mapping_covariance_ok"] = result.mapping_covariance_ok;
  nlohmann::json subimages = nlohmann::json::array();
  for (const auto& m : result.mappings) {
    nlohmann::json s = {{"id", m.subimage},
                        {"camera", m.camera},
                        {"model", std::string(calib::MappingModelName(m.model))},
                        {"params", m.params},
                        {"sigma", m.sigma},
                        {"initial", m.initial},
                        {"base", m.base}};
    if (!m.exposure.empty()) s["exposure"] = m.exposure;
    subimages.push_back(s);
  }
  j["subimages"] = subimages;
  nlohmann::json stitching = nlohmann::json::array();
  for (const auto& s : result.stitching) {
    nlohmann::json e = {{"image", s.image}, {"n_observations", s.n_observations}};
    e["sigma0_before_px"] = std::isfinite(s.sigma0_before_px) ? nlohmann::json(s.sigma0_before_px) : nlohmann::json();
    e["sigma0_after_px"] = std::isfinite(s.sigma0_after_px) ? nlohmann::json(s.sigma0_after_px) : nlohmann::json();
    stitching.push_back(e);
  }
  j["stitching_per_exposure"] = stitching;
  nlohmann::json correlations = nlohmann::json::array();
  for (const auto& h : result.mapping_interior_correlations)
    correlations.push_back({{"a", h.a}, {"b", h.b}, {"correlation", h.correlation}});
  j["mapping_interior_correlations"] = correlations;
  return j;
}

stitch::BatchResult StitchExposures(const Project& project, const stitch::BatchOptions& options,
                                    double default_sigma_px, Progress* progress) {
  if (project.stitching_file.empty())
    ThrowInputError({project.path, 0}, "the project names no stitching measurements (stitching:)");
  std::string camera_id;
  for (const auto& [id, camera] : project.cameras) {
    if (camera.subimages.empty()) continue;
    if (!camera_id.empty())
      throw ConfigError(project.path + ": the flight's stitching is run for one camera with sub-images (found " +
                        camera_id + " and " + id + ")");
    camera_id = id;
  }
  if (camera_id.empty()) ThrowInputError({project.path, 0}, "no camera of the project has sub-images to stitch");
  const calib::Camera& camera = project.cameras.at(camera_id);
  std::vector<stitch::StitchObservation> rows;
  for (const auto& row : stitch::ReadStitchObservations(project.stitching_file, default_sigma_px)) {
    const Exposure* e = project.FindExposure(row.frame);
    if (e && e->camera == camera_id) rows.push_back(row);  // the stitching of the block's exposures
  }
  const auto frames = stitch::GroupByFrame(camera, rows, project.stitching_file);
  if (frames.empty())
    ThrowInputError({project.stitching_file, 0}, "no stitching measurements of the block's exposures");
  return stitch::RunStitchBatch(camera, frames, options, progress);
}

calib::Camera JointMappingsFromStitching(const calib::Camera& camera, const stitch::BatchResult* batch,
                                         const stitch::BatchOptions& batch_options,
                                         std::optional<calib::MappingModel> forced, JointOptions* options) {
  options->model = forced;
  if (!batch || batch->frames.empty()) {
    options->model_reason = forced ? "given by the user; starting from the camera file's mappings"
                                   : "each sub-image keeps its camera-file model (no stitching measurements)";
    return camera;
  }
  const MappingModel model = forced ? *forced : stitch::FlightModel(*batch, batch_options);
  const std::string name(calib::MappingModelName(model));
  options->model = model;
  for (const stitch::FrameRun& run : batch->frames) {
    const stitch::FrameAdjustment* alone = run.adjustment.model == model ? &run.adjustment : nullptr;
    if (!alone && run.choice)
      for (const auto& c : run.choice->candidates)
        if (c.model == model && c.determinable) alone = &c.adjustment;
    if (alone && alone->converged) options->stitching_sigma0_before_px[alone->frame] = alone->sigma0_px;
  }
  std::string reason;
  if (forced) {
    reason = "given by the user";
  } else if (batch_options.model) {
    reason = "the model the stitching was run with";
  } else {
    const auto chosen = std::count_if(batch->frames.begin(), batch->frames.end(),
                                      [&](const stitch::FrameRun& run) { return run.adjustment.model == model; });
    reason = "chosen by the stitching F test (alpha " + FormatNumber(batch_options.alpha, 3) + ") in " +
             std::to_string(chosen) + " of " + std::to_string(batch->frames.size()) + " exposures";
  }
  if (auto mean = stitch::FlightMeanCamera(camera, *batch, model)) {
    options->model_reason = reason + "; starting from the stitching's flight-mean " + name + " mappings";
    return *mean;
  }
  options->model_reason = reason + "; starting from the camera file's mappings (the stitching did not adjust " +
                          name + " in every exposure)";
  return camera;
}

calib::Camera JointUpdatedCamera(const calib::Camera& camera, const std::string& camera_id,
                                 const JointResult& result) {
  calib::Camera out = camera;
  for (const auto& estimate : result.adjustment.cameras)
    if (estimate.id == camera_id) out = UpdatedCamera(camera, estimate);
  for (const auto& m : result.mappings) {
    if (m.camera != camera_id || !m.exposure.empty()) continue;
    const int k = out.SubimageIndex(m.subimage);
    if (k < 0) continue;
    out.subimages[k].model = m.model;
    out.subimages[k].params = m.params;
  }
  return out;
}

std::string FormatJointSummary(const JointResult& result) {
  int free = 0;
  for (const auto& m : result.mappings) free += m.base ? 0 : 1;
  std::string out = "joint mappings: " + result.mapping_model + ", " + MappingScopeName(result.scope) + ", " +
                    std::to_string(free) + " free (" + result.mapping_model_reason + ")\n";
  out += "focal-plane datum: " + result.datum + "\n";
  std::vector<double> before, after;
  for (const auto& s : result.stitching) {
    if (std::isfinite(s.sigma0_before_px)) before.push_back(s.sigma0_before_px);
    if (std::isfinite(s.sigma0_after_px)) after.push_back(s.sigma0_after_px);
  }
  if (!result.stitching.empty())
    out += StringPrintf("stitching sigma0 per exposure (median of %zu): before %.3f px, after %.3f px\n",
                        result.stitching.size(), Median(before), Median(after));
  for (const auto& h : result.mapping_interior_correlations)
    out += StringPrintf("mapping/interior correlation %.3f: %s ~ %s\n", h.correlation, h.a.c_str(), h.b.c_str());
  return out;
}

}  // namespace aerocal::triangulation
