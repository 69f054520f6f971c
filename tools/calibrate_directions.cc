#include "tools/calibrate_directions.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "calib/core/string_printf.h"
#include "tools/calibrate_direction_subimages.h"
#include "tools/calibrate_direction_units.h"
#include "tools/calibrate_models.h"
#include "tools/camera_formats.h"
#include "tools/command_registry.h"
#include "triangulation/calibration/calibration_json.h"
#include "triangulation/calibration/direction_io.h"
#include "triangulation/calibration/direction_run.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <tuple>

namespace aerocal::tools {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kArcSecond = kDeg / 3600.0;

nlohmann::json Arcsec(const Eigen::Vector2d& rad) {
  return {rad.x() / kArcSecond, rad.y() / kArcSecond};
}

// The method: the instrument, the file, what was estimated besides the interior.
nlohmann::json MethodJson(const triangulation::DirectionRun& d,
                          const triangulation::DirectionData& data,
                          const std::string& path) {
  int known = 0;
  for (const auto& t : data.targets) known += t.known;
  return {
      {"kind", d.all.method},
      {"directions", path},
      {"targets", data.targets.size()},
      {"known_targets", known},
      {"settings", data.settings},
      {"adjustment",
       "direction adjustment (calib/residuals/direction.h): the interior and the camera's "
       "rotation to the "
       "instrument; no position, no scale; no data snooping"},
      {"budget",
       "the directions' angular sigmas are part of each observation's a-priori covariance: the "
       "adjustment's "
       "component holds them (no separate type-B component of the directions)"},
      {"instrument_from_camera_opk_deg", DegreesJson(d.all.opk_rad)},
      {"instrument_from_camera_sigma_arcsec",
       d.all.covariance_ok ? nlohmann::json({d.all.opk_sigma_rad.x() / kArcSecond,
                                             d.all.opk_sigma_rad.y() / kArcSecond,
                                             d.all.opk_sigma_rad.z() / kArcSecond})
                           : nlohmann::json()},
      {"start_opk_deg", DegreesJson(d.start_opk_rad)},
      {"estimated_targets", EstimatedTargetsJson(d.all.target_angles_rad, d.all.target_sigma_rad)},
      {"sub_images",
       "the camera file's (virtual) image; a multi-CCD camera's sub-images are calibrated in "
       "one adjustment when the directions name them (`unit`), a rig's heads likewise"}};
}

// The camera file written in the requested format: the --model run's camera when it was given.
nlohmann::json WriteCamera(const DirectionsArgs& args,
                           std::string* printed,
                           const calib::Camera& camera,
                           const triangulation::CameraEstimate& estimate) {
  const calib::ConversionResult written =
      WriteCameraInFormat(args.write_camera,
                          triangulation::UpdatedCamera(camera, estimate),
                          args.camera_format,
                          &estimate.sigma);
  *printed += StringPrintf("camera (%s) -> %s (%s)\n",
                           std::string(calib::CameraModelName(estimate.model)).c_str(),
                           args.write_camera.c_str(),
                           args.camera_format.c_str());
  return {{"file", args.write_camera},
          {"format", args.camera_format},
          {"model", std::string(calib::CameraModelName(estimate.model))},
          {"exact", written.exact},
          {"residual_px",
           {{"rms", written.residual.rms_px},
            {"max", written.residual.max_px},
            {"max_inner80", written.residual.max_inner80_px}}}};
}

}  // namespace

DirectionSetup ReadDirectionSetup(const DirectionsArgs& args, const calib::Camera& camera) {
  DirectionSetup setup;
  setup.options.calibration.free_interior = triangulation::ParseSelfCalibration(
      args.self_calibration.empty() ? DefaultSelfCalibration(camera.model) : args.self_calibration,
      camera.model);
  if (setup.options.calibration.free_interior.empty())
    throw ConfigError("--self-calibration: calibrate needs at least one parameter (got none)");
  if (!args.out.empty()) CheckOutputFile(args.out, "--out");
  if (!args.write_camera.empty()) CheckOutputFile(args.write_camera, "--write-camera");
  FindCameraFormat(args.camera_format, "--camera-format");
  if (!args.budget.empty()) setup.budget = triangulation::ReadBudgetOptions(args.budget);
  if (setup.budget.target_radius_mm > 0)
    throw ConfigError(args.budget +
                      ": target_radius_mm is the eccentricity of test-field targets; a direction "
                      "calibration has none (--directions)");
  if (!args.radii_mm.empty()) setup.budget.radii_mm = args.radii_mm;
  setup.radii_given = !setup.budget.radii_mm.empty();
  if (!setup.radii_given) setup.budget.radii_mm = DefaultCertifiedRadiiMm(camera);
  return setup;
}

