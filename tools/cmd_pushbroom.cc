// aerocal pushbroom calibrate: calibration of a line (pushbroom) camera from cloud control points
// (triangulation/pushbroom/line_calibration.h, module README).
#include <cstdio>
#include <filesystem>

#include "calib/camera/line_camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "tools/command_registry.h"
#include "triangulation/block/block_io.h"
#include "triangulation/pushbroom/line_calibration.h"

namespace aerocal::tools {
namespace {

struct CalibrateArgs {
  std::string camera, pos, observations, points, out, write_camera, lines_csv;
  double sigma_px = 0.3;
  std::string degree = "auto";
  std::string datum = "reference";
  std::string pos_prior = "on";
  triangulation::LineCalibrationOptions options;
};

int RunCalibrate(CalibrateArgs& a) {
  CheckOutputFile(a.out, "--out");
  if (!a.write_camera.empty()) CheckOutputFile(a.write_camera, "--write-camera");
  if (!a.lines_csv.empty()) CheckOutputFile(a.lines_csv, "--lines");
  auto& o = a.options;
  if (a.degree != "auto") {
    const auto d = ParseDouble(a.degree);
    if (!d || *d != std::floor(*d)) throw ConfigError("--degree must be auto or 0 .. 5 (got '" + a.degree + "')");
    o.degree = int(*d);
  }
  if (a.datum != "reference" && a.datum != "none")
    throw ConfigError("--datum must be reference or none (got '" + a.datum + "')");
  o.reference_datum = a.datum == "reference";
  if (a.pos_prior != "on" && a.pos_prior != "off")
    throw ConfigError("--pos-prior must be on or off (got '" + a.pos_prior + "')");
  o.pos_prior = a.pos_prior == "on";
  o.Validate();
  const calib::LineCamera camera = calib::ReadLineCamera(a.camera);
  const auto pos = triangulation::PosTrajectory::Read(a.pos);
  const auto observations = triangulation::ReadLineObservations(a.observations, a.sigma_px);
  const auto points = triangulation::ReadPoints(a.points);
  const auto result =
      triangulation::CalibrateLineCamera(camera, pos, observations, points, o, a.observations);
  WriteFileAtomically(a.out, triangulation::LineCalibrationToJson(result));
  if (!a.lines_csv.empty()) WriteFileAtomically(a.lines_csv, triangulation::LineCorrectionsToCsv(result));
  if (!a.write_camera.empty() && result.valid) calib::WriteLineCamera(a.write_camera, result.camera);
  std::printf("pushbroom calibration: %d observations of %d control points, sigma0 %.3f (%.3f px), "
              "redundancy %d, %s\n",
              result.n_observations, result.n_control, result.report.sigma0, result.sigma0_px,
              result.report.redundancy, result.report.converged ? "converged" : "NOT converged");
  for (const auto& s : result.subcameras)
    std::printf("  %-4s detectors %d..%d: %d obs, degree x %d y %d, RMS across %.3f -> %.3f px, "
                "along %.3f -> %.3f px\n",
                s.id.c_str(), s.first, s.last, s.n, s.degree_x, s.degree_y, s.across_before_px,
                s.across_after_px, s.along_before_px, s.along_after_px);
  for (const auto& [name, rho] : result.correlations)
    std::printf("  correlation %s: %.4f\n", name.c_str(), rho);
  for (const auto& w : result.warnings)
    std::fprintf(stderr, "warning: %s (%s): %s\n", w.name.c_str(), w.subject.c_str(), w.message.c_str());
  if (!a.write_camera.empty() && !result.valid)
    std::fprintf(stderr, "warning: no camera written to %s: the result cannot be trusted\n",
                 a.write_camera.c_str());
  return result.valid && result.report.converged ? kExitOk : kExitNotConverged;
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto args = std::make_shared<CalibrateArgs>();
  auto& o = args->options;
  CLI::App* cal = app.add_subcommand(
      "calibrate",
      "Per-line EO corrections (cubic B-spline) and per-detector calibration (polynomial per "
      "sub-camera) of a line camera from control points");
  cal->option_defaults()->always_capture_default();
  cal->add_option("--camera", args->camera, "Line camera file (YAML with a line section)")->required();
  cal->add_option("--pos", args->pos, "pos.csv: line,time_s,X,Y,Z,omega,phi,kappa[,sigmas]")->required();
  cal->add_option("--observations", args->observations,
                  "observations.csv: point,col,row[,sigma_px] (col = detector, row = scan line)")
      ->required();
  cal->add_option("--points", args->points, "points.csv: control points with sX,sY,sZ (others ignored)")
      ->required();
  cal->add_option("--out", args->out, "result.json")->required();
  cal->add_option("--write-camera", args->write_camera,
                  "The updated camera file (written only when the result is valid)");
  cal->add_option("--lines", args->lines_csv, "Per-line corrections with sigmas (CSV)");
  cal->add_option("--sigma-px", args->sigma_px, "Image sigma where observations.csv gives none, px");
  cal->add_option("--node-spacing", o.node_spacing_lines, "Spline nodes every N lines, >= 1");
  cal->add_option("--degree", args->degree, "Detector polynomial degree: auto (Wald test) or 0 .. 5");
  cal->add_option("--max-degree", o.max_degree, "Highest degree the test starts from, 0 .. 5");
  cal->add_option("--degree-alpha", o.degree_test_alpha, "Significance of the degree test, (0, 0.5)");
  cal->add_option("--datum", args->datum,
                  "reference: the reference sub-camera's constant and linear terms are fixed "
                  "(trajectory takes them) | none: all free (reported ill-posed)");
  cal->add_option("--reference", o.reference_subcamera, "Reference sub-camera index (-1: the middle one)");
  cal->add_flag("--free-c", o.free_c, "Estimate the principal distance (nearly a scale of the table)");
  cal->add_option("--pos-prior", args->pos_prior, "on | off: the POS sigmas as priors on the spline nodes");
  cal->add_option("--pos-sigma-m", o.pos_sigma_m, "POS position sigma where pos.csv gives none, m");
  cal->add_option("--pos-sigma-deg", o.pos_sigma_deg, "POS attitude sigma where pos.csv gives none, deg");
  cal->add_option("--min-per-segment", o.min_observations_per_segment,
                  "Fewer observations between two nodes: warning few_points_per_line");
  return [args, cal] {
    if (cal->parsed()) return RunCalibrate(*args);
    return kExitInternal;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(pushbroom, "pushbroom",
                         "Line (pushbroom) cameras: calibration from cloud control points", Setup);

}  // namespace aerocal::tools
