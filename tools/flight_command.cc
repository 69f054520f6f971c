#include "tools/flight_command.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/result_file.h"
#include "tools/camera_formats.h"
#include "tools/certificate_writer.h"
#include "tools/command_registry.h"
#include "tools/dynamic_resolution.h"
#include "tools/observation_tables.h"
#include "tools/option_ranges.h"
#include "tools/output_set.h"
#include "tools/python_script.h"
#include "tools/suspect_effect_option.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/joint/joint_adjustment.h"
#include "triangulation/workflow/flight_workflow.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace aerocal::tools {

void AddFlightOptions(CLI::App& app, const std::shared_ptr<FlightArgs>& args) {
  app.add_option("--camera", args->options.camera_file, "Camera file (YAML) used by every step")
      ->required();
  app.add_option(
         "--data",
         args->options.data_folder,
         "Flight folder: project.yaml (virtual-image observations), optional project_subimage.yaml "
         "(raw sub-image observations) and the stitching measurements the project names")
      ->required();
  app.add_option(
         "--out", args->out, "Output folder: result.json, report.html, camera_calibrated.yaml")
      ->required();
  app.add_option(
      "--base",
      args->base,
      "Base sub-images holding the datum of the focal plane (default: reference points)");
  app.add_option("--stitch-sigma-px",
                 args->options.stitch_sigma_px,
                 "Stitching sigma where the file has none, px")
      ->check(PositiveUpTo(100));
  app.add_flag(
      "--no-joint",
      [args](std::int64_t) { args->options.joint = false; },
      "Skip the joint adjustment");
  app.add_option("--joint-model",
                 args->joint_model,
                 "Mapping model of the joint adjustment: translation | conformal | affine | "
                 "projective | auto "
                 "(the model the flight's stitching F test chose)")
      ->capture_default_str();
  app.add_option("--self-calibration",
                 args->self_calibration,
                 "Interior parameters of the self-calibration: auto (default: those of the "
                 "10-parameter model that this block determines and that are significant, each "
                 "held one named with the reason, self_calibration_choice), all, or a list such "
                 "as c,x0,y0,K1,K2")
      ->capture_default_str();
  AddSuspectEffectOption(app, &args->options.suspect_effect_limit);
  app.add_flag("--no-report", args->no_report, "Write result.json only (no report.html)");
  app.add_flag("--residuals-csv",
               args->residuals_csv,
               "Write each adjustment's per-observation residual table as "
               "residuals_<adjustment>.csv and the stitching frames' as residuals_stitching.csv "
               "beside result.json (named there with their SHA-256) instead of inside it: a big "
               "flight's result.json stays small");
  app.add_option(
      "--camera-format",
      args->camera_format,
      "Also write the calibrated camera as camera_calibrated.FORMAT in another tool's format (" +
          CameraFormatNames() + "), converted with its residual printed");
  app.add_flag("--certificate",
               args->certificate,
               "Also write the certificate of the in-flight calibration (OUT/certificate/: "
               "certificate.json, .html, .pdf; its budget as `aerocal certificate` of "
               "result.json gives it); only for a valid flight");
  app.add_option("--lab", args->lab, "Lab YAML of the certificate (as `aerocal certificate --lab`)")
      ->needs("--certificate");
  app.add_option(
      "--quality",
      args->quality,
      "Results of `aerocal quality mtf|bars|star` on this flight's images: the dynamic image "
      "resolution section of result.json and report.html (and of the certificate, as `aerocal "
      "certificate --quality`); repeatable");
}

void PrepareFlight(FlightArgs* args) {
  CheckOutputFolder(args->out, "--out");
  if (args->certificate) ReadCertificateLab(args->lab);  // a bad lab file before the flight runs
  for (const auto& path : args->quality)                 // and a file that is no quality result
    ReadResult(
        path, {"quality_mtf", "quality_bars", "quality_star"}, "`aerocal quality` (--quality)");
  if (!args->camera_format.empty()) FindCameraFormat(args->camera_format, "--camera-format");
  args->options.base_ids = SplitCommaList(args->base);
  // Every --base id names a sub-image of the camera (the stitching step would otherwise fail
  // inside the workflow and the flight go on without it).
  if (!args->options.base_ids.empty()) {
    const calib::Camera camera = calib::ReadCamera(args->options.camera_file);
    std::string known;
    for (const auto& s : camera.subimages) known += (known.empty() ? "" : ", ") + s.id;
    for (const auto& id : args->options.base_ids)
      if (std::none_of(camera.subimages.begin(),
                       camera.subimages.end(),
                       [&](const calib::SubimageMapping& s) { return s.id == id; }))
        throw ConfigError("--base: sub-image '" + id + "' is not in " + args->options.camera_file +
                          " (sub-images: " + (known.empty() ? "none" : known) + ")");
  }
  args->options.joint_model = triangulation::ParseJointModel(args->joint_model);
  args->options.choose_free_set = args->self_calibration == "auto";
  if (!args->options.choose_free_set) {
    args->options.free_interior = triangulation::ParseSelfCalibration(args->self_calibration);
    if (args->options.free_interior.empty())
      throw ConfigError(
          "--self-calibration none: flight calibrates the camera (use `aerocal "
          "adjust` for a conventional run alone)");
  }
}

