#include "tools/calibrate_direction_subimages.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "stitch/adjustment/mapping_param_names.h"
#include "tools/calibrate_models.h"
#include "tools/camera_formats.h"
#include "triangulation/calibration/calibration_json.h"
#include "triangulation/calibration/direction_subimages_run.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <map>

namespace aerocal::tools {
namespace {

void RefuseOptions(const DirectionsArgs& args) {
  if (!args.model.empty())
    throw ConfigError(
        "--model: a multi-CCD camera's sub-images are calibrated in the camera "
        "file's model (--camera " +
        args.camera + " has sub-images)");
  if (args.camera_format != "aerocal")
    throw ConfigError(
        "--camera-format: the sub-images' mappings are written in aerocal's camera "
        "file only (got " +
        args.camera_format + ")");
}

// Per sub-image a camera of its format (the directions' col, row are bounded by it).
std::map<std::string, calib::Camera> SubimageFormats(const calib::Camera& camera) {
  std::map<std::string, calib::Camera> out;
  for (const calib::SubimageMapping& m : camera.subimages) {
    calib::Camera c = camera;
    c.subimages.clear();
    c.width_px = m.width_px;
    c.height_px = m.height_px;
    out[m.id] = c;
  }
  return out;
}

// The mappings' budget: every estimated entry as "<SUB>.<param>" (type A, nu = redundancy).
std::vector<triangulation::BudgetQuantity> MappingBudget(
    const triangulation::SubimageDirectionsCalibration& c, double redundancy) {
  std::vector<triangulation::BudgetQuantity> out;
  for (const auto& s : c.subimages) {
    const auto names = stitch::MappingParamNames(s.mapping.model);
    for (size_t e = 0; e < names.size(); ++e) {
      if (!s.sigma[e]) continue;
      const std::string& n = names[e];
      const bool shift = n == "Tx" || n == "Ty" || n == "a0" || n == "b0" || n == "a3" || n == "b3";
      const bool perspective = n == "c1" || n == "c2";
      out.push_back(triangulation::AdjustedQuantityBudget(
          s.id + "." + n,
          shift         ? "px"
          : perspective ? "1/px"
                        : "1",
          "mapping of sub-image " + s.id + " onto the virtual image (" + names[e] + ")",
          s.mapping.params[e],
          *s.sigma[e],
          redundancy,
          "the direction adjustment's covariance of the mapping (its gauge: calibration.gauge)"));
    }
  }
  return out;
}

nlohmann::json GaugeJson(const triangulation::SubimageDirectionGauge& g) {
  return {{"reference", g.reference},
          {"held", g.held},
          {"rank_defect", g.rank_defect},
          {"rank_defect_with_gauge", g.rank_defect_with_gauge},
          {"smallest_relative_eigenvalues", g.smallest_relative_eigenvalues},
          {"smallest_relative_eigenvalues_with_gauge", g.smallest_relative_eigenvalues_with_gauge},
          {"threshold", g.threshold},
          {"ok", g.ok},
          {"message", g.message},
          {"linearisation",
           "the start values with every radial, decentring and affinity term 0 and every observed "
           "sub-image's mapping free (triangulation/calibration/direction_subimages.h)"}};
}

nlohmann::json SubimagesJson(const triangulation::SubimageDirectionsCalibration& c) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& s : c.subimages) {
    nlohmann::json sigma = nlohmann::json::array();
    for (const auto& v : s.sigma) sigma.push_back(v ? nlohmann::json(*v) : nlohmann::json());
    out.push_back({{"id", s.id},
                   {"observations", s.observations},
                   {"model", std::string(calib::MappingModelName(s.mapping.model))},
                   {"param_names", stitch::MappingParamNames(s.mapping.model)},
                   {"params", s.mapping.params},
                   {"sigma", sigma},
                   {"held", s.held}});
  }
  return out;
}

nlohmann::json MethodJson(const triangulation::SubimageDirectionsRun& d,
                          const triangulation::DirectionData& data,
                          const std::string& path) {
  const triangulation::DirectionCalibration& f = d.all.frame;
  int known = 0;
  for (const auto& t : data.targets) known += t.known;
  std::vector<std::string> ids;
  for (const auto& s : d.all.subimages) ids.push_back(s.id);
  return {
      {"kind", f.method},
      {"directions", path},
      {"targets", data.targets.size()},
      {"known_targets", known},
      {"settings", data.settings},
      {"units", ids},
      {"adjustment",
       "direction adjustment of a multi-CCD camera's sub-images in one problem "
       "(triangulation/calibration/direction_subimages.h): the virtual image's interior, the "
       "camera's rotation to the instrument, per sub-image its mapping onto the virtual image "
       "(the reference's gauge entries held); no position, no scale; no data snooping"},
      {"budget",
       "the interior's budget is the single camera's; each mapping entry has one type-A "
       "component (the adjustment's covariance, which holds the directions' angular sigmas)"},
      {"instrument_from_camera_opk_deg", DegreesJson(f.opk_rad)},
      {"instrument_from_camera_sigma_arcsec", ArcsecOrNullJson(f.opk_sigma_rad, f.covariance_ok)},
      {"start_opk_deg", DegreesJson(d.start_opk_rad)},
      {"estimated_targets", EstimatedTargetsJson(f.target_angles_rad, f.target_sigma_rad)},
      {"sub_images",
       "the sub-images named in `unit`, in one adjustment (gauge: calibration.gauge)"}};
}

