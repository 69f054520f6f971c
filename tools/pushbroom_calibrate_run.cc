#include "tools/pushbroom_calibrate_run.h"

#include "calib/camera/line_camera_io.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/problem/mounted_block.h"
#include "triangulation/block/block_io.h"

#include <cmath>

namespace aerocal::tools {
namespace {

// The options of the request, each text option parsed and every value checked.
triangulation::LineCalibrationOptions CheckedOptions(const LineCalibrationRequest& a) {
  triangulation::LineCalibrationOptions o = a.options;
  if (a.degree != "auto") {
    const auto d = ParseDouble(a.degree);
    if (!d || *d != std::floor(*d))
      throw ConfigError("--degree must be auto or 0 .. 5 (got '" + a.degree + "')");
    o.degree = int(*d);
  }
  if (a.datum == "gauge")
    o.datum = triangulation::LineDatum::kGauge;
  else if (a.datum == "reference")
    o.datum = triangulation::LineDatum::kReference;
  else if (a.datum == "none")
    o.datum = triangulation::LineDatum::kNone;
  else
    throw ConfigError("--datum must be gauge, reference or none (got '" + a.datum + "')");
  if (a.pos_prior != "on" && a.pos_prior != "off")
    throw ConfigError("--pos-prior must be on or off (got '" + a.pos_prior + "')");
  o.pos_prior = a.pos_prior == "on";
  o.boresight = calib::BlockModeOption(a.boresight, "--boresight");
  o.lever_arm = calib::BlockModeOption(a.lever_arm, "--lever-arm");
  o.boresight_sigma_rad = a.boresight_sigma_deg * M_PI / 180.0;
  o.Validate();
  return o;
}

// The command's summary of a result: sigma0, datum, time offset, sub-cameras, platform, warnings.
void Summarise(const triangulation::LineCalibrationResult& result,
               std::string* printed,
               std::string* errors) {
  *printed += StringPrintf(
      "pushbroom calibration: %d observations of %d control points, sigma0 %.3f (%.3f px), "
      "redundancy %d, %s\n",
      result.n_observations,
      result.n_control,
      result.report.sigma0,
      result.sigma0_px,
      result.report.redundancy,
      result.report.converged ? "converged" : "NOT converged");
  {
    const auto& d = result.datum;
    std::string names;
    for (const auto& g : d.directions) names += (names.empty() ? "" : ", ") + g.name;
    *printed +=
        StringPrintf("  datum %s: rank defect %s without it, %d constraints%s%s%s\n",
                     triangulation::LineDatumName(d.mode),
                     d.null_space_computed ? std::to_string(d.rank_defect).c_str() : "not computed",
                     d.n_constraints,
                     d.n_constraints ? " on " : "",
                     d.n_constraints ? d.blocks.front().c_str() : "",
                     names.empty() ? "" : (" (gauge: " + names + ")").c_str());
  }
  if (result.time_offset_estimated)
    *printed += StringPrintf("  time offset: %.6f +- %s s\n",
                             result.time_offset_s,
                             result.time_offset_sigma_s
                                 ? FormatNumber(*result.time_offset_sigma_s, 3).c_str()
                                 : "(not determined)");
  for (const auto& s : result.subcameras)
    *printed += StringPrintf(
        "  %-4s detectors %d..%d: %d obs, degree x %d y %d, RMS across %.3f -> %.3f px, "
        "along %.3f -> %.3f px\n",
        s.id.c_str(),
        s.first,
        s.last,
        s.n,
        s.degree_x,
        s.degree_y,
        s.across_before_px,
        s.across_after_px,
        s.along_before_px,
        s.along_after_px);
  const double deg = 180.0 / M_PI;
  if (result.boresight != triangulation::PlatformParamMode::kFixed) {
    const Eigen::Vector3d v = result.boresight_rad * deg;
    const Eigen::Vector3d s =
        result.boresight_sigma_rad.value_or(Eigen::Vector3d::Constant(NAN)) * deg;
    *printed += StringPrintf(
        "  boresight (%s): omega %.5f +- %.5f, phi %.5f +- %.5f, kappa %.5f +- %.5f deg\n",
        triangulation::PlatformParamModeName(result.boresight).c_str(),
        v.x(),
        s.x(),
        v.y(),
        s.y(),
        v.z(),
        s.z());
  }
  if (result.lever_arm != triangulation::PlatformParamMode::kFixed) {
    const Eigen::Vector3d& v = result.lever_arm_m;
    const Eigen::Vector3d s = result.lever_arm_sigma_m.value_or(Eigen::Vector3d::Constant(NAN));
    *printed += StringPrintf("  lever arm (%s): x %.4f +- %.4f, y %.4f +- %.4f, z %.4f +- %.4f m\n",
                             triangulation::PlatformParamModeName(result.lever_arm).c_str(),
                             v.x(),
                             s.x(),
                             v.y(),
                             s.y(),
                             v.z(),
                             s.z());
  }
  for (const auto& [name, rho] : result.correlations)
    *printed += StringPrintf("  correlation %s: %.4f\n", name.c_str(), rho);
  for (const auto& w : result.warnings)
    *errors += StringPrintf(
        "warning: %s (%s): %s\n", w.name.c_str(), w.subject.c_str(), w.message.c_str());
}

}  // namespace

LineCalibrationRun RunLineCalibration(const LineCalibrationRequest& request) {
  const triangulation::LineCalibrationOptions options = CheckedOptions(request);
  LineCalibrationRun run;
  run.camera = calib::ReadLineCamera(request.camera);
  const auto pos = triangulation::PosTrajectory::Read(request.pos);
  const auto observations =
      triangulation::ReadLineObservations(request.observations, request.sigma_px);
  const auto points = triangulation::ReadPoints(request.points);
  run.result = triangulation::CalibrateLineCamera(
      run.camera, pos, observations, points, options, request.observations);
  run.json = triangulation::LineCalibrationToJson(run.result);
  Summarise(run.result, &run.printed, &run.errors);
  return run;
}

}  // namespace aerocal::tools
