// aerocal adjust: self-calibrating bundle block adjustment with control and check points
// (triangulation/adjustment). Parsing, loading, calling the library, writing results.
#include "calib/camera/camera_io.h"
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/problem/mounted_block.h"
#include "tools/adjust_joint.h"
#include "tools/camera_formats.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/rig_adjust_run.h"
#include "tools/suspect_effect_option.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/conventional_reference.h"
#include "triangulation/adjustment/self_calibration_choice.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/object_frame.h"
#include "triangulation/sensor/rig_head_camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace aerocal::tools {
namespace {

using triangulation::AdjustmentResult;

// `adjust` of a project with a rig camera file: the rig bundle (tools/rig_adjust_run.h), then
// the result and the rig file written.
int RunRigAdjustment(const RigAdjustRequest& request,
                     const triangulation::AdjustOptions& options,
                     const triangulation::Project& input,
                     const std::string& project_path,
                     const std::string& out,
                     const std::string& write_camera) {
  RigAdjustRun run = RunRigAdjust(request, options, input, project_path);
  std::printf("%s", run.printed.c_str());
  const triangulation::RigAdjustmentResult& result = run.result;
  // As the frame camera: exit 3 and no rig file when the result is not valid.
  return FinishAdjust(result.adjustment, std::move(run.json), out, write_camera, "rig camera", [&] {
    calib::WriteRig(write_camera, triangulation::UpdatedRig(input.rigs.at(result.camera), result));
    std::printf("rig camera %s -> %s\n", result.camera.c_str(), write_camera.c_str());
  });
}

// The camera model of the project's cameras, whose table names --self-calibration's parameters
// (a camera file may be in any registered model: the adjustment works in it).
calib::CameraModelId CamerasModel(const triangulation::Project& project) {
  const calib::CameraModelId model = project.cameras.begin()->second.model;
  for (const auto& [id, camera] : project.cameras)
    if (camera.model != model)
      throw ConfigError("--self-calibration: the project's cameras are in different models (" +
                        std::string(calib::CameraModelName(model)) + ", " + id + " in " +
                        std::string(calib::CameraModelName(camera.model)) +
                        "): self-calibrate them in separate projects");
  return model;
}

// Everything `adjust` reads from its command line.
struct AdjustArgs {
  std::string project, out, write_camera, self_calibration = "none", camera_format = "aerocal";
  bool compare = false, no_snooping = false, no_eo_priors = false, no_interior_sigma = false;
  bool no_robust_start = false;
  double default_sigma_px = 0.5;
  triangulation::AdjustOptions options;
  JointAdjustArgs joint;
  RigAdjustRequest rig;
  // The GNSS/IMU platform over the project YAML's `platform:` (each given option replaces).
  std::vector<double> lever_arm_m, boresight_deg;
  double time_offset_ms = 0.0, lever_arm_sigma_m = 0.0, boresight_sigma_deg = 0.0,
         time_offset_sigma_ms = 0.0;
  std::string lever_arm, boresight, time_offset;  // fixed | free | weighted
};

// The options by topic, in the order --help lists them.

// The project, the outputs and what to estimate.
void AddInputOptions(CLI::App& app, AdjustArgs* args) {
  app.add_option(
         "--project", args->project, "Project YAML (or folder with project.yaml), FORMATS.md")
      ->required();
  app.add_option("--out", args->out, "Output file: the result JSON (written atomically)")
      ->required();
  app.add_option("--self-calibration",
                 args->self_calibration,
                 "Interior parameters to estimate: none (conventional, default), auto (those of "
                 "the model that this block determines and that are significant: held one by one "
                 "with the reason, self_calibration_choice), all, or a list such as c,x0,y0,K1,K2 "
                 "(the names of the camera file's model, e.g. f,cx,cy,k1,k2 for metashape_frame)");
  app.add_flag("--compare",
               args->compare,
               "Run the conventional and the self-calibrating adjustment and compare them "
               "(self-calibration: the --self-calibration list, or all)");
  app.add_option("--write-camera",
                 args->write_camera,
                 "Write the estimated camera file (camera-file YAML) for the next run");
  app.add_option(
      "--camera-format",
      args->camera_format,
      "Format of --write-camera: " + CameraFormatNames() + " (converted, with its residual)");
  app.add_option("--sigma-px",
                 args->default_sigma_px,
                 "Image sigma where observations.csv has no sigma_px, px")
      ->check(PositiveUpTo(100));
}

// Gross errors: data snooping, the robust start and when a result is not valid.
void AddRobustnessOptions(CLI::App& app, AdjustArgs* args) {
  app.add_flag("--no-snooping", args->no_snooping, "Do not test for gross errors");
  app.add_flag("--robust-start",
               args->options.robust_start,
               "Adjust first with a robust (Cauchy) loss, reject the obvious gross errors, then "
               "re-adjust cleanly (large blunders, rough starting values)");
  app.add_flag("--no-robust-start",
               args->no_robust_start,
               "Never start robustly (by default the robust start runs when more than 1 % of the "
               "image components of the first solve are above 10 sigma)");
  app.add_option("--max-rejections",
                 args->options.max_rejections,
                 "Rejection cap of data snooping; reaching it is a warning and exit 3 (default: 10 "
                 "% of the "
                 "tested image observations, at least 100)")
      ->check(PositiveUpTo(1e7));
  app.add_option("--max-sigma0",
                 args->options.max_sigma0,
                 "A result with sigma0 above this is not valid (exit 3)")
      ->check(PositiveUpTo(1e6));
  AddSuspectEffectOption(app, &args->options.suspect_effect_limit);
  app.add_option("--min-redundancy",
                 args->options.min_redundancy,
                 "Redundancy number below which an observation is weakly controlled: reported, "
                 "never rejected")
      ->check(FiniteRange(0.0, 0.999));
  app.add_option("--critical-value",
                 args->options.snooping_critical_value,
                 "Critical |w| of data snooping (0: from alpha = 5 % / n; 1e6: never reject)")
      ->check(FiniteRange(0, 1e9));
}

// The a-priori weights used and the solver.
void AddSolverOptions(CLI::App& app, AdjustArgs* args) {
  app.add_flag("--no-eo-priors",
               args->no_eo_priors,
               "Ignore the GNSS/IMU sigma columns of exposures.csv (starting values only)");
  app.add_flag("--no-interior-sigma",
               args->no_interior_sigma,
               "Ignore the camera file's interior_sigma (unweighted self-calibration)");
  app.add_option("--max-iterations", args->options.solver.max_iterations, "Solver iterations")
      ->check(PositiveUpTo(1e5));
  app.add_option("--threads",
                 args->options.solver.num_threads,
                 "Solver threads (0: all cores); the result is the same bits for every count")
      ->check(FiniteRange(0, 1024));
  app.add_option("--correlation-threshold",
                 args->options.correlation_threshold,
                 "Report parameter pairs correlated above this")
      ->check(FiniteRange(0.0, 1.0));
}

// The GNSS/IMU platform: lever arm, boresight, GNSS time offset.
void AddPlatformOptions(CLI::App& app, AdjustArgs* args) {
  app.add_option("--lever-arm-m",
                 args->lever_arm_m,
                 "GNSS lever arm a (projection centre -> antenna, camera frame), m, \"X,Y,Z\": its "
                 "value (fixed) or start (free, weighted)")
      ->check(FiniteRange(-1000, 1000))
      ->delimiter(',')
      ->expected(3);
  app.add_option("--lever-arm", args->lever_arm, "Lever arm: fixed (default) | free | weighted");
  app.add_option("--lever-arm-sigma-m",
                 args->lever_arm_sigma_m,
                 "Lever arm sigma per axis when weighted, m")
      ->check(PositiveUpTo(1000));
  app.add_option("--boresight-deg",
                 args->boresight_deg,
                 "Boresight misalignment M (IMU attitude = R M^T), omega,phi,kappa deg")
      ->check(FiniteRange(-360, 360))
      ->delimiter(',')
      ->expected(3);
  app.add_option("--boresight", args->boresight, "Boresight: fixed (default) | free | weighted");
  app.add_option("--boresight-sigma-deg",
                 args->boresight_sigma_deg,
                 "Boresight sigma per angle when weighted, deg")
      ->check(PositiveUpTo(180));
  app.add_option(
         "--gnss-time-offset-ms",
         args->time_offset_ms,
         "GNSS time offset dt (GNSS position = antenna at exposure time + dt; needs vX, vY, "
         "vZ in exposures.csv), ms")
      ->check(FiniteRange(-1e4, 1e4));
  app.add_option("--gnss-time-offset",
                 args->time_offset,
                 "GNSS time offset: fixed (default) | free | weighted");
  app.add_option("--gnss-time-offset-sigma-ms",
                 args->time_offset_sigma_ms,
                 "GNSS time offset sigma when weighted, ms")
      ->check(PositiveUpTo(1e4));
}

// The rig bundle (a project whose camera file has a `rig` section): which rig parameters of the
// non-reference heads are estimated. Returns the options (a project without a rig refuses them).
std::vector<CLI::Option*> AddRigOptions(CLI::App& app, AdjustArgs* args) {
  return {
      app.add_option("--rig-mounts",
                     args->rig.mounts,
                     "Rig: mount angles of the non-reference heads: fixed | free (default) | "
                     "weighted (the rig file's mount_sigma_deg)"),
      app.add_option("--rig-lever-arms",
                     args->rig.lever_arms,
                     "Rig: lever arms of the non-reference heads: fixed | free (default) | "
                     "weighted (the rig file's lever_arm_sigma_m)"),
      app.add_option("--rig-increments",
                     args->rig.increments,
                     "Rig: per-exposure attitude increments E_k of the non-reference heads: fixed "
                     "(zero, default) | free | weighted (--rig-increment-sigma-arcsec)"),
      app.add_option("--rig-increment-sigma-arcsec",
                     args->rig.increment_sigma_arcsec,
                     "Rig: sigma of weighted increments around zero, arcsec")
          ->check(PositiveUpTo(36000)),
      app.add_option("--rig-time-offsets",
                     args->rig.time_offsets,
                     "Rig: exposure time offset dT_k of each non-reference head: fixed (zero, "
                     "default) | free | weighted (--rig-time-offset-sigma-ms); needs the velocity "
                     "columns vX,vY,vZ"),
      app.add_option("--rig-time-offset-sigma-ms",
                     args->rig.time_offset_sigma_ms,
                     "Rig: sigma of weighted time offsets around zero, ms")
          ->check(PositiveUpTo(1e4))};
}

// The command line's platform options over the project's `platform:`; true when any was given.
bool ApplyPlatformOptions(const CLI::App& app,
                          const AdjustArgs* args,
                          triangulation::PlatformSpec* p) {
  auto given = [&](const char* name) { return app.count(name) > 0; };
  if (given("--lever-arm-m"))
    p->lever_arm_m =
        Eigen::Vector3d(args->lever_arm_m[0], args->lever_arm_m[1], args->lever_arm_m[2]);
  if (given("--boresight-deg"))
    p->boresight_rad =
        Eigen::Vector3d(args->boresight_deg[0], args->boresight_deg[1], args->boresight_deg[2]) *
        (M_PI / 180.0);
  if (given("--gnss-time-offset-ms")) p->time_offset_s = args->time_offset_ms * 1e-3;
  if (given("--lever-arm")) p->lever_arm = calib::BlockModeOption(args->lever_arm, "--lever-arm");
  if (given("--boresight")) p->boresight = calib::BlockModeOption(args->boresight, "--boresight");
  if (given("--gnss-time-offset"))
    p->time_offset = calib::BlockModeOption(args->time_offset, "--gnss-time-offset");
  if (given("--lever-arm-sigma-m")) p->lever_arm_sigma_m = args->lever_arm_sigma_m;
  if (given("--boresight-sigma-deg"))
    p->boresight_sigma_rad = args->boresight_sigma_deg * M_PI / 180.0;
  if (given("--gnss-time-offset-sigma-ms"))
    p->time_offset_sigma_s = args->time_offset_sigma_ms * 1e-3;
  for (const char* name : {"--lever-arm-m",
                           "--lever-arm",
                           "--lever-arm-sigma-m",
                           "--boresight-deg",
                           "--boresight",
                           "--boresight-sigma-deg",
                           "--gnss-time-offset-ms",
                           "--gnss-time-offset",
                           "--gnss-time-offset-sigma-ms"})
    if (given(name)) {
      p->source = p->source.empty() ? "options" : p->source + " and options";
      triangulation::ValidatePlatform(*p);
      return true;
    }
  return false;
}

// The adjustment of a frame-camera project: one run, or --compare's two, then the result and the
// camera written.
int RunFrameAdjust(const AdjustArgs* args,
                   const triangulation::AdjustOptions& options,
                   const triangulation::Project& input,
                   const triangulation::Project& project,
                   const triangulation::ObjectFrame& frame,
                   bool auto_free,
                   calib::CameraModelId model) {
  // Big blocks take minutes: a progress bar of the adjustment stages (terminal only).
  const int stages =
      (auto_free && !options.free_interior.empty() ? triangulation::AutoFreeSetRounds(options)
                                                   : triangulation::AdjustStages(options)) +
      (args->compare ? triangulation::BlockAdjustment::kRunStages : 0);
  Progress progress("adjust", stages);
  auto run = [&](const std::vector<std::string>& free) {
    auto o = options;
    o.free_interior = free;
    AdjustmentResult r = auto_free && !free.empty()
                             ? triangulation::AdjustWithChosenFreeSet(project, o, {}, &progress)
                             : triangulation::Adjust(project, o, &progress);
    triangulation::ToInputFrame(frame, &r);
    return r;
  };
  nlohmann::json json;
  AdjustmentResult main;
  if (args->compare) {
    const auto self_list = options.free_interior.empty()
                               ? triangulation::ParseSelfCalibration("all", model)
                               : options.free_interior;
    main = run(self_list);
    AdjustmentResult conventional =
        triangulation::AdjustConventionalReference(project, options, main, &progress);
    triangulation::ToInputFrame(frame, &conventional);
    progress.Finish();  // before the tables, so the bar never interleaves with them
    std::printf("%s", triangulation::FormatComparison(conventional, main).c_str());
    json = triangulation::AdjustmentToJson(main);
    json["comparison"] = triangulation::ComparisonToJson(conventional, main);
    json["conventional"] = triangulation::AdjustmentToJson(conventional);
    main.solve.converged = main.solve.converged && conventional.solve.converged;
    for (const auto& reason : conventional.invalid_reasons)
      main.Invalidate("conventional run: " + reason);
  } else {
    main = run(options.free_interior);
    progress.Finish();
    std::printf("%s", triangulation::FormatSummary(main).c_str());
    json = triangulation::AdjustmentToJson(main);
  }
  json["project"] = args->project;
  AddProjectFacts(input, &json);
  // Which adjustment a written camera comes from (as flight's camera_written_from).
  if (!args->write_camera.empty() && main.valid)
    json["camera_written_from"] = {
        {"adjustment", main.free_interior.empty() ? "conventional" : "self_calibration"},
        {"reason",
         main.free_interior.empty()
             ? "the adjustment run (no interior parameter estimated: the camera file's "
               "interior with the adjustment's frame)"
             : "the self-calibrating adjustment (--self-calibration)"}};
  json["valid"] = main.valid;
  json["invalid_reasons"] = main.invalid_reasons;
  // Exit 3 (results written, valid: false) when the run must not be trusted; the camera file
  // is then not written at all.
  return FinishAdjust(main, std::move(json), args->out, args->write_camera, "camera", [&] {
    for (const auto& estimate : main.cameras) {
      const std::string path =
          CameraOutputPath(args->write_camera, estimate.id, main.cameras.size() > 1);
      WriteCameraInFormat(path,
                          triangulation::UpdatedCamera(input.cameras.at(estimate.id), estimate),
                          args->camera_format,
                          &estimate.sigma);
      std::printf("camera %s -> %s\n", estimate.id.c_str(), path.c_str());
    }
  });
}

int RunAdjust(const CLI::App& app,
              const AdjustArgs* args,
              const std::vector<CLI::Option*>& rig_options) {
  auto options = args->options;
  options.data_snooping = !args->no_snooping;
  options.use_eo_priors = !args->no_eo_priors;
  options.auto_robust_start = !args->no_robust_start;
  if (options.robust_start && args->no_robust_start)
    throw ConfigError("--robust-start and --no-robust-start exclude each other");
  options.use_interior_sigma = !args->no_interior_sigma;
  // The names of the 10-parameter model here (the joint adjustment needs it); the plain
  // adjustment reads them again in the model of the project's cameras below.
  const bool other_model_names = !args->joint.Requested();
  const bool auto_free = args->self_calibration == "auto";
  if (auto_free && args->joint.Requested())
    throw ConfigError(
        "--self-calibration auto: not with --joint-stitching (give the list, e.g. "
        "the `self_calibration_choice.chosen` of an auto run)");
  const std::string free_text = auto_free ? "all" : args->self_calibration;
  if (!other_model_names) options.free_interior = triangulation::ParseSelfCalibration(free_text);
  options.Validate();
  CheckOutputFile(args->out, "--out");
  if (!args->write_camera.empty()) CheckOutputFile(args->write_camera, "--write-camera");
  FindCameraFormat(args->camera_format, "--camera-format");
  if (args->joint.Requested() && args->camera_format != "aerocal")
    throw ConfigError(
        "--camera-format: the joint adjustment writes our camera file only (aerocal)");
  if (args->joint.Requested() && args->compare)
    throw ConfigError(
        "--compare and --joint-stitching do not combine (`aerocal flight` runs and compares "
        "both)");
  triangulation::Project input = triangulation::ReadProject(args->project, args->default_sigma_px);
  const bool self_calibrating =
      args->compare || (args->self_calibration != "none" && !args->self_calibration.empty());
  const calib::CameraModelId model =
      self_calibrating ? CamerasModel(input) : calib::Camera::Model::kId;
  if (other_model_names) {
    options.free_interior = triangulation::ParseSelfCalibration(free_text, model);
    options.Validate();
  }
  ApplyPlatformOptions(app, args, &input.platform);
  if (args->joint.Requested())
    return RunJointAdjust(
        args->joint, options, input, args->project, args->out, args->write_camera);
  const triangulation::ObjectFrame frame(input.frame);
  const triangulation::Project project = triangulation::ToAdjustmentFrame(input, frame);
  const bool rig_option_given = std::any_of(
      rig_options.begin(), rig_options.end(), [](const CLI::Option* o) { return o->count() > 0; });
  if (!input.rigs.empty()) {
    CheckRigProject(input, args->project, args->compare, auto_free, options.robust_start);
    return RunRigAdjustment(
        args->rig, options, input, args->project, args->out, args->write_camera);
  }
  if (rig_option_given)
    throw ConfigError(args->project +
                      ": the --rig-* options need a rig camera file (a camera "
                      "file with a rig section)");
  if (!args->write_camera.empty() && options.free_interior.empty() && !args->compare)
    throw ConfigError(
        "--write-camera needs a self-calibrating run (--self-calibration or --compare)");
  // From here the adjustment reads `project` only; of `input` the writers need the file names and
  // the cameras. Its observations, points and exposures (a second copy of the block, about 190 B
  // per observation, docs/measurements/triangulation.md) are freed before the solve.
  std::vector<triangulation::ImageObservation>().swap(input.observations);
  std::vector<triangulation::GroundPoint>().swap(input.points);
  std::vector<triangulation::Exposure>().swap(input.exposures);
  return RunFrameAdjust(args, options, input, project, frame, auto_free, model);
}

CommandRun SetupAdjust(CLI::App& app) {
  auto args = std::make_shared<AdjustArgs>();
  AddInputOptions(app, args.get());
  AddRobustnessOptions(app, args.get());
  AddSolverOptions(app, args.get());
  AddPlatformOptions(app, args.get());
  AddJointAdjustOptions(app, &args->joint);
  const std::vector<CLI::Option*> rig_options = AddRigOptions(app, args.get());
  return [&app, args, rig_options]() { return RunAdjust(app, args.get(), rig_options); };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(
    adjust,
    "adjust",
    "Bundle block adjustment (conventional or self-calibrating) with control and "
    "check points",
    SetupAdjust);

}  // namespace aerocal::tools
