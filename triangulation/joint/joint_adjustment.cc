#include "triangulation/joint/joint_adjustment.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/median.h"
#include "calib/core/string_printf.h"
#include "stitch/adjustment/frame_measurements.h"
#include "stitch/adjustment/mapping_param_names.h"
#include "stitch/adjustment/stitch_adjustment.h"
#include "stitch/simulation/stitch_simulator.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/calibration/control_cofactor.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {
using calib::MappingModel;

// Q N_control Q of the interior of `camera` in the solved `adjustment` (control_cofactor.h);
// empty when its covariance is not determinable.
Eigen::MatrixXd InteriorControlCofactor(const Project& project,
                                        const std::string& camera,
                                        const AdjustmentResult& result,
                                        BlockAdjustment& adjustment) {
  const calib::BlockId block = adjustment.InteriorBlock(camera);
  if (block < 0 || !result.solve.usable || result.solve.redundancy <= 0 ||
      !result.determinability.covariance_ok || !(result.sigma0 > 0))
    return {};
  const int size = project.cameras.at(camera).interior.size();
  const calib::CovarianceReport cov =
      adjustment.builder().EstimateCovariance({block}, result.sigma0);
  if (!cov.ok) return {};
  return ControlCofactor(adjustment, block, size, result.sigma0, cov.BlockCovariance(block, size));
}

// The camera whose sub-images the joint adjustment maps (the first with sub-images).
std::string SubimageCameraId(const Project& project) {
  for (const auto& [id, camera] : project.cameras)
    if (!camera.subimages.empty()) return id;
  return project.cameras.empty() ? std::string() : project.cameras.begin()->first;
}
}  // namespace

std::optional<calib::MappingModel> ParseJointModel(const std::string& text) {
  if (text == "auto") return std::nullopt;
  if (const auto model = calib::ParseMappingModel(text)) return model;
  throw ConfigError(
      "--joint-model must be translation, conformal, affine, projective or auto (got '" + text +
      "')");
}

void JointOptions::Validate(const Project& project) const {
  adjust.Validate();
  if (!(stitch_sigma_px > 0)) throw ConfigError("stitch sigma must be > 0 px");
  const bool any_subimage = std::any_of(
      project.observations.begin(), project.observations.end(), [](const ImageObservation& o) {
        return ObservationKind(o) == SensorKind::kSubimage;
      });
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
                      "camera " + id +
                          " has neither base sub-images (--base) nor reference points: "
                          "the focal plane has no datum");
  }
}

JointResult AdjustJoint(const Project& project, const JointOptions& options) {
  options.Validate(project);
  auto sensor = std::make_unique<SubimageCamera>(options);
  SubimageCamera& subimage = *sensor;
  std::vector<std::unique_ptr<ImagingModel>> sensors;
  sensors.push_back(std::move(sensor));
  BlockAdjustment adjustment(project, options.adjust, std::move(sensors));

  JointResult result;
  result.scope = options.scope;
  // (sigma0 in px and um comes over every image observation, virtual and raw.)
  result.adjustment = adjustment.Run();
  result.datum = options.base_ids.empty()
                     ? "reference points (maker-surveyed virtual positions) fix the focal plane"
                     : "base sub-images keep their camera-file mapping:";
  for (const auto& b : options.base_ids) result.datum += " " + b;
  result.mapping_model =
      options.model ? std::string(calib::MappingModelName(*options.model)) : "camera file";
  result.mapping_model_reason = !options.model_reason.empty() ? options.model_reason
                                : options.model               ? "given by the caller"
                                                : "each sub-image keeps its camera-file model";
  SubimageReport report =
      subimage.Report(adjustment.context(), result.adjustment.sigma0, &result.adjustment);
  result.mappings = std::move(report.mappings);
  result.stitching = std::move(report.stitching);
  result.mapping_interior_correlations = std::move(report.mapping_interior_correlations);
  result.mapping_covariance_ok = report.mapping_covariance_ok;
  // After the report: the control weights are stepped and restored (new residual ids).
  if (options.control_cofactor) {
    result.interior_camera = SubimageCameraId(project);
    result.interior_control_cofactor =
        InteriorControlCofactor(project, result.interior_camera, result.adjustment, adjustment);
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
                        {"param_names", stitch::MappingParamNames(m.model)},
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
    e["sigma0_before_px"] =
        std::isfinite(s.sigma0_before_px) ? nlohmann::json(s.sigma0_before_px) : nlohmann::json();
    e["sigma0_after_px"] =
        std::isfinite(s.sigma0_after_px) ? nlohmann::json(s.sigma0_after_px) : nlohmann::json();
    stitching.push_back(e);
  }
  j["stitching_per_exposure"] = stitching;
  nlohmann::json correlations = nlohmann::json::array();
  for (const auto& h : result.mapping_interior_correlations)
    correlations.push_back({{"a", h.a}, {"b", h.b}, {"correlation", h.correlation}});
  j["mapping_interior_correlations"] = correlations;
  if (result.interior_control_cofactor.size() > 0) {
    const auto& camera = result.adjustment.cameras;
    nlohmann::json names = nlohmann::json::array(), matrix = nlohmann::json::array();
    for (const auto& e : camera)
      if (e.id == result.interior_camera)
        for (const auto& info : calib::CameraModelParams(e.model))
          names.push_back(std::string(info.name));
    for (int i = 0; i < result.interior_control_cofactor.rows(); ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (int k = 0; k < result.interior_control_cofactor.cols(); ++k)
        row.push_back(result.interior_control_cofactor(i, k));
      matrix.push_back(row);
    }
    j["interior_control_cofactor"] = {
        {"camera", result.interior_camera}, {"names", names}, {"matrix", matrix}};
  }
  return j;
}

