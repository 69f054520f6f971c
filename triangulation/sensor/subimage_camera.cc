#include "triangulation/sensor/subimage_camera.h"

#include "calib/core/error.h"
#include "calib/core/median.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/stitching.h"
#include "stitch/adjustment/stitch_adjustment.h"
#include "triangulation/sensor/frame_camera.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace aerocal::triangulation {
namespace {

using calib::BlockId;
using calib::MappingModel;
using calib::ResidualId;

std::vector<std::string> MappingEntryNames(MappingModel model) {
  std::vector<std::string> names;
  for (int i = 0; i < calib::MappingParamCount(model); ++i)
    names.push_back("p" + std::to_string(i));
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
  const std::vector<double> about_centre = calib::ParamsFromHomography(
      model, calib::HomographyFromParams(s.model, s.params.data()) * centre);
  return calib::ParamsFromHomography(
      model, calib::HomographyFromParams(model, about_centre.data()) * uncentre);
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

std::string SubimageCamera::Describe(const ImageObservation& observation) const {
  return "image " + observation.image + " sub-image " + observation.subimage + " point " +
         observation.point;
}

void SubimageCamera::Annotate(const ImageObservation& observation,
                              ObservationResidual* residual) const {
  residual->subimage = observation.subimage;
  residual->subimage_px = observation.pixel;
}

void SubimageCamera::Annotate(const ImageObservation& observation,
                              RejectedObservation* rejected) const {
  rejected->subimage = observation.subimage;
}

SubimageCamera::Key SubimageCamera::KeyOf(const SensorContext& context,
                                          const std::string& image,
                                          const std::string& subimage) const {
  const ExposureIndex exposure = context.index.Exposure(image);
  const CameraIndex camera = context.index.CameraOfExposure(exposure);
  const calib::Camera& c = context.project.cameras.at(context.index.CameraId(camera));
  return {camera,
          c.SubimageIndex(subimage),
          options_.scope == MappingScope::kPerExposure ? exposure : -1};
}

SubimageCamera::Mapping& SubimageCamera::MappingOf(const SensorContext& context,
                                                   const std::string& image,
                                                   const std::string& subimage) {
  const auto it = mapping_index_.find(KeyOf(context, image, subimage));
  AEROCAL_CHECK(it != mapping_index_.end())
      << "no mapping block for image " << image << " sub-image " << subimage;
  return mappings_[it->second];
}

void SubimageCamera::RegisterBlocks(const SensorContext& context) {
  const Project& project = context.project;
  // Which mappings are used, in order of first use: the observations, then the stitching.
  std::vector<std::pair<std::string, std::string>> uses;  // (image, sub-image)
  for (const auto& o : project.observations)
    if (ObservationKind(o) == Kind()) uses.emplace_back(o.image, o.subimage);
  if (options_.use_stitching && !project.stitching_file.empty()) {
    const auto rows =
        stitch::ReadStitchObservations(project.stitching_file, options_.stitch_sigma_px);
    std::map<std::string, std::vector<stitch::StitchObservation>> rows_by_camera;
    for (const auto& row : rows) {
      const Exposure* e = project.FindExposure(row.frame);
      if (!e) continue;  // stitching of an exposure not in the block
      rows_by_camera[e->camera].push_back(row);
    }
    for (const auto& [camera_id, camera_rows] : rows_by_camera) {
      const calib::Camera& camera = project.cameras.at(camera_id);
      frames_by_camera_[camera_id] =
          stitch::GroupByFrame(camera, camera_rows, project.stitching_file);
      for (const auto& frame : frames_by_camera_[camera_id]) {
        for (const auto& ref : frame.references)
          uses.emplace_back(frame.frame, camera.subimages[ref.subimage].id);
        for (const auto& tie : frame.ties)
          for (const auto& ray : tie.rays)
            uses.emplace_back(frame.frame, camera.subimages[ray.subimage].id);
      }
    }
  }
  std::vector<Key> keys;
  for (const auto& [image, subimage] : uses) {
    const Key key = KeyOf(context, image, subimage);
    if (mapping_index_.emplace(key, static_cast<int>(keys.size())).second) keys.push_back(key);
  }
  mappings_.resize(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) {
    const auto& [camera_index, subimage_index, exposure_index] = keys[i];
    const std::string& camera_id = context.index.CameraId(camera_index);
    const calib::SubimageMapping& s = project.cameras.at(camera_id).subimages[subimage_index];
    Mapping& m = mappings_[i];
    m.camera = camera_id;
    m.subimage = s.id;
    m.exposure = exposure_index < 0 ? "" : project.exposures[exposure_index].image;
    m.base = std::find(options_.base_ids.begin(), options_.base_ids.end(), s.id) !=
             options_.base_ids.end();
    m.model = options_.model && !m.base ? *options_.model : s.model;
    m.conditioning = calib::MappingConditioning::ForSubimage(m.model, s.width_px, s.height_px);
    m.initial_plain = ConvertedParams(s, m.model);
    m.values = calib::ConditionedFromPlain(m.model, m.conditioning, m.initial_plain);
    m.block = context.builder.AddBlock(
        "mapping " + camera_id + " " + s.id + (m.exposure.empty() ? "" : " " + m.exposure),
        m.values.data(),
        static_cast<int>(m.values.size()),
        calib::BlockKind::kMapping,
        MappingEntryNames(m.model));
    if (m.base) context.builder.FixBlock(m.block);
  }
}

ImageRay SubimageCamera::StartingRay(const SensorContext& context,
                                     const ImageObservation& observation) const {
  const ObservationSite site = context.Site(observation);
  const calib::SubimageMapping& s =
      site.camera->subimages[site.camera->SubimageIndex(observation.subimage)];
  return RayFromPixel(*site.camera,
                      site.exposure->opk_rad,
                      site.exposure->center_m,
                      s.VirtualFromSub(observation.pixel));
}

ObservationTerm SubimageCamera::Observe(const SensorContext& context,
                                        const ImageObservation& observation,
                                        calib::BlockId point) {
  const ObservationSite site = context.Site(observation);
  Mapping& m = MappingOf(context, observation.image, observation.subimage);
  m.used = true;
  ObservationTerm term;
  term.group = calib::kGroupSubimage;
  term.cost = calib::MakeSubimageCollinearityResidual(site.camera->model,
                                                      m.model,
                                                      site.camera->frame(),
                                                      m.conditioning,
                                                      observation.pixel,
                                                      observation.sigma_px);
  term.blocks = {m.block,
                 context.frame.InteriorBlock(site.camera_index),
                 site.pose.rotation,
                 site.pose.center,
                 point};
  return term;
}

void SubimageCamera::AddOwnResiduals(const SensorContext& context) {
  calib::ProblemBuilder& builder = context.builder;
  for (const auto& [camera_id, frames] : frames_by_camera_) {
    const calib::Camera& camera = context.project.cameras.at(camera_id);
    stitch::StitchOptions stitch_options;
    stitch_options.base_ids = options_.base_ids;
    for (const auto& frame : frames) {
      ExposureStitching stats;
      stats.image = frame.frame;
      // Before: the exposure's own stitching adjustment with the joint model (or the camera
      // file's richest), the caller's when it has it.
      if (const auto it = options_.stitching_sigma0_before_px.find(frame.frame);
          it != options_.stitching_sigma0_before_px.end()) {
        stats.sigma0_before_px = it->second;
      } else {
        try {
          MappingModel model = MappingModel::kTranslation;
          for (const auto& s : camera.subimages)
            if (static_cast<int>(s.model) > static_cast<int>(model)) model = s.model;
          if (options_.model) model = *options_.model;
          const auto alone = stitch::AdjustFrame(camera, frame, model, stitch_options);
          if (alone.converged) stats.sigma0_before_px = alone.sigma0_px;
        } catch (const Error&) {
          // under-determined alone: no "before" figure
        }
      }
      FrameResiduals& fr = frame_residuals_[frame.frame];
      for (const auto& ref : frame.references) {
        Mapping& m = MappingOf(context, frame.frame, camera.subimages[ref.subimage].id);
        m.used = true;
        auto cost = calib::VisitMappingModel(m.model, [&](auto model) {
          return calib::StitchReferenceResidual<decltype(model)>::Create(
              m.conditioning, ref.uv, ref.virtual_px, ref.sigma_px);
        });
        fr.residuals.push_back(
            builder.AddResidual(calib::kGroupStitchReference,
                                std::move(cost),
                                {m.block},
                                "frame " + frame.frame + " reference " + ref.point));
        fr.sigmas_px.push_back(ref.sigma_px);
      }
      for (const auto& tie : frame.ties) {
        Eigen::Vector2d start = Eigen::Vector2d::Zero();
        for (const auto& ray : tie.rays)
          start += camera.subimages[ray.subimage].VirtualFromSub(ray.uv);
        Eigen::Vector2d& p = tie_points_.emplace_back(start / static_cast<double>(tie.rays.size()));
        const BlockId pb = builder.AddBlock("stitch tie " + frame.frame + " " + tie.point,
                                            p.data(),
                                            2,
                                            calib::BlockKind::kTiePoint2d,
                                            {"U", "V"});
        ++fr.ties;
        for (const auto& ray : tie.rays) {
          Mapping& m = MappingOf(context, frame.frame, camera.subimages[ray.subimage].id);
          m.used = true;
          auto cost = calib::VisitMappingModel(m.model, [&](auto model) {
            return calib::StitchTieResidual<decltype(model)>::Create(
                m.conditioning, ray.uv, ray.sigma_px);
          });
          fr.residuals.push_back(builder.AddResidual(calib::kGroupStitchTie,
                                                     std::move(cost),
                                                     {m.block, pb},
                                                     "frame " + frame.frame + " tie " + tie.point +
                                                         " sub-image " +
                                                         camera.subimages[ray.subimage].id));
          fr.sigmas_px.push_back(ray.sigma_px);
        }
      }
      stitching_.push_back(stats);
    }
  }
}

SubimageReport SubimageCamera::Report(const SensorContext& context,
                                      double sigma0,
                                      AdjustmentResult* adjustment) const {
  const calib::ProblemBuilder& builder = context.builder;
  SubimageReport report;
  report.stitching = stitching_;
  // Mapping estimates with sigmas (plain form) and their correlations with the interior.
  std::vector<BlockId> blocks;
  for (const auto& m : mappings_)
    if (m.used) blocks.push_back(m.block);
  for (CameraIndex k = 0; k < context.index.NumCameras(); ++k)
    blocks.push_back(context.frame.InteriorBlock(k));
  const calib::CovarianceReport covariance =
      builder.EstimateCovariance(blocks, sigma0, context.options.correlation_threshold);
  report.mapping_covariance_ok = covariance.ok;
  std::map<BlockId, calib::SubimageMapping> refined;  // per mapping block, plain form
  for (const auto& m : mappings_) {
    if (!m.used) continue;
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
      const Eigen::MatrixXd j =
          calib::PlainFromConditionedJacobian(m.model, m.conditioning, m.values);
      const Eigen::MatrixXd c = j * covariance.BlockCovariance(m.block, n) * j.transpose();
      for (int i = 0; i < n; ++i) estimate.sigma[i] = std::sqrt(std::max(0.0, c(i, i)));
    }
    refined[m.block].model = m.model;
    refined[m.block].params = estimate.params;
    report.mappings.push_back(estimate);
  }
  // Residuals of raw sub-image observations, placed in the virtual image by the refined mapping.
  for (auto& v : adjustment->residuals) {
    if (v.subimage.empty()) continue;
    const auto it = mapping_index_.find(KeyOf(context, v.image, v.subimage));
    if (it == mapping_index_.end() || !refined.count(mappings_[it->second].block)) continue;
    v.measured_px = refined.at(mappings_[it->second].block).VirtualFromSub(v.subimage_px);
  }
  for (const auto& h : covariance.high_correlations) {
    const bool a_mapping = h.a.rfind("mapping ", 0) == 0, b_mapping = h.b.rfind("mapping ", 0) == 0;
    if (a_mapping != b_mapping) report.mapping_interior_correlations.push_back(h);
  }

  // Stitching precision after: each exposure's stitching residuals in the joint solution.
  int free_mapping_params = 0;
  for (const auto& m : mappings_)
    if (m.used && !m.base && m.exposure.empty())
      free_mapping_params += static_cast<int>(m.values.size());
  const double shared_per_frame =
      frame_residuals_.empty() ? 0.0
                               : static_cast<double>(free_mapping_params) / frame_residuals_.size();
  for (auto& stats : report.stitching) {
    const FrameResiduals& fr = frame_residuals_.at(stats.image);
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
    if (options_.scope == MappingScope::kPerExposure)
      for (const auto& m : mappings_)
        if (m.used && !m.base && m.exposure == stats.image)
          unknowns += static_cast<double>(m.values.size());
    stats.n_observations = n;
    if (n > unknowns)
      stats.sigma0_after_px = std::sqrt(vtpv / (n - unknowns)) * Median(fr.sigmas_px);
  }
  return report;
}

}  // namespace aerocal::triangulation