void CheckGroups(const triangulation::DirectionData& data, const std::string& path) {
  std::set<std::string> names;
  for (const auto& g : data.groups)
    if (!g.empty()) names.insert(g);
  if (names.size() == 1)
    ThrowInputError(
        {path, 0}, "1 group (" + *names.begin() + "): the stability test needs two groups or more");
}

namespace {

// The `calibration` section of a single camera's run: the budget, the method, the start, the data.
nlohmann::json SingleCalibrationJson(const DirectionsArgs& args,
                                     const calib::Camera& camera,
                                     const triangulation::DirectionRun& d,
                                     const triangulation::DirectionData& data,
                                     const DirectionSetup& setup,
                                     const std::vector<triangulation::BudgetQuantity>& budget) {
  const triangulation::CalibrationRun& run = d.run;
  nlohmann::json cal =
      triangulation::CalibrationToJson(run, budget, setup.budget.radii_mm, camera.c_mm());
  int known = 0;
  for (const auto& t : data.targets) known += t.known;
  cal["method"] = MethodJson(d, data, args.directions);
  cal["start"] = {
      {"c_camera_file_mm", camera.c_mm()},
      {"c_start_mm", camera.c_mm()},
      {"opk_deg", DegreesJson(d.start_opk_rad)},
      {"rotation", known >= 2 ? "Wahba's problem (SVD) on the known directions" : "zero"}};
  cal["data"] = DirectionDataJson(data, run.groups.size());
  cal["camera"] = {{"id", run.camera},
                   {"file", args.camera},
                   {"pixel_size_mm", camera.pixel_size_mm},
                   {"format_px", {camera.width_px, camera.height_px}}};
  cal["model"] = std::string(calib::CameraModelName(camera.model));
  cal["rms_px"] = RmsPx(run.all.result);
  return cal;
}

// --model: the same directions calibrated in that model beside the camera file's (its camera is
// what --write-camera writes); into cal["beside"]. Returns its start and, when valid, its estimate.
std::pair<calib::Camera, std::optional<triangulation::CameraEstimate>> BesideModel(
    const calib::Camera& camera,
    calib::CameraModelId model,
    const triangulation::DirectionData& data,
    const DirectionSetup& setup,
    const std::string& camera_id,
    nlohmann::json* cal,
    std::string* printed) {
  triangulation::DirectionRunOptions in_model = setup.options;
  in_model.calibration.free_interior =
      triangulation::ParseSelfCalibration(DefaultSelfCalibration(model), model);
  const calib::Camera start = StartInModel(camera, model, in_model.calibration.free_interior);
  const triangulation::DirectionRun other = triangulation::RunDirectionCalibration(
      camera_id, start, data.targets, data.observations, {}, in_model);
  const triangulation::AdjustmentResult& o = other.run.all.result;
  nlohmann::json b = triangulation::CalibrationRunToJson(o);
  b["model"] = std::string(calib::CameraModelName(model));
  b["self_calibration"] = in_model.calibration.free_interior;
  b["rms_px"] = RmsPx(o);
  *printed += StringPrintf("beside, in model %s: sigma0 %.4f, RMS %.4f px%s\n",
                           std::string(calib::CameraModelName(model)).c_str(),
                           o.sigma0,
                           RmsPx(o),
                           o.valid ? "" : " (not valid)");
  (*cal)["beside"] = b;
  if (!o.valid) return {start, std::nullopt};
  return {start, o.cameras[0]};
}

}  // namespace

