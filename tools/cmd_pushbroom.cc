// aerocal pushbroom calibrate: calibration of a line (pushbroom) camera from cloud control points
// (triangulation/pushbroom/line_calibration.h); aerocal pushbroom control: the cloud control points
// from the line image and oriented reference frame images (cloud_control.h). Module README.
#include "calib/camera/camera_io.h"
#include "calib/camera/line_camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "stitch/image_io/image_io.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/pushbroom_calibrate_run.h"
#include "tools/pushbroom_control_run.h"
#include "triangulation/block/block_io.h"
#include "triangulation/pushbroom/cloud_control.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_plots.h"
#include "triangulation/pushbroom/reference_frames.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace aerocal::tools {
namespace {

struct CalibrateArgs : LineCalibrationRequest {
  std::string out, write_camera, lines_csv, plot;
};

int RunCalibrate(CalibrateArgs& a) {
  CheckOutputFile(a.out, "--out");
  if (!a.write_camera.empty()) CheckOutputFile(a.write_camera, "--write-camera");
  if (!a.lines_csv.empty()) CheckOutputFile(a.lines_csv, "--lines");
  if (!a.plot.empty()) CheckOutputFile(a.plot, "--plot");
  const LineCalibrationRun run = RunLineCalibration(a);
  const auto& result = run.result;
  WriteResult(a.out, "pushbroom", run.json, 1);
  if (!a.lines_csv.empty())
    WriteFileAtomically(a.lines_csv, triangulation::LineCorrectionsToCsv(result));
  if (!a.plot.empty())
    WriteFileAtomically(
        a.plot,
        triangulation::LineCalibrationSvg(result, run.camera.name + " (" + a.observations + ")"));
  if (!a.write_camera.empty() && result.valid)
    calib::WriteLineCamera(a.write_camera, result.camera);
  std::fputs(run.printed.c_str(), stdout);
  std::fputs(run.errors.c_str(), stderr);
  if (!a.write_camera.empty() && !result.valid)
    std::fprintf(stderr,
                 "warning: no camera written to %s: the result cannot be trusted\n",
                 a.write_camera.c_str());
  return run.Ok() ? kExitOk : kExitNotConverged;
}

struct ControlArgs {
  PushbroomControlRequest request;
  std::string out;
  bool write_l1 = false;
  int min_points = 20;
};

int RunControl(ControlArgs& a) {
  CheckOutputFolder(a.out, "--out");
  const PushbroomControlRun run = RunPushbroomControl(a.request);
  const triangulation::CloudControlResult& result = run.result;
  if (run.skipped_exposures > 0)
    std::printf("reference: %d adjusted exposures of %s (%d not used by the adjustment, skipped)\n",
                run.reference_exposures,
                a.request.reference_result.c_str(),
                run.skipped_exposures);
  namespace fs = std::filesystem;
  fs::create_directories(a.out);
  triangulation::WriteLineObservations((fs::path(a.out) / "observations.csv").string(),
                                       result.observations);
  triangulation::WritePoints((fs::path(a.out) / "points.csv").string(), result.points);
  WriteResult((fs::path(a.out) / "control.json").string(), "pushbroom_control", run.document);
  if (a.write_l1) stitch::WriteGrayImage((fs::path(a.out) / "l1.png").string(), result.l1.image);
  std::printf(
      "cloud control: L1 image %d x %d cells of %.3f m at Z = %.2f m, %d interest points, "
      "%d matches, %zu control points (dropped: %d fewer than two matches, %d gross errors, "
      "%d imprecise, %d line outliers; %d single rays removed), median match sigma %.3f px -> %s\n",
      result.l1.grid.width,
      result.l1.grid.height,
      result.l1.grid.gsd_m,
      result.l1.grid.z_m,
      result.n_interest,
      result.n_rays,
      result.points.size(),
      result.n_no_match,
      result.n_gross,
      result.n_imprecise,
      result.n_line_outliers,
      result.n_rays_removed,
      result.median_match_sigma_px,
      a.out.c_str());
  if (int(result.points.size()) < a.min_points) {
    std::fprintf(
        stderr,
        "warning: too_few_control_points: %zu control points (fewer than --min-points %d)\n",
        result.points.size(),
        a.min_points);
    return kExitNotConverged;
  }
  return kExitOk;
}

// `pushbroom calibrate`'s estimation: the spline, the polynomial test, the datum, the POS and
// the mount (boresight, lever arm, time offset).
void AddLineEstimationOptions(CLI::App* cal, CalibrateArgs* args) {
  auto& o = args->options;
  cal->add_option("--node-spacing", o.node_spacing_lines, "Spline nodes every N lines, >= 1")
      ->check(FiniteRange(1, 1e6));
  cal->add_option(
      "--degree", args->degree, "Detector polynomial degree: auto (Wald test) or 0 .. 5");
  cal->add_option("--max-degree", o.max_degree, "Highest degree the test starts from, 0 .. 5")
      ->check(FiniteRange(0, 5));
  cal->add_option(
         "--degree-alpha", o.degree_test_alpha, "Significance of the degree test, (0, 0.5)")
      ->check(FiniteRange(0, 0.5, true));
  cal->add_option("--datum",
                  args->datum,
                  "gauge (default): exactly the rank defect of the problem as configured, on the "
                  "gauge directions of its null space (none with the POS priors on and the "
                  "boresight and lever arm fixed) | reference: the earlier datum, the reference "
                  "sub-camera's Legendre mean and slope per axis held at zero (4 constraints: "
                  "over-constrains, e.g. holds the scale the control determines) | none: no "
                  "datum (an undetermined problem is reported ill-posed)");
  cal->add_option("--reference",
                  o.reference_subcamera,
                  "Sub-camera index carrying the datum (-1: the middle one)")
      ->check(FiniteRange(-1, 1000));
  cal->add_option("--gauge-threshold",
                  o.gauge_threshold,
                  "Relative eigenvalue of the scaled normal matrix below which a direction is a "
                  "gauge freedom, (0, 1e-3]")
      ->check(FiniteRange(0, 1e-3, true));
  cal->add_flag(
      "--free-c", o.free_c, "Estimate the principal distance (nearly a scale of the table)");
  cal->add_option(
      "--pos-prior", args->pos_prior, "on | off: the POS sigmas as priors on the spline nodes");
  cal->add_option("--pos-sigma-m", o.pos_sigma_m, "POS position sigma where pos.csv gives none, m")
      ->check(PositiveUpTo(1000));
  cal->add_option(
         "--pos-sigma-deg", o.pos_sigma_deg, "POS attitude sigma where pos.csv gives none, deg")
      ->check(PositiveUpTo(180));
  cal->add_option("--boresight",
                  args->boresight,
                  "Boresight (the camera file's mount): fixed (default) | free | weighted (around "
                  "the file's values by --boresight-sigma-deg)");
  cal->add_option("--boresight-sigma-deg",
                  args->boresight_sigma_deg,
                  "Sigma of each weighted boresight angle, deg, > 0")
      ->check(PositiveUpTo(180));
  cal->add_option("--lever-arm",
                  args->lever_arm,
                  "Lever arm (the camera file's, body frame): fixed (default) | free | weighted "
                  "(around the file's values by --lever-arm-sigma-m)");
  cal->add_option("--lever-arm-sigma-m",
                  o.lever_arm_sigma_m,
                  "Sigma of each weighted lever-arm component, m, > 0")
      ->check(PositiveUpTo(1000));
  cal->add_flag("--time-offset",
                o.time_offset,
                "Estimate a time offset of the line camera against the POS (shutter / POS "
                "latency, s); determinable only through the POS priors "
                "(time_offset_vs_along_track)");
  cal->add_option("--min-per-segment",
                  o.min_observations_per_segment,
                  "Fewer observations between two nodes: warning few_points_per_line")
      ->check(FiniteRange(0, 1e6));
}

// `pushbroom control`'s L1 rectification, matching and gross-error options.
void AddControlMatchingOptions(CLI::App* ctl, ControlArgs* control_args) {
  auto& c = control_args->request.options;
  ctl->add_option("--mean-height-m", c.mean_height_m, "Height of the L1 rectification plane, m")
      ->check(FiniteRange(-500, 10000));
  ctl->add_option("--gsd-m", c.gsd_m, "L1 cell size, m (0: the POS line spacing)")
      ->check(FiniteRange(0, 1e4));
  ctl->add_option(
         "--map-step", c.map_step_px, "Exact L1 inverse every N cells, bilinear between, 1..64")
      ->check(FiniteRange(1, 64));
  ctl->add_option(
         "--template-half", c.template_half_px, "Half size of the matching template, 3..30 px")
      ->check(FiniteRange(3, 30));
  ctl->add_option("--search-px", c.search_px, "Correlation search radius, L1 cells, 0..100")
      ->check(FiniteRange(0, 100));
  ctl->add_option("--min-correlation", c.min_correlation, "Minimum correlation peak, 0..1")
      ->check(FiniteRange(0, 1));
  ctl->add_option("--max-interest",
                  c.foerstner.max_points,
                  "Strongest Foerstner points kept on the L1 image")
      ->check(FiniteRange(1, 1e6));
  ctl->add_option("--interest-spacing",
                  c.foerstner.suppression_px,
                  "Foerstner non-maximum suppression window (odd), L1 cells")
      ->check(FiniteRange(1, 101));
  ctl->add_option("--interest-weight",
                  c.foerstner.weight_factor,
                  "Foerstner threshold: weight above this times the mean weight")
      ->check(FiniteRange(0, 1000));
  ctl->add_option("--min-match-sigma-px", c.min_match_sigma_px, "Floor of the matching sigma, px")
      ->check(PositiveUpTo(100));
  ctl->add_option(
         "--line-sigma-px", c.line_sigma_px, "Sigma written for the line-image observations, px")
      ->check(PositiveUpTo(100));
  ctl->add_option("--gross-error-alpha", c.gross_error_alpha, "Significance of the misclosure test")
      ->check(FiniteRange(0, 0.5, true));
  ctl->add_option(
         "--max-point-sigma-m", c.max_point_sigma_m, "Drop points less precise than this, m")
      ->check(PositiveUpTo(1e4));
  ctl->add_option(
         "--line-outlier-k",
         c.line_outlier_k,
         "Line-side gross errors: off the smooth misclosure fit by more than k x 1.4826 MAD")
      ->check(PositiveUpTo(1000));
  ctl->add_option("--line-outlier-min-px", c.line_outlier_min_px, "... and by more than this, px")
      ->check(PositiveUpTo(1e4));
  ctl->add_option("--min-points",
                  control_args->min_points,
                  "Fewer control points: warning too_few_control_points, exit 3")
      ->check(FiniteRange(0, 1e6));
  ctl->add_flag("--write-l1", control_args->write_l1, "Also write the L1 image (l1.png)");
}

// `pushbroom calibrate`: its files, then the estimation's options.
CLI::App* AddCalibrate(CLI::App& app, const std::shared_ptr<CalibrateArgs>& args) {
  CLI::App* cal = app.add_subcommand(
      "calibrate",
      "Per-line EO corrections (cubic B-spline) and per-detector calibration (polynomial per "
      "sub-camera) of a line camera from control points");
  cal->option_defaults()->always_capture_default();
  cal->add_option("--camera", args->camera, "Line camera file (YAML with a line section)")
      ->required();
  cal->add_option("--pos", args->pos, "pos.csv: line,time_s,X,Y,Z,omega,phi,kappa[,sigmas]")
      ->required();
  cal->add_option("--observations",
                  args->observations,
                  "observations.csv: point,col,row[,sigma_px] (col = detector, row = scan line)")
      ->required();
  cal->add_option(
         "--points", args->points, "points.csv: control points with sX,sY,sZ (others ignored)")
      ->required();
  cal->add_option("--out", args->out, "Output file: the result JSON")->required();
  cal->add_option("--write-camera",
                  args->write_camera,
                  "The updated camera file (written only when the result is valid)");
  cal->add_option("--lines", args->lines_csv, "Per-line corrections with sigmas (CSV)");
  cal->add_option("--plot",
                  args->plot,
                  "SVG: per sub-camera the errors along and across track against the detector with "
                  "the fitted polynomial and its sigma band");
  cal->add_option("--sigma-px", args->sigma_px, "Image sigma where observations.csv gives none, px")
      ->check(PositiveUpTo(100));
  AddLineEstimationOptions(cal, args.get());
  return cal;
}

// `pushbroom control`: its files, then the rectification's and matching's options.
CLI::App* AddControl(CLI::App& app, const std::shared_ptr<ControlArgs>& control_args) {
  CLI::App* ctl = app.add_subcommand(
      "control",
      "Cloud control points from the line image: L1 rectification onto the mean terrain height, "
      "Foerstner points, matching into oriented reference frame images, forward intersection");
  ctl->option_defaults()->always_capture_default();
  ctl->add_option("--camera", control_args->request.camera, "Nominal line camera file")->required();
  ctl->add_option("--pos", control_args->request.pos, "pos.csv of the line image")->required();
  ctl->add_option("--line-image",
                  control_args->request.line_image,
                  "The line image: row = scan line, column = detector")
      ->required();
  ctl->add_option("--reference-camera",
                  control_args->request.reference_camera,
                  "Camera file of the reference frame images")
      ->required();
  auto* ref_csv =
      ctl->add_option("--reference-exposures",
                      control_args->request.reference_exposures,
                      "exposures.csv with the oriented reference frames (the block result)");
  auto* ref_result = ctl->add_option(
      "--reference-result",
      control_args->request.reference_result,
      "result.json of `aerocal adjust` with the oriented reference frames (instead of "
      "--reference-exposures; its used exposures)");
  ref_csv->excludes(ref_result);
  ctl->add_option("--reference-images",
                  control_args->request.reference_images,
                  "Folder of the reference images (named by their exposure id, .png/.tif/.jpg)")
      ->required();
  ctl->add_option("--out",
                  control_args->out,
                  "Output folder: observations.csv, points.csv, control.json (and l1.png)")
      ->required();
  AddControlMatchingOptions(ctl, control_args.get());
  return ctl;
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto args = std::make_shared<CalibrateArgs>();
  auto control_args = std::make_shared<ControlArgs>();
  CLI::App* cal = AddCalibrate(app, args);
  CLI::App* ctl = AddControl(app, control_args);
  return [args, cal, control_args, ctl] {
    if (ctl->parsed()) return RunControl(*control_args);
    if (cal->parsed()) return RunCalibrate(*args);
    return kExitInternal;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(pushbroom,
                         "pushbroom",
                         "Line (pushbroom) cameras: calibration from cloud control points",
                         Setup);

}  // namespace aerocal::tools
