#include "stitch/io/stitch_result_json.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/result_file.h"
#include "stitch/adjustment/mapping_param_names.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>

namespace aerocal::stitch {
namespace {

using nlohmann::json;

std::string ModelName(calib::MappingModel model) {
  return std::string(calib::MappingModelName(model));
}

json SubimageToJson(const SubimageEstimate& e) {
  json corners = json::array();
  for (const CornerPrecision& c : e.corners)
    corners.push_back({{"u", c.uv.x()},
                       {"v", c.uv.y()},
                       {"U", c.virtual_px.x()},
                       {"V", c.virtual_px.y()},
                       {"sigma_U_px", c.sigma_U_px},
                       {"sigma_V_px", c.sigma_V_px},
                       {"sigma_px", c.sigma_px()}});
  return {{"id", e.id},
          {"model", ModelName(e.model)},
          {"base", e.base},
          {"param_names", MappingParamNames(e.model)},
          {"params", e.params},
          {"sigma", e.sigma},
          {"corners", corners},
          {"max_corner_sigma_px", e.max_corner_sigma_px}};
}

json CandidateToJson(const ModelCandidate& c) {
  json j = {{"model", ModelName(c.model)}, {"determinable", c.determinable}};
  if (!c.determinable) {
    j["refusal"] = c.refusal;
    return j;
  }
  j["sigma0"] = c.adjustment.sigma0;
  j["sigma0_px"] = c.adjustment.sigma0_px;
  j["redundancy"] = c.adjustment.redundancy;
  j["vtpv"] = c.adjustment.vtpv;
  j["max_corner_sigma_px"] = c.adjustment.max_corner_sigma_px;
  if (c.tested)
    j["test"] = {{"against", c.against},
                 {"F", c.f},
                 {"F_critical", c.f_critical},
                 {"p_value", c.p_value},
                 {"df1", c.df1},
                 {"df2", c.df2},
                 {"significant", c.significant}};
  return j;
}

json StabilityToJson(const ModelStability& s) {
  json parameters = json::array();
  for (const auto& p : s.parameters)
    parameters.push_back({{"subimage", p.subimage},
                          {"name", p.name},
                          {"mean", p.mean},
                          {"std", p.std},
                          {"mean_sigma", p.mean_sigma}});
  json flagged = json::array();
  for (const auto& f : s.flagged) flagged.push_back({{"frame", f.frame}, {"reasons", f.reasons}});
  return {{"model", ModelName(s.model)},
          {"n_frames", s.n_frames},
          {"mean_sigma0", s.mean_sigma0},
          {"std_sigma0", s.std_sigma0},
          {"mean_sigma0_px", s.mean_sigma0_px},
          {"std_sigma0_px", s.std_sigma0_px},
          {"parameters", parameters},
          {"flagged", flagged}};
}

}  // namespace

json FrameResultToJson(const FrameAdjustment& a, const ModelChoice* choice) {
  json subimages = json::array();
  for (const auto& e : a.subimages) subimages.push_back(SubimageToJson(e));
  json residuals = json::array();
  for (const auto& r : a.residuals)
    residuals.push_back({{"point", r.point},
                         {"subimage", r.subimage},
                         {"kind", r.reference ? "reference" : "tie"},
                         {"vU_px", r.v_px.x()},
                         {"vV_px", r.v_px.y()},
                         {"sigma_px", r.sigma_px}});
  json rejected = json::array();
  for (const auto& r : a.rejected)
    rejected.push_back({{"point", r.point},
                        {"subimage", r.subimage},
                        {"kind", r.reference ? "reference" : "tie"},
                        {"w", r.w},
                        {"vU_px", r.v_px.x()},
                        {"vV_px", r.v_px.y()}});
  json j = {{"kind", "stitch"},
            {"frame", a.frame},
            {"sigma0", a.sigma0},
            {"sigma0_px", a.sigma0_px},
            {"redundancy", a.redundancy},
            {"iterations", a.iterations},
            {"converged", a.converged},
            {"model", ModelName(a.model)},
            {"n_observations", a.n_observations},
            {"n_unknowns", a.n_unknowns},
            {"n_ties", a.n_ties},
            {"n_references", a.n_references},
            {"n_single_ray_points", a.n_single_ray_points},
            {"covariance_ok", a.covariance_ok},
            {"max_corner_sigma_px", a.max_corner_sigma_px},
            {"subimages", subimages},
            {"rejected", rejected},
            {"residuals", residuals},
            {"diagnostics", a.diagnostics}};
  if (choice) {
    json table = json::array();
    for (const auto& c : choice->candidates) table.push_back(CandidateToJson(c));
    j["model_choice"] = {{"test", choice->test},
                         {"alpha", choice->alpha},
                         {"chosen", ModelName(choice->chosen)},
                         {"reason", choice->reason},
                         {"table", table}};
  }
  return j;
}

namespace {

// The flight's statistics over its frames: sigma0 from the summed v^T P v and redundancy, the
// a-priori sigma from any frame (sigma0_px / sigma0), the models the frames chose.
json FlightSummaryJson(const BatchResult& result, calib::MappingModel model) {
  double vtpv = 0;
  int redundancy = 0, iterations = 0;
  bool converged = true;
  std::map<calib::MappingModel, int> chosen;
  double scale = 0;
  for (const FrameRun& run : result.frames) {
    vtpv += run.adjustment.vtpv;
    redundancy += run.adjustment.redundancy;
    iterations = std::max(iterations, run.adjustment.iterations);
    converged = converged && run.adjustment.converged;
    ++chosen[run.adjustment.model];
    if (run.adjustment.sigma0 > 0) scale = run.adjustment.sigma0_px / run.adjustment.sigma0;
  }
  const double sigma0 = redundancy > 0 ? std::sqrt(vtpv / redundancy) : 0.0;
  json counts = json::object();
  for (const auto& [m, n] : chosen) counts[ModelName(m)] = n;
  return {{"kind", "stitch"},
          {"sigma0", sigma0},
          {"sigma0_px", sigma0 * scale},
          {"redundancy", redundancy},
          {"iterations", iterations},
          {"converged", converged},
          {"model", ModelName(model)},
          {"n_frames", result.frames.size()},
          {"models_chosen", counts}};
}

// The first frame adjustment in `model` (a frame's own or a determinable candidate of its choice).
const FrameAdjustment* FirstAdjustmentIn(const BatchResult& result, calib::MappingModel model) {
  for (const FrameRun& run : result.frames) {
    const FrameAdjustment* found = run.adjustment.model == model ? &run.adjustment : nullptr;
    if (run.choice)
      for (const auto& c : run.choice->candidates)
        if (c.model == model && c.determinable) found = &c.adjustment;
    if (found) return found;
  }
  return nullptr;
}

// The flight's mean mappings in the reported model, their sigma the spread over the frames. A
// base sub-image keeps its own (held: sigma 0); a parameter without a spread has a null sigma.
json FlightSubimagesJson(const BatchResult& result, const ModelStability& s) {
  json subimages = json::array();
  const FrameAdjustment* first = FirstAdjustmentIn(result, s.model);
  AEROCAL_CHECK(first) << "stability of a model no frame adjusted";
  for (const SubimageEstimate& e : first->subimages) {
    const auto names = MappingParamNames(e.model);
    std::vector<double> params = e.params;
    json sigma = json::array();
    for (size_t i = 0; i < e.params.size(); ++i) sigma.push_back(e.base ? json(0.0) : json());
    for (const auto& p : s.parameters)
      if (p.subimage == e.id)
        for (size_t i = 0; i < names.size(); ++i)
          if (names[i] == p.name) {
            params[i] = p.mean;
            sigma[i] = p.std;
          }
    subimages.push_back({{"id", e.id},
                         {"model", ModelName(e.model)},
                         {"base", e.base},
                         {"param_names", names},
                         {"params", params},
                         {"sigma", sigma}});
  }
  return subimages;
}

// sigma0's mean and spread over the frames (of the reported model's stability, else of the
// frames' own results when that model was not adjusted in every frame) and every model's.
json FlightStabilityJson(const BatchResult& result, const ModelStability* reported) {
  json stability = json::object();
  if (reported) {
    stability["mean_sigma0_px"] = reported->mean_sigma0_px;
    stability["std_sigma0_px"] = reported->std_sigma0_px;
  } else {
    double mean = 0, var = 0;
    const double n = static_cast<double>(result.frames.size());
    for (const FrameRun& run : result.frames) mean += run.adjustment.sigma0_px / n;
    for (const FrameRun& run : result.frames)
      var += (run.adjustment.sigma0_px - mean) * (run.adjustment.sigma0_px - mean) / (n - 1);
    stability["mean_sigma0_px"] = mean;
    stability["std_sigma0_px"] = std::sqrt(var);
  }
  json per_model = json::array();
  for (const ModelStability& s : result.stability) per_model.push_back(StabilityToJson(s));
  stability["models"] = per_model;
  return stability;
}

}  // namespace

json StitchResultToJson(const BatchResult& result, const BatchOptions& options) {
  AEROCAL_CHECK(!result.frames.empty()) << "stitch result without frames";
  auto frame_json = [](const FrameRun& run) {
    return FrameResultToJson(run.adjustment, run.choice ? &*run.choice : nullptr);
  };
  if (result.frames.size() == 1) return frame_json(result.frames.front());

  const calib::MappingModel model = FlightModel(result, options);
  json j = FlightSummaryJson(result, model);
  const ModelStability* reported = nullptr;
  for (const ModelStability& s : result.stability)
    if (s.model == model) reported = &s;
  j["subimages"] = reported ? FlightSubimagesJson(result, *reported) : json::array();
  j["stability"] = FlightStabilityJson(result, reported);
  json frames = json::array();
  for (const FrameRun& run : result.frames) frames.push_back(frame_json(run));
  j["frames"] = frames;
  return j;
}

calib::Camera ApplyStitchResult(const calib::Camera& camera,
                                const std::string& path,
                                const std::string& frame) {
  return ApplyStitchDocument(camera, ReadResult(path, {"stitch"}, "`aerocal stitch`"), path, frame);
}

calib::Camera ApplyStitchDocument(const calib::Camera& camera,
                                  const json& doc,
                                  const std::string& path,
                                  const std::string& frame) {
  const json* source = &doc;
  if (!frame.empty()) {
    // A frame's result is an object whose "frame" is that id; a flight's "frames" an array of them.
    auto is_frame = [&frame](const json& j) {
      return j.is_object() && j.contains("frame") && j["frame"].is_string() &&
             j["frame"].get<std::string>() == frame;
    };
    source = nullptr;
    if (is_frame(doc)) source = &doc;
    if (doc.contains("frames")) {
      if (!doc["frames"].is_array()) throw InputError(path + ": frames: not an array");
      for (const json& f : doc["frames"])
        if (is_frame(f)) source = &f;
    }
    if (!source) throw InputError(path + ": no result for frame " + frame);
  }
  if (!source->contains("subimages") || !(*source)["subimages"].is_array())
    throw InputError(path + ": no subimages in the stitch result");
  calib::Camera out = camera;
  std::vector<bool> seen(out.subimages.size(), false);
  try {
    for (const json& s : (*source)["subimages"]) {
      const std::string id = s.at("id").get<std::string>();
      const int k = out.SubimageIndex(id);
      if (k < 0) throw InputError(path + ": sub-image " + id + " is not in the camera");
      const auto model = calib::ParseMappingModel(s.at("model").get<std::string>());
      if (!model) throw InputError(path + ": sub-image " + id + ": unknown model");
      const auto params = s.at("params").get<std::vector<double>>();
      if (static_cast<int>(params.size()) != calib::MappingParamCount(*model))
        throw InputError(path + ": sub-image " + id + ": wrong number of params");
      for (double p : params)
        if (!(std::abs(p) <= 1e7))
          throw InputError(path + ": sub-image " + id +
                           ": a parameter is not finite or beyond 1e7");
      out.subimages[k].model = *model;
      out.subimages[k].params = params;
      // The mapping must be invertible over the sub-image: its Jacobian at the centre and the
      // corners (central differences of 1 px) must not be singular (an all-zero affine is).
      const calib::SubimageMapping& m = out.subimages[k];
      for (const auto& [cu, cv] :
           {std::pair{0.5, 0.5}, {0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {1.0, 1.0}}) {
        const Eigen::Vector2d uv(cu * m.width_px, cv * m.height_px);
        Eigen::Matrix2d j;
        j.col(0) = (m.VirtualFromSub(uv + Eigen::Vector2d(0.5, 0)) -
                    m.VirtualFromSub(uv - Eigen::Vector2d(0.5, 0)));
        j.col(1) = (m.VirtualFromSub(uv + Eigen::Vector2d(0, 0.5)) -
                    m.VirtualFromSub(uv - Eigen::Vector2d(0, 0.5)));
        const double det = j.determinant();
        if (!std::isfinite(det) || std::abs(det) < 1e-6)
          throw InputError(path + ": sub-image " + id + ": the " +
                           std::string(calib::MappingModelName(*model)) +
                           " mapping is singular (not invertible) over the sub-image");
      }
      seen[k] = true;
    }
  } catch (const json::exception& e) {
    throw InputError(path + ": malformed sub-image entry (" + e.what() + ")");
  }
  for (size_t k = 0; k < seen.size(); ++k)
    if (!seen[k]) throw InputError(path + ": no mapping for sub-image " + out.subimages[k].id);
  return out;
}

}  // namespace aerocal::stitch
