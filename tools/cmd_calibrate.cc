// aerocal calibrate: camera calibration from a test field (observations.csv + points.csv) or a
// planar board detected in images, on the existing self-calibrating adjustment
// (triangulation/calibration); or from known directions (--directions: calibrate_directions.cc).
// Parsing, loading, detecting, calling the library, writing results.
#include "calib/camera/camera_io.h"
#include "calib/camera/convert_camera.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "calib/core/string_printf.h"
#include "tools/board_detection.h"
#include "tools/calibrate_directions.h"
#include "tools/calibrate_models.h"
#include "tools/camera_formats.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/suspect_effect_option.h"
#include "triangulation/block/block_io.h"
#include "triangulation/calibration/calibration.h"
#include "triangulation/calibration/calibration_json.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

namespace aerocal::tools {
namespace {

using triangulation::AdjustmentResult;

// Board points: design coordinates; the default sigma stands for the print / machining accuracy.
constexpr double kDefaultBoardSigmaMm = 0.01;

// Image -> (group, the line that put it there), from either source of groups.
using GroupLines = std::map<std::string, std::pair<std::string, int>>;

// The checks both sources share, at the line that breaks them: every image is observed, each group
// holds two images or more, and there are two groups or more (the stability test compares groups).
std::map<std::string, std::string> CheckedGroups(const GroupLines& lines, const std::string& file,
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
      ThrowInputError({file, g.second}, "group " + group + " has " + std::to_string(g.first) +
                                            " image (a group needs two or more)");
  if (groups.size() < 2)
    ThrowInputError({file, 0}, std::to_string(groups.size()) +
                                   " group(s): the stability test needs two groups or more");
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

CommandRun SetupCalibrate(CLI::App& app) {
  struct Args {
    std::string camera, observations, points, images, board, directions, groups, budget, out, write_marks;
    std::string write_camera, camera_format = "aerocal";
    std::string self_calibration;  // default: the model's (DefaultSelfCalibration)
    std::string model;             // default: the camera file's
    double sigma_px = 0.5, board_sigma_mm = kDefaultBoardSigmaMm;
    std::vector<double> radii_mm;
    bool no_snooping = false, no_closed_form = false;
    double suspect_effect_limit = triangulation::AdjustOptions{}.suspect_effect_limit;
  };
  auto args = std::make_shared<Args>();
  app.add_option("--camera", args->camera,
                 "Camera file (FORMATS.md): pixel size, format and an approximate c")
      ->required();
  app.add_option("--observations", args->observations,
                 "Test field / target marks: observations.csv (image,point,col,row[,sigma_px])");
  app.add_option("--points", args->points,
                 "Test field / target points: points.csv (role control; check points are not "
                 "used, only compared)");
  app.add_option("--images", args->images, "Board images: a glob such as 'data/left*.jpg'");
  app.add_option("--board", args->board,
                 "Board of --images: chessboard|circles|acircles:COLSxROWS:SPACING_MM, e.g. "
                 "chessboard:9x6:25 (inner corners)");
  app.add_option("--directions", args->directions,
                 "Laboratory calibration from known directions: a collimator array or a goniometer "
                 "sequence (CSV target,col,row,... of docs/formats.md 'Directions file')");
  app.add_option("--self-calibration", args->self_calibration,
                 "Interior parameters calibrated, names of the camera file's model: all, or a "
                 "list such as c,x0,y0,K1,K2,K3,P1,P2 (default of brown_fraser_10; opencv: "
                 "fx,fy,cx,cy,k1,k2,p1,p2,k3; another model: all)");
  app.add_option("--model", args->model,
                 "The camera is calibrated in the camera file's model (any registered model); "
                 "--model also calibrates it in this model, in the same bundle adjustment, side by "
                 "side: brown10 (the 10-parameter model), opencv (fx, fy, cx, cy, k1, k2, p1, p2, "
                 "k3; with --images also cv::calibrateCamera on the same marks) or a registered "
                 "name (" + calib::CameraModelNames() + ")");
  app.add_option("--groups", args->groups,
                 "Image groups: CSV image,group (or a group column in observations.csv); each group "
                 "is calibrated too and the stability over the groups tested (chi-square, 5 %)");
  app.add_option("--budget", args->budget,
                 "Uncertainty budget options (YAML: radii_mm, target_radius_mm, components)");
  app.add_option("--radii-mm", args->radii_mm,
                 "Radii of the certified distortion values, mm (default: 1/4 .. 4/4 of the half "
                 "diagonal)")
      ->check(PositiveUpTo(1e4));
  app.add_option("--sigma-px", args->sigma_px,
                 "Image sigma where observations.csv or the directions file has no sigma_px, and of "
                 "detected marks, px")
      ->check(PositiveUpTo(100));
  // Options of the test field / board only: refused by name with --directions.
  std::vector<CLI::Option*> field_only = {app.get_option("--groups")};
  field_only.push_back(app.add_option("--board-sigma-mm", args->board_sigma_mm,
                                      "Sigma of the board's design coordinates (print accuracy), mm")
                           ->check(PositiveUpTo(100)));
  field_only.push_back(app.add_flag("--no-snooping", args->no_snooping, "Do not test for gross errors"));
  AddSuspectEffectOption(app, &args->suspect_effect_limit);
  field_only.push_back(app.get_option("--suspect-effect-limit"));
  field_only.push_back(app.add_flag("--no-closed-form", args->no_closed_form,
                                    "Planar target: start from the camera file's c, not Zhang's closed form"));
  field_only.push_back(app.add_option("--write-marks", args->write_marks,
                                      "Write the detected marks as DIR/observations.csv and DIR/points.csv"));
  app.add_option("--out", args->out, "Output file: the result JSON (keys of `adjust` plus `calibration`)")
      ->required();
  app.add_option("--write-camera", args->write_camera,
                 "Write the calibrated camera (only when the result is valid)");
  app.add_option("--camera-format", args->camera_format,
                 "Format of --write-camera: " + CameraFormatNames() +
                     " (converted into the format's model where it differs, with its residual)");
  return [args, field_only]() {
    const bool field = !args->observations.empty() || !args->points.empty();
    const bool board = !args->images.empty() || !args->board.empty();
    if (!args->directions.empty()) {
      if (field || board)
        throw ConfigError("--directions: give either --directions, or --observations and --points, or "
                          "--images and --board");
      for (const CLI::Option* o : field_only)
        if (o->count() > 0)
          throw ConfigError(o->get_name() + ": not an option of a direction calibration (--directions)");
      return CalibrateFromDirectionsFile({args->camera, args->directions, args->budget, args->out,
                                          args->write_camera, args->camera_format, args->self_calibration,
                                          args->model, args->sigma_px, args->radii_mm});
    }
    if (field == board)
      throw ConfigError("give either --observations and --points, or --images and --board, or --directions");
    if (field && (args->observations.empty() || args->points.empty()))
      throw ConfigError("--observations and --points go together");
    if (board && (args->images.empty() || args->board.empty()))
      throw ConfigError("--images and --board go together");
    const calib::Camera file_camera = calib::ReadCamera(args->camera, calib::CameraModels::kAny);
    const calib::CameraModelId model = file_camera.model;
    const calib::CameraModelId beside_model =
        args->model.empty() ? model : ModelOfOption(args->model);
    triangulation::CalibrateOptions options;
    options.adjust.free_interior = triangulation::ParseSelfCalibration(
        args->self_calibration.empty() ? DefaultSelfCalibration(model) : args->self_calibration,
        model);
    if (options.adjust.free_interior.empty())
      throw ConfigError("--self-calibration: calibrate needs at least one parameter (got none)");
    options.adjust.data_snooping = !args->no_snooping;
    options.adjust.suspect_effect_limit = args->suspect_effect_limit;
    options.closed_form_c = !args->no_closed_form;
    options.adjust.Validate();
    CheckOutputFile(args->out, "--out");
    if (!args->write_marks.empty()) CheckOutputFolder(args->write_marks, "--write-marks");
    if (!args->write_camera.empty()) CheckOutputFile(args->write_camera, "--write-camera");
    FindCameraFormat(args->camera_format, "--camera-format");
    triangulation::BudgetOptions budget;
    if (!args->budget.empty()) budget = triangulation::ReadBudgetOptions(args->budget);
    if (!args->radii_mm.empty()) budget.radii_mm = args->radii_mm;

    const calib::Camera& camera = file_camera;
    triangulation::Project project;
    const std::string camera_id = camera.name.empty() ? "cam1" : camera.name;
    project.cameras[camera_id] = camera;
    project.camera_files[camera_id] = args->camera;
    nlohmann::json method;
    DetectedBoards detected;
    BoardSpec spec;
    if (board) {
      spec = ParseBoard(args->board, "--board");
      detected = DetectBoards(args->images, spec, args->sigma_px, args->board_sigma_mm);
      if (detected.width_px != camera.width_px || detected.height_px != camera.height_px)
        throw InputError(StringPrintf("%s: format_px is %d x %d, the images are %d x %d px",
                                      args->camera.c_str(), camera.width_px, camera.height_px,
                                      detected.width_px, detected.height_px));
      project.observations = detected.observations;
      project.points = detected.points;
      project.path = project.observations_file = args->images;
      for (const auto& path : detected.not_detected)
        std::printf("warning: board not found in %s (image left out)\n", path.c_str());
      method = {{"kind", "planar target"},
                {"board", spec.kind},
                {"columns", spec.columns},
                {"rows", spec.rows},
                {"spacing_mm", spec.square_mm},
                {"board_sigma_mm", args->board_sigma_mm},
                {"images", args->images},
                {"detected", detected.image_paths},
                {"not_detected", detected.not_detected},
                {"detector", spec.kind == "chessboard"
                                 ? "cv::findChessboardCorners + cv::cornerSubPix (11 x 11, 1e-4 px)"
                                 : "cv::findCirclesGrid"}};
    } else {
      project.observations = triangulation::ReadObservations(args->observations, args->sigma_px);
      project.points = triangulation::ReadPoints(args->points);
      project.path = args->observations;
      project.observations_file = args->observations;
      project.points_file = args->points;
      method = {{"kind", "test field"},
                {"observations", args->observations},
                {"points", args->points}};
    }
    // Cross-file checks of the block readers, with one exposure per observed image.
    {
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
    std::set<std::string> observed;
    for (const auto& o : project.observations) observed.insert(o.image);
    std::map<std::string, std::string> groups;
    if (!args->groups.empty()) groups = ReadGroups(args->groups, observed);
    if (field) {
      const auto from_column = GroupsFromObservations(args->observations, observed);
      if (!from_column.empty() && !args->groups.empty())
        throw ConfigError("--groups: " + args->observations + " has a group column already (give one)");
      if (!from_column.empty()) groups = from_column;
    }
    if (budget.radii_mm.empty()) {
      const double half_diagonal =
          0.5 * camera.pixel_size_mm * std::hypot(camera.width_px, camera.height_px);
      for (int i = 1; i <= 4; ++i) budget.radii_mm.push_back(std::round(half_diagonal * i / 4 * 10) / 10);
    }
    if (!args->write_marks.empty() && board) {
      triangulation::WriteObservations(args->write_marks + "/observations.csv", project.observations);
      triangulation::WritePoints(args->write_marks + "/points.csv", project.points);
    }

    const triangulation::CalibrationRun run = triangulation::Calibrate(project, options, groups);
    const auto budget_table = triangulation::UncertaintyBudget(run, run.project, budget);
    const AdjustmentResult& r = run.all.result;
    std::printf("%s", triangulation::FormatSummary(r).c_str());

    nlohmann::json json = triangulation::AdjustmentToJson(r);
    json["command"] = "calibrate";
    json["valid"] = r.valid;
    json["invalid_reasons"] = r.invalid_reasons;
    nlohmann::json cal = triangulation::CalibrationToJson(run, budget_table, budget.radii_mm,
                                                          file_camera.c_mm());
    cal["method"] = method;
    cal["camera"] = {{"id", camera_id},
                     {"file", args->camera},
                     {"pixel_size_mm", camera.pixel_size_mm},
                     {"format_px", {camera.width_px, camera.height_px}}};
    cal["model"] = std::string(calib::CameraModelName(model));
    for (const auto& q : budget_table) std::printf("  %s\n", q.statement.c_str());
    AddStabilityWarnings(run.stability, &json);
    // The --model estimate of this run: what --write-camera writes when --model is given.
    std::optional<calib::Camera> beside_camera;
    std::optional<triangulation::CameraEstimate> beside_estimate;
    if (beside_model != model) {
      // The same marks calibrated in --model, started from the camera file's values converted.
      triangulation::CalibrateOptions beside = options;
      beside.adjust.free_interior = triangulation::ParseSelfCalibration(
          DefaultSelfCalibration(beside_model), beside_model);
      beside.control_propagation = false;
      triangulation::Project in_model = project;
      in_model.cameras[camera_id] =
          StartInModel(camera, beside_model, beside.adjust.free_interior);
      const triangulation::CalibrationRun other = triangulation::Calibrate(in_model, beside, {});
      const AdjustmentResult& o = other.all.result;
      nlohmann::json b = triangulation::CalibrationRunToJson(o);
      b["model"] = std::string(calib::CameraModelName(beside_model));
      b["self_calibration"] = beside.adjust.free_interior;
      b["rms_px"] = RmsPx(o);
      b["seconds"] = o.solve.seconds;
      std::printf("beside, in model %s: sigma0 %.4f, RMS %.4f px%s\n",
                  std::string(calib::CameraModelName(beside_model)).c_str(), o.sigma0, RmsPx(o),
                  o.valid ? "" : " (not valid)");
      cal["beside"] = b;
      if (o.valid && !o.cameras.empty()) {
        beside_camera = triangulation::UpdatedCamera(in_model.cameras[camera_id], o.cameras[0]);
        beside_estimate = o.cameras[0];
      }
    }
    if (beside_model == calib::OpenCvModel::kId && board) {
      const OpenCvCalibration cv = CalibrateWithOpenCv(detected);
      const double p = camera.pixel_size_mm;
      cal["opencv"] = {
          {"function", "cv::calibrateCamera (flags 0: fx, fy, cx, cy, k1, k2, p1, p2, k3)"},
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
          {"equivalent", {{"c", 0.5 * (cv.fx + cv.fy) * p},
                          {"x0", (cv.cx - 0.5 * (camera.width_px - 1)) * p},
                          {"y0", -(cv.cy - 0.5 * (camera.height_px - 1)) * p}}}};
      std::printf("cv::calibrateCamera: RMS %.4f px, fx %.4f fy %.4f cx %.4f cy %.4f (%.3f s)\n",
                  cv.rms_px, cv.fx, cv.fy, cv.cx, cv.cy, cv.seconds);
    }
    cal["rms_px"] = RmsPx(r);
    // The calibrated camera, in the format asked for; only for a valid result (a file that exists
    // is one the next run may use).
    // With --model the model-M estimate of this run is written (issue 29), not a refit of ours.
    if (!args->write_camera.empty() && beside_model != model && beside_camera) {
      const calib::ConversionResult written = WriteCameraInFormat(
          args->write_camera, *beside_camera, args->camera_format, &beside_estimate->sigma);
      cal["camera_written"] = {{"file", args->write_camera},
                               {"format", args->camera_format},
                               {"model", std::string(calib::CameraModelName(beside_model))},
                               {"exact", written.exact},
                               {"residual_px",
                                {{"rms", written.residual.rms_px},
                                 {"max", written.residual.max_px},
                                 {"max_inner80", written.residual.max_inner80_px}}}};
      std::printf("camera (the %s estimate) -> %s (%s)\n",
                  std::string(calib::CameraModelName(beside_model)).c_str(),
                  args->write_camera.c_str(), args->camera_format.c_str());
    } else if (!args->write_camera.empty() && beside_model != model) {
      std::fprintf(stderr, "camera not written: the --model result is not valid\n");
    } else if (!args->write_camera.empty() && r.valid && !r.cameras.empty()) {
      const calib::ConversionResult written = WriteCameraInFormat(
          args->write_camera, triangulation::UpdatedCamera(camera, r.cameras[0]), args->camera_format,
          &r.cameras[0].sigma);
      cal["camera_written"] = {{"file", args->write_camera},
                               {"format", args->camera_format},
                               {"exact", written.exact},
                               {"residual_px",
                                {{"rms", written.residual.rms_px},
                                 {"max", written.residual.max_px},
                                 {"max_inner80", written.residual.max_inner80_px}}}};
      std::printf("camera -> %s (%s)\n", args->write_camera.c_str(), args->camera_format.c_str());
    } else if (!args->write_camera.empty()) {
      std::fprintf(stderr, "camera not written: the result is not valid\n");
    }
    json["calibration"] = cal;
    WriteResult(args->out, "adjust", json);
    for (const auto& reason : r.invalid_reasons)
      std::fprintf(stderr, "calibrate: not valid: %s\n", reason.c_str());
    std::printf("result -> %s\n", args->out.c_str());
    return r.valid && run.stability.agree ? kExitOk : kExitNotConverged;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(calibrate,
                         "calibrate",
                         "Camera calibration from a test field, a planar board or known directions "
                         "(collimator array, goniometer); image-group stability, GUM budget",
                         SetupCalibrate);

}  // namespace aerocal::tools