ExposureMeasurements ReadExposureMeasurements(const Project& project, double default_sigma_px) {
  if (project.stitching_file.empty())
    ThrowInputError({project.path, 0}, "the project names no stitching measurements (stitching:)");
  std::string camera_id;
  for (const auto& [id, camera] : project.cameras) {
    if (camera.subimages.empty()) continue;
    if (!camera_id.empty())
      throw ConfigError(project.path +
                        ": the flight's stitching is run for one camera with sub-images (found " +
                        camera_id + " and " + id + ")");
    camera_id = id;
  }
  if (camera_id.empty())
    ThrowInputError({project.path, 0}, "no camera of the project has sub-images to stitch");
  ExposureMeasurements out;
  out.camera = project.cameras.at(camera_id);
  for (const auto& row : stitch::ReadStitchObservations(project.stitching_file, default_sigma_px)) {
    const Exposure* e = project.FindExposure(row.frame);
    if (e && e->camera == camera_id)
      out.rows.push_back(row);  // the stitching of the block's exposures
  }
  out.frames = stitch::GroupByFrame(out.camera, out.rows, project.stitching_file);
  if (out.frames.empty())
    ThrowInputError({project.stitching_file, 0},
                    "no stitching measurements of the block's exposures");
  return out;
}

stitch::BatchResult StitchExposures(const Project& project,
                                    const stitch::BatchOptions& options,
                                    double default_sigma_px,
                                    Progress* progress) {
  const ExposureMeasurements m = ReadExposureMeasurements(project, default_sigma_px);
  return stitch::RunStitchBatch(m.camera, m.frames, options, progress);
}

calib::Camera JointMappingsFromStitching(const calib::Camera& camera,
                                         const stitch::BatchResult* batch,
                                         const stitch::BatchOptions& batch_options,
                                         std::optional<calib::MappingModel> forced,
                                         JointOptions* options) {
  options->model = forced;
  if (!batch || batch->frames.empty()) {
    options->model_reason =
        forced ? "given by the user; starting from the camera file's mappings"
               : "each sub-image keeps its camera-file model (no stitching measurements)";
    return camera;
  }
  const MappingModel model = forced ? *forced : stitch::FlightModel(*batch, batch_options);
  const std::string name(calib::MappingModelName(model));
  options->model = model;
  for (const stitch::FrameRun& run : batch->frames) {
    const stitch::FrameAdjustment* alone =
        run.adjustment.model == model ? &run.adjustment : nullptr;
    if (!alone && run.choice)
      for (const auto& c : run.choice->candidates)
        if (c.model == model && c.determinable) alone = &c.adjustment;
    if (alone && alone->converged)
      options->stitching_sigma0_before_px[alone->frame] = alone->sigma0_px;
  }
  std::string reason;
  if (forced) {
    reason = "given by the user";
  } else if (batch_options.model) {
    reason = "the model the stitching was run with";
  } else {
    const auto chosen =
        std::count_if(batch->frames.begin(), batch->frames.end(), [&](const stitch::FrameRun& run) {
          return run.adjustment.model == model;
        });
    reason = "chosen by the stitching F test (alpha " + FormatNumber(batch_options.alpha, 3) +
             ") in " + std::to_string(chosen) + " of " + std::to_string(batch->frames.size()) +
             " exposures";
  }
  if (auto mean = stitch::FlightMeanCamera(camera, *batch, model)) {
    options->model_reason =
        reason + "; starting from the stitching's flight-mean " + name + " mappings";
    return *mean;
  }
  options->model_reason =
      reason + "; starting from the camera file's mappings (the stitching did not adjust " + name +
      " in every exposure)";
  return camera;
}

calib::Camera JointUpdatedCamera(const calib::Camera& camera,
                                 const std::string& camera_id,
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
  std::string out = "joint mappings: " + result.mapping_model + ", " +
                    MappingScopeName(result.scope) + ", " + std::to_string(free) + " free (" +
                    result.mapping_model_reason + ")\n";
  out += "focal-plane datum: " + result.datum + "\n";
  std::vector<double> before, after;
  for (const auto& s : result.stitching) {
    if (std::isfinite(s.sigma0_before_px)) before.push_back(s.sigma0_before_px);
    if (std::isfinite(s.sigma0_after_px)) after.push_back(s.sigma0_after_px);
  }
  if (!result.stitching.empty())
    out += StringPrintf(
        "stitching sigma0 per exposure (median of %zu): before %.3f px, after %.3f px\n",
        result.stitching.size(),
        Median(before),
        Median(after));
  for (const auto& h : result.mapping_interior_correlations)
    out += StringPrintf(
        "mapping/interior correlation %.3f: %s ~ %s\n", h.correlation, h.a.c_str(), h.b.c_str());
  return out;
}

}  // namespace aerocal::triangulation