CalibrateOutcome CalibrateFromDirections(const DirectionsArgs& args) {
  // A rig file: its heads are the units of one adjustment (the directions' `unit` column).
  if (IsRigCameraFile(args.camera)) return CalibrateRigFromDirections(args);
  const calib::Camera camera = calib::ReadCamera(args.camera, calib::CameraModels::kAny);
  // A multi-CCD camera whose directions name their sub-images: one adjustment of the interior
  // and the mappings.
  if (!camera.subimages.empty() && HasUnitColumn(args.directions))
    return CalibrateSubimagesFromDirections(args, camera);
  CalibrateOutcome outcome;
  const calib::CameraModelId beside_model =
      args.model.empty() ? camera.model : ModelOfOption(args.model);
  const DirectionSetup setup = ReadDirectionSetup(args, camera);
  const triangulation::DirectionData data =
      triangulation::ReadDirections(args.directions, camera, args.sigma_px);
  CheckGroups(data, args.directions);

  const std::string camera_id = camera.name.empty() ? "cam1" : camera.name;
  const triangulation::DirectionRun d = triangulation::RunDirectionCalibration(
      camera_id, camera, data.targets, data.observations, data.groups, setup.options);
  const triangulation::CalibrationRun& run = d.run;
  const auto budget = triangulation::UncertaintyBudget(run, run.project, setup.budget);
  const triangulation::AdjustmentResult& r = run.all.result;
  outcome.printed += StringPrintf("%s (%s): %s",
                                  d.all.method.c_str(),
                                  args.directions.c_str(),
                                  triangulation::FormatSummary(r).c_str());
  nlohmann::json json = DirectionResultJson(r, setup);
  nlohmann::json cal = SingleCalibrationJson(args, camera, d, data, setup, budget);
  for (const auto& q : budget) outcome.printed += StringPrintf("  %s\n", q.statement.c_str());
  AddStabilityWarnings(run.stability, &json);
  std::optional<calib::Camera> beside_start;
  std::optional<triangulation::CameraEstimate> beside;
  if (beside_model != camera.model)
    std::tie(beside_start, beside) =
        BesideModel(camera, beside_model, data, setup, camera_id, &cal, &outcome.printed);
  // Only a valid result is written as a camera file (a file that exists is one the next run may
  // use).
  if (!args.write_camera.empty()) {
    if (beside_start && beside)
      cal["camera_written"] = WriteCamera(args, &outcome.printed, *beside_start, *beside);
    else if (!beside_start && r.valid)
      cal["camera_written"] = WriteCamera(args, &outcome.printed, camera, r.cameras[0]);
    else
      outcome.errors += StringPrintf("camera not written: the %sresult is not valid\n",
                                     beside_start ? "--model " : "");
  }
  json["calibration"] = cal;
  FinishDirectionOutcome(r, std::move(json), run.stability.agree, &outcome);
  return outcome;
}

nlohmann::json DirectionResultJson(const triangulation::AdjustmentResult& r,
                                   const DirectionSetup& setup) {
  nlohmann::json json = triangulation::AdjustmentToJson(r);
  json["command"] = "calibrate";
  json["valid"] = r.valid;
  json["invalid_reasons"] = r.invalid_reasons;
  json["self_calibration"] = setup.options.calibration.free_interior;
  return json;
}

nlohmann::json DirectionDataJson(const triangulation::DirectionData& data, size_t groups) {
  int known = 0;
  for (const auto& t : data.targets) known += t.known;
  return {{"images", std::max(1, data.settings)},
          {"observations", data.observations.size()},
          {"control_points", known},
          {"check_points", 0},
          {"groups", groups},
          {"targets", data.targets.size()},
          {"settings", data.settings}};
}

void FinishDirectionOutcome(const triangulation::AdjustmentResult& r,
                            nlohmann::json json,
                            bool groups_agree,
                            CalibrateOutcome* outcome) {
  for (const auto& reason : r.invalid_reasons)
    outcome->errors += "calibrate: not valid: " + reason + "\n";
  outcome->doc = std::move(json);
  outcome->valid = r.valid && groups_agree;
}

nlohmann::json EstimatedTargetsJson(const std::map<std::string, Eigen::Vector2d>& angles_rad,
                                    const std::map<std::string, Eigen::Vector2d>& sigma_rad) {
  nlohmann::json targets = nlohmann::json::object();
  for (const auto& [id, angles] : angles_rad) {
    const auto s = sigma_rad.find(id);
    targets[id] = {{"azimuth_deg", angles.x() / kDeg},
                   {"elevation_deg", angles.y() / kDeg},
                   {"sigma_arcsec", s == sigma_rad.end() ? nlohmann::json() : Arcsec(s->second)}};
  }
  return targets;
}

nlohmann::json DegreesJson(const Eigen::Vector3d& rad) {
  return {rad.x() / kDeg, rad.y() / kDeg, rad.z() / kDeg};
}

nlohmann::json ArcsecOrNullJson(const Eigen::Vector3d& rad, bool known) {
  if (!known) return nullptr;
  return {rad.x() / kArcSecond, rad.y() / kArcSecond, rad.z() / kArcSecond};
}

bool HasUnitColumn(const std::string& directions) {
  return CsvTable::Read(directions).HasColumn("unit");
}

int CalibrateFromDirectionsFile(const DirectionsArgs& args) {
  const CalibrateOutcome outcome = CalibrateFromDirections(args);
  std::fputs(outcome.printed.c_str(), stdout);
  std::fputs(outcome.errors.c_str(), stderr);
  WriteResult(args.out, "adjust", outcome.doc);
  std::printf("result -> %s\n", args.out.c_str());
  return outcome.valid ? kExitOk : kExitNotConverged;
}

}  // namespace aerocal::tools
