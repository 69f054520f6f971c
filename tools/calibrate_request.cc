#include "tools/calibrate_request.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/convert_camera.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "tools/board_detection.h"
#include "tools/calibrate_models.h"
#include "tools/camera_formats.h"
#include "triangulation/block/block_io.h"
#include "triangulation/calibration/calibration.h"
#include "triangulation/calibration/calibration_json.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

namespace aerocal::tools {
namespace {

using triangulation::AdjustmentResult;

// Image -> (group, the line that put it there), from either source of groups.
using GroupLines = std::map<std::string, std::pair<std::string, int>>;

// The checks both sources share, at the line that breaks them: every image is observed, each group
// holds two images or more, and there are two groups or more (the stability test compares groups).
std::map<std::string, std::string> CheckedGroups(const GroupLines& lines,
                                                 const std::string& file,
                                                 const std::set<std::string>& observed) {
  std::map<std::string, std::pair<int, int>> groups;  // group -> (images, first line)
  for (const auto& [image, entry] : lines) {
    if (!observed.count(image))
      ThrowInputError({file, entry.second}, "image " + image + " has no observations");
    auto& g = groups.emplace(entry.first, std::make_pair(0, entry.second)).first->second;
    ++g.first;
    g.second = std::min(g.second, entry.second);
  }
  for (const auto& [group, g] : groups)
    if (g.first < 2)
      ThrowInputError({file, g.second},
                      "group " + group + " has " + std::to_string(g.first) +
                          " image (a group needs two or more)");
  if (groups.size() < 2)
    ThrowInputError(
        {file, 0},
        std::to_string(groups.size()) + " group(s): the stability test needs two groups or more");
  std::map<std::string, std::string> out;
  for (const auto& [image, entry] : lines) out[image] = entry.first;
  return out;
}

std::map<std::string, std::string> ReadGroups(const std::string& path,
                                              const std::set<std::string>& observed) {
  const CsvTable table = CsvTable::Read(path);
  table.RequireColumns({"image", "group"});
  table.RejectUnknownColumns({"image", "group"});
  GroupLines out;
  for (const auto& row : table.rows()) {
    const std::string image = table.String(row, "image"), group = table.String(row, "group");
    if (image.empty() || group.empty())
      throw InputError(table.Where(row).ToString() + ": image and group must not be empty");
    if (!out.emplace(image, std::make_pair(group, row.line)).second)
      throw InputError(table.Where(row).ToString() + ": image " + image + " listed twice");
  }
  return CheckedGroups(out, path, observed);
}

// The optional `group` column of observations.csv: image -> group (rows with an empty group put
// nothing); an image given two different groups is an error at the second one's line.
std::map<std::string, std::string> GroupsFromObservations(const std::string& path,
                                                          const std::set<std::string>& observed) {
  const CsvTable table = CsvTable::Read(path);
  GroupLines out;
  if (!table.HasColumn("group")) return {};
  for (const auto& row : table.rows()) {
    const std::string image = table.String(row, "image"), group = table.String(row, "group");
    if (group.empty()) continue;
    const auto [at, added] = out.emplace(image, std::make_pair(group, row.line));
    if (!added && at->second.first != group)
      throw InputError(table.Where(row).ToString() + ": image " + image + " is in group " +
                       at->second.first + " above, here in " + group);
  }
  if (out.empty()) return {};
  return CheckedGroups(out, path, observed);
}

// How the board's marks were found, for the result's method.
std::string BoardDetector(const CalibrateRequest& r, const BoardSpec& spec) {
  if (!r.corners.empty()) return "given (corners measured by the caller)";
  return spec.kind == "chessboard"
             ? "cv::findChessboardCorners + cv::cornerSubPix (11 x 11, 1e-4 px)"
             : "cv::findCirclesGrid";
}

// The marks of the request in `project` (a test field's files, or the board detected in the
// images or given as marks), and the method's description for the result.
nlohmann::json LoadMarks(const CalibrateRequest& r,
                         const calib::Camera& camera,
                         DetectedBoards* detected,
                         triangulation::Project* project,
                         std::string* printed) {
  if (r.images.empty() && r.corners.empty()) {
    project->observations = triangulation::ReadObservations(r.observations, r.sigma_px);
    project->points = triangulation::ReadPoints(r.points);
    project->path = project->observations_file = r.observations;
    project->points_file = r.points;
    return {{"kind", "test field"}, {"observations", r.observations}, {"points", r.points}};
  }
  const BoardSpec spec = ParseBoard(r.board, "--board");
  if (!r.corners.empty()) {
    *detected = BoardsFromMarks(
        r.corners, spec, camera.width_px, camera.height_px, r.sigma_px, r.board_sigma_mm);
  } else {
    *detected = DetectBoards(r.images, spec, r.sigma_px, r.board_sigma_mm);
    if (detected->width_px != camera.width_px || detected->height_px != camera.height_px)
      throw InputError(StringPrintf("%s: format_px is %d x %d, the images are %d x %d px",
                                    r.camera.c_str(),
                                    camera.width_px,
                                    camera.height_px,
                                    detected->width_px,
                                    detected->height_px));
  }
  project->observations = detected->observations;
  project->points = detected->points;
  project->path = project->observations_file = r.corners.empty() ? r.images : "corners";
  for (const auto& path : detected->not_detected)
    *printed += "warning: board not found in " + path + " (image left out)\n";
  return {{"kind", "planar target"},
          {"board", spec.kind},
          {"columns", spec.columns},
          {"rows", spec.rows},
          {"spacing_mm", spec.square_mm},
          {"board_sigma_mm", r.board_sigma_mm},
          {"images", r.corners.empty() ? r.images : "corners"},
          {"detected", detected->image_paths},
          {"not_detected", detected->not_detected},
          {"detector", BoardDetector(r, spec)}};
}

// The cross-file checks of the block readers, with one exposure per observed image.
void ValidateMarks(const triangulation::Project& project, const std::string& camera_id) {
  triangulation::Project check = project;
  std::set<std::string> images;
  for (const auto& o : project.observations) images.insert(o.image);
  for (const auto& image : images) {
    triangulation::Exposure e;
    e.image = image;
    e.camera = camera_id;
    check.exposures.push_back(e);
  }
  triangulation::ValidateProject(check);
}

// The image groups: --groups, or the group column of a test field's observations.csv.
std::map<std::string, std::string> GroupsOf(const CalibrateRequest& r,
                                            const triangulation::Project& project) {
  std::set<std::string> observed;
  for (const auto& o : project.observations) observed.insert(o.image);
  std::map<std::string, std::string> groups;
  if (!r.groups.empty()) groups = ReadGroups(r.groups, observed);
  if (!r.observations.empty()) {
    const auto from_column = GroupsFromObservations(r.observations, observed);
    if (!from_column.empty() && !r.groups.empty())
      throw ConfigError("--groups: " + r.observations + " has a group column already (give one)");
    if (!from_column.empty()) groups = from_column;
  }
  return groups;
}

struct BesideRun {  // the same marks calibrated in --model
  nlohmann::json json;
  std::optional<calib::Camera> camera;
  std::optional<triangulation::CameraEstimate> estimate;
};

// The same marks calibrated in --model, started from the camera file's values converted.
BesideRun CalibrateBeside(const triangulation::Project& project,
                          const std::string& camera_id,
                          const calib::Camera& camera,
                          calib::CameraModelId beside_model,
                          const triangulation::CalibrateOptions& options,
                          std::string* printed) {
  triangulation::CalibrateOptions beside = options;
  beside.adjust.free_interior =
      triangulation::ParseSelfCalibration(DefaultSelfCalibration(beside_model), beside_model);
  beside.control_propagation = false;
  triangulation::Project in_model = project;
  in_model.cameras[camera_id] = StartInModel(camera, beside_model, beside.adjust.free_interior);
  const triangulation::CalibrationRun other = triangulation::Calibrate(in_model, beside, {});
  const AdjustmentResult& o = other.all.result;
  BesideRun run;
  run.json = triangulation::CalibrationRunToJson(o);
  run.json["model"] = std::string(calib::CameraModelName(beside_model));
  run.json["self_calibration"] = beside.adjust.free_interior;
  run.json["rms_px"] = RmsPx(o);
  run.json["seconds"] = o.solve.seconds;
  *printed += StringPrintf("beside, in model %s: sigma0 %.4f, RMS %.4f px%s\n",
                           std::string(calib::CameraModelName(beside_model)).c_str(),
                           o.sigma0,
                           RmsPx(o),
                           o.valid ? "" : " (not valid)");
  if (o.valid && !o.cameras.empty()) {
    run.camera = triangulation::UpdatedCamera(in_model.cameras[camera_id], o.cameras[0]);
    run.estimate = o.cameras[0];
  }
  return run;
}

// cv::calibrateCamera on the detected marks, for comparison (--model opencv with --images).
nlohmann::json OpenCvBeside(const DetectedBoards& detected,
                            const calib::Camera& camera,
                            std::string* printed) {
  const OpenCvCalibration cv = CalibrateWithOpenCv(detected);
  const double p = camera.pixel_size_mm;
  *printed +=
      StringPrintf("cv::calibrateCamera: RMS %.4f px, fx %.4f fy %.4f cx %.4f cy %.4f (%.3f s)\n",
                   cv.rms_px,
                   cv.fx,
                   cv.fy,
                   cv.cx,
                   cv.cy,
                   cv.seconds);
  return {{"function", "cv::calibrateCamera (flags 0: fx, fy, cx, cy, k1, k2, p1, p2, k3)"},
          {"rms_px", cv.rms_px},
          {"seconds", cv.seconds},
          {"fx", cv.fx},
          {"fy", cv.fy},
          {"cx", cv.cx},
          {"cy", cv.cy},
          {"k1", cv.distortion[0]},
          {"k2", cv.distortion[1]},
          {"p1", cv.distortion[2]},
          {"p2", cv.distortion[3]},
          {"k3", cv.distortion[4]},
          {"equivalent",
           {{"c", 0.5 * (cv.fx + cv.fy) * p},
            {"x0", (cv.cx - 0.5 * (camera.width_px - 1)) * p},
            {"y0", -(cv.cy - 0.5 * (camera.height_px - 1)) * p}}}};
}

// --write-camera: the calibrated camera in the format asked for, only from a valid estimate (a
// file that exists is one the next run may use); "camera_written" for the result, or "" with the
// reason in `errors`.
nlohmann::json WriteCalibratedCamera(const CalibrateRequest& r,
                                     const calib::Camera& camera,
                                     const triangulation::CameraEstimate& estimate,
                                     const std::string& model_name,
                                     std::string* printed) {
  const calib::ConversionResult written =
      WriteCameraInFormat(r.write_camera, camera, r.camera_format, &estimate.sigma);
  nlohmann::json j = {{"file", r.write_camera}, {"format", r.camera_format}};
  if (!model_name.empty()) j["model"] = model_name;
  j["exact"] = written.exact;
  j["residual_px"] = {{"rms", written.residual.rms_px},
                      {"max", written.residual.max_px},
                      {"max_inner80", written.residual.max_inner80_px}};
  *printed +=
      model_name.empty()
          ? StringPrintf("camera -> %s (%s)\n", r.write_camera.c_str(), r.camera_format.c_str())
          : StringPrintf("camera (the %s estimate) -> %s (%s)\n",
                         model_name.c_str(),
                         r.write_camera.c_str(),
                         r.camera_format.c_str());
  return j;
}

void CheckRequest(const CalibrateRequest& r) {
  const bool field = !r.observations.empty() || !r.points.empty();
  const bool board = !r.images.empty() || !r.board.empty() || !r.corners.empty();
  if (field == board)
    throw ConfigError(
        "give either --observations and --points, or --images and --board, or --directions");
  if (field && (r.observations.empty() || r.points.empty()))
    throw ConfigError("--observations and --points go together");
  if (!r.images.empty() && !r.corners.empty())
    throw ConfigError("corners: give either the images or their corners, not both");
  if (!r.corners.empty() && r.board.empty())
    throw ConfigError("corners needs board (e.g. 'chessboard:9x6:25')");
  if (board && ((r.images.empty() && r.corners.empty()) || r.board.empty()))
    throw ConfigError("--images and --board go together");
}

// The adjustment's options of the request: the free set (the model's default unless given), data
// snooping, the closed-form start of c.
triangulation::CalibrateOptions CalibrateOptionsOf(const CalibrateRequest& r,
                                                   calib::CameraModelId model) {
  triangulation::CalibrateOptions options;
  options.adjust.free_interior = triangulation::ParseSelfCalibration(
      r.self_calibration.empty() ? DefaultSelfCalibration(model) : r.self_calibration, model);
  if (options.adjust.free_interior.empty())
    throw ConfigError("--self-calibration: calibrate needs at least one parameter (got none)");
  options.adjust.data_snooping = !r.no_snooping;
  options.adjust.suspect_effect_limit = r.suspect_effect_limit;
  options.closed_form_c = !r.no_closed_form;
  options.adjust.Validate();
  return options;
}

// Every output checked before the work (nothing is written when one cannot be).
void CheckOutputs(const CalibrateRequest& r) {
  if (!r.out.empty()) CheckOutputFile(r.out, "--out");
  if (!r.write_marks.empty()) CheckOutputFolder(r.write_marks, "--write-marks");
  if (!r.write_camera.empty()) CheckOutputFile(r.write_camera, "--write-camera");
  FindCameraFormat(r.camera_format, "--camera-format");
}

// --write-camera: the camera of this run, or with --model (`beside` given) the model-M estimate of
// this run (issue 29), not a refit of ours; null and a message when the estimate is not valid.
nlohmann::json WriteCameraOf(const CalibrateRequest& r,
                             const calib::Camera& camera,
                             const BesideRun* beside,
                             const AdjustmentResult& result,
                             CalibrateOutcome* outcome) {
  if (beside != nullptr && beside->camera)
    return WriteCalibratedCamera(r,
                                 *beside->camera,
                                 *beside->estimate,
                                 std::string(calib::CameraModelName(beside->camera->model)),
                                 &outcome->printed);
  if (beside != nullptr) {
    outcome->errors += "camera not written: the --model result is not valid\n";
    return nullptr;
  }
  if (result.valid && !result.cameras.empty())
    return WriteCalibratedCamera(r,
                                 triangulation::UpdatedCamera(camera, result.cameras[0]),
                                 result.cameras[0],
                                 "",
                                 &outcome->printed);
  outcome->errors += "camera not written: the result is not valid\n";
  return nullptr;
}

}  // namespace

CalibrateOutcome RunCalibration(const CalibrateRequest& r) {
  CheckRequest(r);
  CalibrateOutcome outcome;
  const calib::Camera camera = calib::ReadCamera(r.camera, calib::CameraModels::kAny);
  const calib::CameraModelId model = camera.model;
  const calib::CameraModelId beside_model = r.model.empty() ? model : ModelOfOption(r.model);
  const triangulation::CalibrateOptions options = CalibrateOptionsOf(r, model);
  CheckOutputs(r);
  triangulation::BudgetOptions budget;
  if (!r.budget.empty()) budget = triangulation::ReadBudgetOptions(r.budget);
  if (!r.radii_mm.empty()) budget.radii_mm = r.radii_mm;

  triangulation::Project project;
  const std::string camera_id = camera.name.empty() ? "cam1" : camera.name;
  project.cameras[camera_id] = camera;
  project.camera_files[camera_id] = r.camera;
  DetectedBoards detected;
  const nlohmann::json method = LoadMarks(r, camera, &detected, &project, &outcome.printed);
  ValidateMarks(project, camera_id);
  const std::map<std::string, std::string> groups = GroupsOf(r, project);
  if (budget.radii_mm.empty()) budget.radii_mm = DefaultCertifiedRadiiMm(camera);
  const bool board_marks = !r.images.empty() || !r.corners.empty();
  if (!r.write_marks.empty() && board_marks) {
    triangulation::WriteObservations(r.write_marks + "/observations.csv", project.observations);
    triangulation::WritePoints(r.write_marks + "/points.csv", project.points);
  }

  const triangulation::CalibrationRun run = triangulation::Calibrate(project, options, groups);
  const auto budget_table = triangulation::UncertaintyBudget(run, run.project, budget);
  const AdjustmentResult& result = run.all.result;
  outcome.printed += triangulation::FormatSummary(result);
  nlohmann::json json = triangulation::AdjustmentToJson(result);
  json["command"] = "calibrate";
  json["valid"] = result.valid;
  json["invalid_reasons"] = result.invalid_reasons;
  nlohmann::json cal =
      triangulation::CalibrationToJson(run, budget_table, budget.radii_mm, camera.c_mm());
  cal["method"] = method;
  cal["camera"] = {{"id", camera_id},
                   {"file", r.camera},
                   {"pixel_size_mm", camera.pixel_size_mm},
                   {"format_px", {camera.width_px, camera.height_px}}};
  cal["model"] = std::string(calib::CameraModelName(model));
  for (const auto& q : budget_table) outcome.printed += "  " + q.statement + "\n";
  AddStabilityWarnings(run.stability, &json);
  BesideRun beside;
  if (beside_model != model) {
    beside = CalibrateBeside(project, camera_id, camera, beside_model, options, &outcome.printed);
    cal["beside"] = beside.json;
  }
  if (beside_model == calib::OpenCvModel::kId && board_marks)
    cal["opencv"] = OpenCvBeside(detected, camera, &outcome.printed);
  cal["rms_px"] = RmsPx(result);
  if (!r.write_camera.empty()) {
    const nlohmann::json written =
        WriteCameraOf(r, camera, beside_model != model ? &beside : nullptr, result, &outcome);
    if (!written.is_null()) cal["camera_written"] = written;
  }
  json["calibration"] = cal;
  for (const auto& reason : result.invalid_reasons)
    outcome.errors += "calibrate: not valid: " + reason + "\n";
  outcome.doc = std::move(json);
  outcome.valid = result.valid && run.stability.agree;
  return outcome;
}

}  // namespace aerocal::tools
