// aerocal calibrate: camera calibration from a test field (observations.csv + points.csv) or a
// planar board detected in images, on the existing self-calibrating adjustment
// (triangulation/calibration); or from known directions (--directions: calibrate_directions.cc).
// Options and routing only: the calibration itself is tools/calibrate_request.h (shared with
// Python).
#include "calib/camera/camera_model.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "tools/calibrate_directions.h"
#include "tools/calibrate_request.h"
#include "tools/camera_formats.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/suspect_effect_option.h"

#include <cstdio>

namespace aerocal::tools {
namespace {

// The command's options: the request of a test field or board, or a directions file.
struct CalibrateArgs : CalibrateRequest {
  std::string directions;
};

// The marks (a test field, a board, known directions) and the camera.
void AddCalibrateInputs(CLI::App& app, CalibrateArgs* args) {
  app.add_option("--camera",
                 args->camera,
                 "Camera file (FORMATS.md): pixel size, format and an approximate c")
      ->required();
  app.add_option("--observations",
                 args->observations,
                 "Test field / target marks: observations.csv (image,point,col,row[,sigma_px])");
  app.add_option("--points",
                 args->points,
                 "Test field / target points: points.csv (role control; check points are not "
                 "used, only compared)");
  app.add_option("--images", args->images, "Board images: a glob such as 'data/left*.jpg'");
  app.add_option("--board",
                 args->board,
                 "Board of --images: chessboard|circles|acircles:COLSxROWS:SPACING_MM, e.g. "
                 "chessboard:9x6:25 (inner corners)");
  app.add_option(
      "--directions",
      args->directions,
      "Laboratory calibration from known directions: a collimator array or a goniometer "
      "sequence (CSV target,col,row,... of docs/formats.md 'Directions file'); with a rig file "
      "as --camera, its unit column names each row's head, with a multi-CCD camera file each "
      "row's sub-image (one adjustment)");
}

// What is calibrated and how its uncertainty is stated.
void AddCalibrateModelOptions(CLI::App& app, CalibrateArgs* args) {
  app.add_option("--self-calibration",
                 args->self_calibration,
                 "Interior parameters calibrated, names of the camera file's model: all, or a "
                 "list such as c,x0,y0,K1,K2,K3,P1,P2 (default of brown_fraser_10; opencv: "
                 "fx,fy,cx,cy,k1,k2,p1,p2,k3; another model: all)");
  app.add_option("--model",
                 args->model,
                 "The camera is calibrated in the camera file's model (any registered model); "
                 "--model also calibrates it in this model, in the same bundle adjustment, side by "
                 "side: brown10 (the 10-parameter model), opencv (fx, fy, cx, cy, k1, k2, p1, p2, "
                 "k3; with --images also cv::calibrateCamera on the same marks) or a registered "
                 "name (" +
                     calib::CameraModelNames() + ")");
  app.add_option(
      "--groups",
      args->groups,
      "Image groups: CSV image,group (or a group column in observations.csv); each group "
      "is calibrated too and the stability over the groups tested (chi-square, 5 %)");
  app.add_option("--budget",
                 args->budget,
                 "Uncertainty budget options (YAML: radii_mm, target_radius_mm, "
                 "pixel_size_tolerance_mm, components)");
  app.add_option("--radii-mm",
                 args->radii_mm,
                 "Radii of the certified distortion values, mm (default: 1/4 .. 4/4 of the half "
                 "diagonal)")
      ->check(PositiveUpTo(1e4));
  app.add_option(
         "--sigma-px",
         args->sigma_px,
         "Image sigma where observations.csv or the directions file has no sigma_px, and of "
         "detected marks, px")
      ->check(PositiveUpTo(100));
}

// Options of the test field / board only: refused by name with --directions.
std::vector<CLI::Option*> AddFieldOnlyOptions(CLI::App& app, CalibrateArgs* args) {
  std::vector<CLI::Option*> field_only = {app.get_option("--groups")};
  field_only.push_back(
      app.add_option("--board-sigma-mm",
                     args->board_sigma_mm,
                     "Sigma of the board's design coordinates (print accuracy), mm")
          ->check(PositiveUpTo(100)));
  field_only.push_back(
      app.add_flag("--no-snooping", args->no_snooping, "Do not test for gross errors"));
  AddSuspectEffectOption(app, &args->suspect_effect_limit);
  field_only.push_back(app.get_option("--suspect-effect-limit"));
  field_only.push_back(
      app.add_flag("--no-closed-form",
                   args->no_closed_form,
                   "Planar target: start from the camera file's c, not Zhang's closed form"));
  field_only.push_back(
      app.add_option("--write-marks",
                     args->write_marks,
                     "Write the detected marks as DIR/observations.csv and DIR/points.csv"));
  return field_only;
}

void AddCalibrateOutputs(CLI::App& app, CalibrateArgs* args) {
  app.add_option(
         "--out", args->out, "Output file: the result JSON (keys of `adjust` plus `calibration`)")
      ->required();
  app.add_option("--write-camera",
                 args->write_camera,
                 "Write the calibrated camera (only when the result is valid)");
  app.add_option("--camera-format",
                 args->camera_format,
                 "Format of --write-camera: " + CameraFormatNames() +
                     " (converted into the format's model where it differs, with its residual)");
}

int RunCalibrate(const CalibrateArgs& args, const std::vector<CLI::Option*>& field_only) {
  const bool field = !args.observations.empty() || !args.points.empty();
  const bool board = !args.images.empty() || !args.board.empty();
  if (!args.directions.empty()) {
    if (field || board)
      throw ConfigError(
          "--directions: give either --directions, or --observations and --points, or "
          "--images and --board");
    for (const CLI::Option* o : field_only)
      if (o->count() > 0)
        throw ConfigError(o->get_name() +
                          ": not an option of a direction calibration (--directions)");
    return CalibrateFromDirectionsFile({args.camera,
                                        args.directions,
                                        args.budget,
                                        args.out,
                                        args.write_camera,
                                        args.camera_format,
                                        args.self_calibration,
                                        args.model,
                                        args.sigma_px,
                                        args.radii_mm});
  }
  const CalibrateOutcome outcome = RunCalibration(args);
  std::printf("%s", outcome.printed.c_str());
  std::fprintf(stderr, "%s", outcome.errors.c_str());
  WriteResult(args.out, "adjust", outcome.doc);
  std::printf("result -> %s\n", args.out.c_str());
  return outcome.valid ? kExitOk : kExitNotConverged;
}

CommandRun SetupCalibrate(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  AddCalibrateInputs(app, args.get());
  AddCalibrateModelOptions(app, args.get());
  const std::vector<CLI::Option*> field_only = AddFieldOnlyOptions(app, args.get());
  AddCalibrateOutputs(app, args.get());
  return [args, field_only]() { return RunCalibrate(*args, field_only); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(calibrate,
                         "calibrate",
                         "Camera calibration from a test field, a planar board or known directions "
                         "(collimator array, goniometer); image-group stability, GUM budget",
                         SetupCalibrate);

}  // namespace aerocal::tools