// The camera file again with the estimated interior (and its sigmas) and mappings.
nlohmann::json WriteSubimageCamera(const DirectionsArgs& args,
                                   const calib::Camera& camera,
                                   const triangulation::SubimageDirectionsRun& d,
                                   std::string* printed) {
  const triangulation::CameraEstimate& estimate = d.run.all.result.cameras[0];
  calib::Camera written = triangulation::UpdatedCamera(camera, estimate);
  written.subimages = d.all.frame.camera.subimages;
  WriteCameraInFormat(args.write_camera, written, "aerocal", &estimate.sigma);
  *printed += "camera (" + std::to_string(d.all.subimages.size()) + " sub-images updated) -> " +
              args.write_camera + "\n";
  return {
      {"file", args.write_camera}, {"format", "aerocal"}, {"sub_images", d.all.subimages.size()}};
}

}  // namespace

CalibrateOutcome CalibrateSubimagesFromDirections(const DirectionsArgs& args,
                                                  const calib::Camera& camera) {
  RefuseOptions(args);
  CalibrateOutcome outcome;
  const DirectionSetup setup = ReadDirectionSetup(args, camera);
  const triangulation::DirectionData data = triangulation::ReadUnitDirections(
      args.directions, SubimageFormats(camera), args.camera, args.sigma_px);
  CheckGroups(data, args.directions);
  const std::string camera_id = camera.name.empty() ? "cam1" : camera.name;
  const triangulation::SubimageDirectionsRun d = triangulation::RunSubimageDirectionCalibration(
      camera_id, camera, data.targets, data.observations, data.units, data.groups, setup.options);
  const triangulation::CalibrationRun& run = d.run;
  const triangulation::AdjustmentResult& r = run.all.result;
  std::vector<triangulation::BudgetQuantity> budget =
      triangulation::UncertaintyBudget(run, run.project, setup.budget);
  for (auto& q : MappingBudget(d.all, r.solve.redundancy)) budget.push_back(std::move(q));
  outcome.printed += StringPrintf("%s, %zu sub-images (%s): %s",
                                  d.all.frame.method.c_str(),
                                  d.all.subimages.size(),
                                  args.directions.c_str(),
                                  triangulation::FormatSummary(r).c_str());
  outcome.printed += "  gauge: sub-image " + d.all.gauge.reference + " holds " +
                     std::to_string(d.all.gauge.held.size()) + " mapping entries (rank defect " +
                     std::to_string(d.all.gauge.rank_defect) + " without, " +
                     std::to_string(d.all.gauge.rank_defect_with_gauge) + " with)\n";
  for (const auto& q : budget) outcome.printed += StringPrintf("  %s\n", q.statement.c_str());
  nlohmann::json json = DirectionResultJson(r, setup);
  nlohmann::json cal =
      triangulation::CalibrationToJson(run, budget, setup.budget.radii_mm, camera.c_mm());
  cal["method"] = MethodJson(d, data, args.directions);
  cal["gauge"] = GaugeJson(d.all.gauge);
  cal["subimages"] = SubimagesJson(d.all);
  cal["start"] = {
      {"c_camera_file_mm", camera.c_mm()},
      {"c_start_mm", camera.c_mm()},
      {"opk_deg", DegreesJson(d.start_opk_rad)},
      {"rotation", "Wahba's problem (SVD) on the known directions through the file's mappings"}};
  cal["data"] = DirectionDataJson(data, run.groups.size());
  cal["data"]["units"] = d.all.subimages.size();
  cal["camera"] = {{"id", camera_id},
                   {"file", args.camera},
                   {"kind", "multi-CCD"},
                   {"pixel_size_mm", camera.pixel_size_mm},
                   {"format_px", {camera.width_px, camera.height_px}}};
  cal["model"] = std::string(calib::CameraModelName(camera.model));
  cal["rms_px"] = RmsPx(r);
  AddStabilityWarnings(run.stability, &json);
  // Only a valid result is written as a camera file.
  if (!args.write_camera.empty() && r.valid)
    cal["camera_written"] = WriteSubimageCamera(args, camera, d, &outcome.printed);
  else if (!args.write_camera.empty())
    outcome.errors += "camera not written: the result is not valid\n";
  json["calibration"] = cal;
  FinishDirectionOutcome(r, std::move(json), run.stability.agree, &outcome);
  return outcome;
}

}  // namespace aerocal::tools
