// The line-camera calibration's result files (line_calibration.h): result.json (kind
// "pushbroom", module README "Result"), one writer per section, and the per-line corrections CSV.
#include "calib/core/csv.h"
#include "calib/problem/solve_statistics_json.h"
#include "triangulation/adjustment/mounted_json.h"
#include "triangulation/pushbroom/line_calibration.h"

#include <cmath>

namespace aerocal::triangulation {
namespace {

using nlohmann::json;

constexpr double kDeg = 180.0 / M_PI;

json Optional(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json DatumToJson(const LineDatumReport& d) {
  json directions = json::array();
  for (const auto& g : d.directions)
    directions.push_back({{"name", g.name}, {"fraction", g.fraction}, {"meaning", g.meaning}});
  return {{"mode", LineDatumName(d.mode)},
          {"null_space_computed", d.null_space_computed},
          {"rank_defect", d.null_space_computed ? json(d.rank_defect) : json(nullptr)},
          {"threshold", d.threshold},
          {"smallest_relative_eigenvalues", d.smallest_relative_eigenvalues},
          {"n_constraints", d.n_constraints},
          {"subcamera", d.subcamera},
          {"blocks", d.blocks},
          {"gauge_directions", directions},
          {"gauge_directions_in_table", d.in_table},
          {"parameters_in_null_space", d.parameters_in_null_space},
          {"message", d.message}};
}

// c, and the blocks mounted on the platform in the one mounted-block form {mode, value, sigma}
// (MountedToJson): the time offset (fixed, or free when estimated) in ms, the boresight in deg,
// the lever arm in m; a sigma is null when held or not determined.
void WriteMountedParameters(const LineCalibrationResult& r, json* j) {
  (*j)["time_offset_ms"] =
      MountedToJson(r.time_offset_estimated ? calib::BlockMode::kFree : calib::BlockMode::kFixed,
                    r.time_offset_s,
                    r.time_offset_sigma_s,
                    1e3);
  (*j)["c_mm"] = r.c_mm;
  (*j)["c_sigma_mm"] = Optional(r.c_sigma_mm);
  (*j)["boresight_deg"] = MountedToJson(r.boresight, r.boresight_rad, r.boresight_sigma_rad, kDeg);
  (*j)["lever_arm_m"] = MountedToJson(r.lever_arm, r.lever_arm_m, r.lever_arm_sigma_m, 1.0);
}

json SubcameraToJson(const SubcameraRms& s) {
  json js;
  js["id"] = s.id;
  js["first"] = s.first;
  js["last"] = s.last;
  js["n"] = s.n;
  js["degree_x"] = s.degree_x;
  js["degree_y"] = s.degree_y;
  js["rms_before_px"] = {{"across", s.across_before_px}, {"along", s.along_before_px}};
  js["rms_after_px"] = {{"across", s.across_after_px}, {"along", s.along_after_px}};
  js["dx_mm"] = s.dx_coefficients_mm;
  js["dy_mm"] = s.dy_coefficients_mm;
  json sx = json::array(), sy = json::array();
  for (const auto& v : s.dx_sigma_mm) sx.push_back(Optional(v));
  for (const auto& v : s.dy_sigma_mm) sy.push_back(Optional(v));
  js["dx_sigma_mm"] = sx;
  js["dy_sigma_mm"] = sy;
  return js;
}

json DetectorsToJson(const LineCalibrationResult& r) {
  json det = json::array();
  for (size_t i = 0; i < r.dx_mm.size(); ++i)
    det.push_back({{"i", i},
                   {"dx_mm", r.dx_mm[i]},
                   {"dy_mm", r.dy_mm[i]},
                   {"sigma_dx_mm", Optional(r.dx_sigma_mm[i])},
                   {"sigma_dy_mm", Optional(r.dy_sigma_mm[i])},
                   {"sigma_dx_fit_mm", Optional(r.dx_fit_sigma_mm[i])},
                   {"sigma_dy_fit_mm", Optional(r.dy_fit_sigma_mm[i])}});
  return det;
}

json TrajectoryToJson(const LineCalibrationResult& r) {
  json nodes = json::array();
  for (size_t k = 0; k < r.node_values.size(); ++k) {
    const auto& v = r.node_values[k];
    const auto& s = r.node_sigma[k];
    nodes.push_back({{"line", r.node_line[k]},
                     {"dX", v[0]},
                     {"dY", v[1]},
                     {"dZ", v[2]},
                     {"domega", v[3] * kDeg},
                     {"dphi", v[4] * kDeg},
                     {"dkappa", v[5] * kDeg},
                     {"sigma",
                      {{"dX", s[0]},
                       {"dY", s[1]},
                       {"dZ", s[2]},
                       {"domega", s[3] * kDeg},
                       {"dphi", s[4] * kDeg},
                       {"dkappa", s[5] * kDeg}}}});
  }
  return {{"form", "cubic_bspline"}, {"nodes", nodes}};
}

}  // namespace

std::string LineCorrectionsToCsv(const LineCalibrationResult& r) {
  std::string out = "line,dX,dY,dZ,domega,dphi,dkappa,sdX,sdY,sdZ,sdomega,sdphi,sdkappa\n";
  for (size_t k = 0; k < r.lines.size(); ++k) {
    out += FormatNumber(r.lines[k]);
    for (int a = 0; a < 6; ++a)
      out += "," + FormatNumber(r.line_corrections[k][a] * (a < 3 ? 1 : kDeg), 10);
    for (int a = 0; a < 6; ++a)
      out += "," + FormatNumber(r.line_sigma[k][a] * (a < 3 ? 1 : kDeg), 6);
    out += "\n";
  }
  return out;
}

nlohmann::json LineCalibrationToJson(const LineCalibrationResult& r) {
  json j;
  j["kind"] = "pushbroom";
  j["sigma0"] = r.report.sigma0;
  j["sigma0_px"] = r.sigma0_px;
  j.update(calib::SolveStatisticsToJson(r.report));  // redundancy .. seconds, groups
  j["valid"] = r.valid;
  j["n_observations"] = r.n_observations;
  j["n_control"] = r.n_control;
  j["n_ignored_observations"] = r.n_ignored;
  j["datum"] = DatumToJson(r.datum);
  WriteMountedParameters(r, &j);
  json subs = json::array();
  for (const auto& s : r.subcameras) subs.push_back(SubcameraToJson(s));
  j["subcameras"] = subs;
  j["degree_test"] = {{"applied", r.degree_test.applied},
                      {"reduced", r.degree_test.reduced},
                      {"start_degree", r.degree_test.start_degree},
                      {"alpha", r.degree_test.alpha},
                      {"table_sigma", r.degree_test.reduced ? "selected" : "fit"}};
  j["detectors"] = DetectorsToJson(r);
  j["trajectory"] = TrajectoryToJson(r);
  json corr = json::object();
  for (const auto& [name, rho] : r.correlations) corr[name] = rho;
  j["correlations"] = corr;
  j["undetermined"] = r.undetermined;
  j["warnings"] = FindingsToJson(r.warnings);
  return j;
}

}  // namespace aerocal::triangulation