int RunFlight(const FlightArgs& args) {
  // The workflow's five steps, then the report (its figures take tens of seconds on a big flight).
  Progress progress("flight", args.no_report ? 5 : 6);
  const auto result = triangulation::RunFlightWorkflow(args.options, &progress);
  namespace fs = std::filesystem;
  for (const auto& line : result.summary) std::printf("%s\n", line.c_str());
  for (const auto& [step, reason] : result.failures)
    std::fprintf(stderr, "flight: step %s failed: %s\n", step.c_str(), reason.c_str());
  if (!result.valid) std::fprintf(stderr, "flight: no calibrated camera written\n");
  // result.json, the calibrated camera(s), report.html and certificate/ are one set
  // (tools/output_set.h): staged in OUT, moved into place only when every part was written, so
  // a failing report or certificate replaces nothing of the previous flight in OUT.
  OutputSet set(args.out);
  const std::string camera_name = "camera_calibrated.yaml";
  const std::string format_name = "camera_calibrated." + args.camera_format;
  std::vector<std::string> parts = {"result.json"}, obsolete;
  const std::string json_path = set.Staged("result.json");
  nlohmann::json document = result.document;
  document["aerocal_version"] = AEROCAL_VERSION;
  // The resolution targets' results, as the certificate has them, for report.html (issue 36).
  if (!args.quality.empty())
    document["dynamic_image_resolution"] = DynamicResolutionJson(args.quality);
  // The residual tables beside result.json, or none (a previous run's would not describe this).
  const std::vector<std::string> tables = args.residuals_csv
                                              ? SplitResidualTables(&document, set.staging())
                                              : std::vector<std::string>{};
  parts.insert(parts.end(), tables.begin(), tables.end());
  obsolete = ResidualTablesNotWritten(tables);
  WriteResult(json_path, "flight", document);
  // A calibrated camera is written only for a valid flight: a file that exists is one the next
  // flight may use (an old one in the folder is removed, so it cannot pass for this run's).
  (result.valid ? parts : obsolete).push_back(camera_name);
  if (result.valid) calib::WriteCamera(set.Staged(camera_name), result.calibrated_camera);
  if (!args.camera_format.empty()) {
    (result.valid ? parts : obsolete).push_back(format_name);
    if (result.valid)
      WriteCameraInFormat(set.Staged(format_name), result.calibrated_camera, args.camera_format);
  }
  // A report or certificate of an earlier flight left beside this result.json would not
  // describe it: parts this run does not write are removed with the commit.
  if (args.no_report) obsolete.insert(obsolete.end(), {"report.html", "report.pdf"});
  if (!args.no_report) {
    const char* env = std::getenv("AEROCAL_REPORT_SCRIPT");
    const std::string script = env ? env : AEROCAL_REPORT_SCRIPT;
    const std::string html = set.Staged("report.html"), pdf = set.Staged("report.pdf");
    progress.Stage("report");
    if (!RunPythonScript(script, {json_path, html, pdf})) {
      std::fprintf(stderr,
                   "error: the report could not be written (%s); nothing written, the "
                   "previous flight in %s is left as it was\n",
                   PythonCommandLine(script, {json_path, html, pdf}).c_str(),
                   args.out.c_str());
      return kExitInternal;
    }
    progress.Advance();
    parts.push_back("report.html");
    // report.pdf: the same page typeset, where weasyprint is installed (tools/report/README.md).
    (std::filesystem::exists(pdf) ? parts : obsolete).push_back("report.pdf");
  }
  int certificate_code = kExitOk;
  if (args.certificate && result.valid) {
    CertificateArgs certificate;
    certificate.result = json_path;
    certificate.lab = args.lab;
    certificate.out = set.Staged("certificate");
    certificate.result_name = set.Final("result.json");
    certificate.out_name = set.Final("certificate");
    certificate.no_render = args.no_report;
    certificate.quality = args.quality;
    certificate_code = WriteCertificate(certificate);
    if (certificate_code == kExitInternal) {
      std::fprintf(stderr,
                   "error: nothing written, the previous flight in %s is left as it was\n",
                   args.out.c_str());
      return certificate_code;
    }
    parts.push_back("certificate");
  } else {
    if (args.certificate)
      std::fprintf(stderr, "flight: no certificate written (the flight is not valid)\n");
    obsolete.push_back("certificate");
  }
  set.Commit(parts, obsolete);
  if (!args.no_report) std::printf("report: %s\n", set.Final("report.html").c_str());
  if (certificate_code != kExitOk) return certificate_code;
  return result.converged && result.valid ? kExitOk : kExitNotConverged;
}

}  // namespace aerocal::tools
