// The calibration certificate of a `calibrate` or `flight` result (certificate.json for programs;
// certificate.html and certificate.pdf for people, rendered by
// tools/certificate/aerocal_certificate.py with matplotlib). This file gathers the data: the lab
// YAML the user fills, the result, the comparison with a previous certificate or result against
// tolerances. Deterministic: no clock, no random numbers (the date comes from the lab file).
#include "tools/certificate_writer.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/json_schema.h"
#include "calib/core/result_file.h"
#include "calib/core/string_printf.h"
#include "calib/core/yaml_util.h"
#include "tools/command_registry.h"
#include "tools/dynamic_resolution.h"
#include "tools/observation_tables.h"
#include "tools/output_set.h"
#include "tools/python_script.h"
#include "triangulation/calibration/distortion_figure.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <vector>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;

// Tolerances: {parameter: allowed |change|} in the quantity's unit.
std::map<std::string, double> ReadTolerances(const std::string& path) {
  std::map<std::string, double> out;
  if (path.empty()) return out;
  const YAML::Node root = LoadYamlFile(path);
  if (!root.IsMap())
    throw InputError(WhereIs(root, path).ToString() + ": expected a map quantity: tolerance");
  for (const auto& item : root)
    out[item.first.as<std::string>()] =
        YamlBounded(item.second, path, item.first.as<std::string>(), 0, 1e12);
  return out;
}

// The schema of the certificate's inputs (docs/schema/certificate_inputs.schema.json) rooted at
// one of its definitions.
nlohmann::json InputSchema(const std::string& definition) {
  static const nlohmann::json schema =
      ReadJsonSchema(std::string(AEROCAL_SCHEMA_DIR) + "/certificate_inputs.schema.json");
  return {{"$ref", "#/definitions/" + definition}, {"definitions", schema.at("definitions")}};
}

// Every row of an uncertainty table (validated by the schema) must state what its numbers say:
// the statement is the one CertificateStatement gives for value, U, k and unit, and U = k u_c. A
// row whose statement quotes other numbers than its value and U is refused, never printed.
void CheckStatements(const nlohmann::json& rows, const std::string& file, const std::string& path) {
  for (size_t i = 0; i < rows.size(); ++i) {
    const nlohmann::json& q = rows[i];
    const std::string at = file + ": " + path + "[" + std::to_string(i) + "]";
    const double big_u = q["U"].is_number() ? q["U"].get<double>() : NAN;
    const std::string expected =
        triangulation::CertificateStatement(q["quantity"].get<std::string>(),
                                            q["value"].get<double>(),
                                            big_u,
                                            q["k"].get<double>(),
                                            q["unit"].get<std::string>());
    if (q["statement"].get<std::string>() != expected)
      throw InputError(at + ".statement: '" + q["statement"].get<std::string>() +
                       "' does not state the row's value, U, k and unit ('" + expected + "')");
    if (q.contains("u_c") && q["u_c"].is_number() && std::isfinite(big_u)) {
      const double k_u_c = q["k"].get<double>() * q["u_c"].get<double>();
      if (!(std::abs(big_u - k_u_c) <= 1e-9 * std::max(1e-300, big_u)))
        throw InputError(at + ".U: " + FormatNumber(big_u) +
                         " is not k u_c = " + FormatNumber(k_u_c));
    }
  }
}

// The uncertainty table of a calibrate result or of a certificate.json.
const nlohmann::json* Uncertainty(const nlohmann::json& doc) {
  if (doc.contains("results") && doc["results"].is_array()) return &doc["results"];
  if (doc.contains("calibration") && doc["calibration"].contains("uncertainty"))
    return &doc["calibration"]["uncertainty"];
  return nullptr;
}

nlohmann::json Compare(const nlohmann::json& now,
                       const nlohmann::json& previous,
                       const std::map<std::string, double>& tolerances,
                       const std::string& previous_file) {
  nlohmann::json rows = nlohmann::json::array();
  bool all_pass = true;
  std::map<std::string, nlohmann::json> old;
  for (const auto& q : previous) old[q.value("quantity", "")] = q;
  for (const auto& q : now) {
    const std::string name = q.at("quantity");
    const auto o = old.find(name);
    if (o == old.end()) continue;
    if (q.value("unit", "") != o->second.value("unit", ""))
      throw InputError(previous_file + ": quantity " + name + " is in " +
                       o->second.value("unit", "") + ", the result's in " + q.value("unit", "") +
                       " (--previous)");
    const double v = q.at("value"), v_old = o->second.at("value");
    const nlohmann::json big_u = q.value("U", nlohmann::json()),
                         big_u_old = o->second.value("U", nlohmann::json());
    const double u = big_u.is_number() ? big_u.get<double>() : NAN;
    const double u_old = big_u_old.is_number() ? big_u_old.get<double>() : NAN;
    const double diff = v - v_old;
    // E_n = |difference| / sqrt(U^2 + U_prev^2) (ISO/IEC 17043 / ISO 13528): <= 1 consistent.
    const double en = std::abs(diff) / std::sqrt(u * u + u_old * u_old);
    nlohmann::json row = {{"quantity", name},
                          {"unit", q.value("unit", nlohmann::json())},
                          {"value", v},
                          {"previous", v_old},
                          {"difference", diff},
                          {"U", big_u},
                          {"U_previous", big_u_old},
                          {"E_n", std::isfinite(en) ? nlohmann::json(en) : nlohmann::json()}};
    const auto t = tolerances.find(name);
    bool pass;
    if (t != tolerances.end()) {
      row["tolerance"] = t->second;
      row["criterion"] = "|difference| <= tolerance";
      pass = std::abs(diff) <= t->second;
    } else {
      row["tolerance"] = nullptr;
      row["criterion"] = "E_n <= 1";
      pass = std::isfinite(en) && en <= 1.0;
    }
    row["pass"] = pass;
    // The comparison judges the camera: sigma0 (m_0) and the check-point RMSEs (m_X, m_Y, m_Z)
    // are properties of the run (its images, targets and pointing), listed for information and
    // not counted in the overall verdict.
    const bool of_the_run = name == "m_0" || name == "m_X" || name == "m_Y" || name == "m_Z";
    row["judged"] = !of_the_run;
    if (!of_the_run) all_pass = all_pass && pass;
    rows.push_back(row);
  }
  return {{"rows", rows}, {"pass", all_pass}};
}

// The adjustment whose camera a flight certifies: the joint one when it ran, else the
// self-calibration (a reference into `flight`).
const nlohmann::json& CertifiedAdjustment(const nlohmann::json& flight, const std::string& path) {
  const nlohmann::json* chosen = nullptr;
  if (flight.contains("adjustments") && flight["adjustments"].is_array())
    for (const auto& a : flight["adjustments"])
      if (a.value("name", "") == "self_calibration" || a.value("name", "") == "joint") chosen = &a;
  if (!chosen || !chosen->contains("cameras") || (*chosen)["cameras"].empty())
    throw InputError(path + ": a flight result without a self-calibrating adjustment (--result)");
  return *chosen;
}

// A matrix of a result's JSON ({names, matrix}); empty unless it is `size` x `size` of numbers.
Eigen::MatrixXd MatrixOf(const nlohmann::json& block, int size) {
  if (!block.is_object() || !block.contains("matrix") || !block["matrix"].is_array() ||
      static_cast<int>(block["matrix"].size()) != size)
    return {};
  Eigen::MatrixXd m(size, size);
  for (int i = 0; i < size; ++i) {
    const nlohmann::json& row = block["matrix"][i];
    if (!row.is_array() || static_cast<int>(row.size()) != size) return {};
    for (int k = 0; k < size; ++k) {
      if (!row[k].is_number()) return {};
      m(i, k) = row[k].get<double>();
    }
  }
  return m;
}

// The pixel pitch's tolerance from the flight's camera file (pixel_size_tolerance_mm), when the
// file is still there and states one.
std::optional<double> PitchTolerance(const std::string& camera_file) {
  std::error_code ec;
  if (camera_file.empty() || !fs::exists(camera_file, ec)) return std::nullopt;
  return calib::ReadCamera(camera_file).pixel_size_tolerance_mm;
}

// The flight's certified interior as the budget needs it (triangulation::AdjustedInterior): its
// estimates, a covariance holding the adjustment's variances (sigma^2; only single parameters
// are certified, so g^T C g needs no covariances), the joint adjustment's Q N_control Q and the
// camera file's pitch tolerance.
triangulation::AdjustedInterior FlightInterior(const nlohmann::json& flight,
                                               const nlohmann::json& adjustment) {
  const nlohmann::json& camera = adjustment.at("cameras").at(0);
  triangulation::AdjustedInterior in;
  const auto model = calib::CameraModelFromName(camera.value("model", ""));
  in.table = calib::CameraModelParams(model ? *model : calib::CameraModelId::kBrownFraser10);
  const int n = static_cast<int>(in.table.size());
  in.params = calib::InteriorParams(std::vector<double>(n, 0.0));
  in.covariance = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    const std::string name(in.table[k].name);
    in.params[k] = camera.at("estimated").value(name, 0.0);
    const nlohmann::json sigma = camera.at("sigma").value(name, nlohmann::json());
    if (sigma.is_number()) in.covariance(k, k) = std::pow(sigma.get<double>(), 2);
  }
  in.sigma0 = adjustment.value("sigma0", 1.0);
  in.redundancy = adjustment.value("redundancy", 0.0);
  in.control_cofactor =
      MatrixOf(adjustment.value("interior_control_cofactor", nlohmann::json()), n);
  const nlohmann::json format = flight.value("camera_format", nlohmann::json::object());
  in.pixel_size_mm = format.value("pixel_size_mm", 0.0);
  const std::string camera_file = flight.value("camera", "");
  in.pitch_tolerance_mm = PitchTolerance(camera_file);
  in.pitch_source = "the camera file " + camera_file;
  in.image_origin = StringPrintf(
      "the flight adjustment's image observations (and GNSS/IMU priors where it has them), scaled "
      "by sigma0 = %.3g "
      "(redundancy %.0f as degrees of freedom)%s",
      in.sigma0,
      in.redundancy,
      in.control_cofactor.size() ? "; the control survey's part apart" : "");
  in.control_origin = StringPrintf(
      "survey sigmas of %d control points propagated through the flight adjustment (Q N_control "
      "Q)",
      adjustment.value("control", nlohmann::json::object()).value("n", 0));
  return in;
}

// The budget of c, x0, y0 of a flight's certified camera (the calibrated ones; fixed or unknown
// are left out): the test field's default components where their source is known
// (triangulation::InteriorParameterBudget: image measurements, control coordinates, pixel pitch).
std::vector<triangulation::BudgetQuantity> FlightBudget(const nlohmann::json& flight,
                                                        const nlohmann::json& adjustment) {
  static const std::map<std::string, const char*> kQuantities = {
      {"c", "principal distance"}, {"x0", "principal point x"}, {"y0", "principal point y"}};
  const triangulation::AdjustedInterior in = FlightInterior(flight, adjustment);
  std::vector<triangulation::BudgetQuantity> quantities;
  for (const auto& [name, description] : kQuantities)
    for (int k = 0; k < static_cast<int>(in.table.size()); ++k)
      if (in.table[k].name == name && in.covariance(k, k) > 0)
        quantities.push_back(triangulation::InteriorParameterBudget(in, k, description));
  return quantities;
}

// The number of used image residuals and their RMS (px, both components together).
std::pair<int, double> UsedResidualRms(const nlohmann::json& adjustment) {
  double sum2 = 0;
  int n = 0;
  for (const auto& r : adjustment.value("residuals", nlohmann::json::array()))
    if (r.value("used", true) && r.contains("v_col_px")) {
      sum2 +=
          std::pow(r.at("v_col_px").get<double>(), 2) + std::pow(r.at("v_row_px").get<double>(), 2);
      ++n;
    }
  return {n, n > 0 ? std::sqrt(sum2 / n) : 0.0};
}

// What the flight's budget holds, for the method statement.
std::string FlightBudgetMethod(const nlohmann::json& adjustment) {
  const bool control = adjustment.contains("interior_control_cofactor");
  return std::string(
             "type A: the image measurements (and GNSS/IMU priors where the flight has them) of "
             "the adjustment, scaled by sigma0; type B: ") +
         (control ? "the control coordinates' survey sigmas propagated (Q N_control Q), "
                  : "the control coordinates are in type A (this adjustment did not separate "
                    "them), ") +
         "the pixel pitch's tolerance of the camera file; target eccentricity and group "
         "reproducibility need a test field and image groups and are not evaluated for an "
         "in-flight calibration";
}

// An in-flight calibration (`aerocal flight` result.json) in the form of a `calibrate` result: the
// certified adjustment (CertifiedAdjustment) and its uncertainty budget (FlightBudget).
nlohmann::json CalibrateFormOfFlight(const nlohmann::json& flight, const std::string& path) {
  const nlohmann::json& chosen = CertifiedAdjustment(flight, path);
  nlohmann::json out = chosen;
  out["command"] = "calibrate";
  out["valid"] = flight.value("valid", false);
  out["invalid_reasons"] = nlohmann::json::array();
  for (const auto& f : flight.value("failures", nlohmann::json::array()))
    out["invalid_reasons"].push_back(f.value("step", "") + ": " + f.value("reason", ""));
  out["warnings"] = flight.value("warnings", nlohmann::json::array());
  const nlohmann::json& camera = out["cameras"][0];
  const auto [n, rms_px] = UsedResidualRms(out);
  const nlohmann::json format = flight.value("camera_format", nlohmann::json::object());
  out["calibration"] = {
      {"method",
       {{"kind", "in-flight calibration"},
        {"adjustment", chosen.value("name", "")},
        {"flight_data", flight.value("data", "")},
        {"budget", FlightBudgetMethod(chosen)}}},
      {"camera",
       {{"id", camera.value("id", "")},
        {"file", flight.value("camera", "")},
        {"pixel_size_mm", format.value("pixel_size_mm", 0.0)},
        {"format_px", {format.value("width_px", 0), format.value("height_px", 0)}}}},
      {"data",
       {{"images", out.value("exposures", nlohmann::json::array()).size()},
        {"observations", n},
        {"control_points", out["control"].value("n", 0)},
        {"check_points", out["check"].value("n", 0)},
        {"groups", 0}}},
      {"uncertainty", triangulation::BudgetToJson(FlightBudget(flight, chosen))},
      {"groups", nlohmann::json::array()},
      {"stability", nlohmann::json::object()},
      {"radii_mm", nlohmann::json::array()},
      {"rms_px", rms_px}};
  return out;
}

}  // namespace

// The lab file: sections of free-text fields, every key known (typos are errors).
nlohmann::json ReadCertificateLab(const std::string& path) {
  const std::map<std::string, std::vector<std::string>> sections = {
      {"lab", {"name", "address", "accreditation", "phone"}},
      {"certificate", {"number", "date", "page_note"}},
      {"camera", {"make", "model", "serial", "lens", "lens_serial"}},
      {"customer", {"name", "address"}},
      {"conditions", {"temperature", "humidity", "location", "target", "note"}},
      {"signatures", {"calibrated_by", "checked_by", "approved_by"}}};
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [section, keys] : sections) {
    out[section] = nlohmann::json::object();
    for (const auto& k : keys) out[section][k] = "";
  }
  if (path.empty()) return out;
  const YAML::Node root = LoadYamlFile(path);
  if (!root || root.IsNull()) return out;
  if (!root.IsMap())
    throw InputError(WhereIs(root, path).ToString() + ": expected a map of sections");
  std::vector<std::string> names;
  for (const auto& [section, keys] : sections) names.push_back(section);
  RejectUnknownKeys(root, names, path);
  for (const auto& [section, keys] : sections) {
    const YAML::Node node = root[section];
    if (!node) continue;
    if (!node.IsMap())
      throw InputError(WhereIs(node, path).ToString() + ": " + section + " must be a map");
    RejectUnknownKeys(node, keys, path);
    for (const auto& k : keys)
      if (node[k]) out[section][k] = YamlString(node[k], path, section + "." + k);
  }
  return out;
}

namespace {

// Runs `read` (typed access into a JSON document); a value of the wrong JSON type or a missing
// table (nlohmann's exception) is bad input naming the file and option (exit 2, nothing written).
template <typename Read>
auto ReadTyped(const std::string& path, const char* option, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a result written by aerocal (" + option + "): " + e.what());
  }
}

// The samples of the distortion figure (distortion_figure.h) from the certified camera: its model
// (the result's parameter table, else the 10-parameter model), estimated parameters by name and the
// camera file's format. Null when one of them is missing (the figure then says so).
nlohmann::json DistortionJson(const nlohmann::json& cert) {
  const nlohmann::json& table = cert["camera_model"];
  const auto model = calib::CameraModelFromName(
      table.is_object() ? table.value("name", "") : std::string(calib::BrownFraser10Model::kName));
  const nlohmann::json& estimated = cert["interior"].value("estimated", nlohmann::json::object());
  const nlohmann::json& file = cert["camera_file"];
  if (!model || !file.contains("format_px") || !file.contains("pixel_size_mm")) return nullptr;
  calib::ModelCamera camera;
  camera.model = *model;
  for (const auto& info : calib::CameraModelParams(*model)) {
    const std::string name(info.name);
    if (!estimated.contains(name) || !estimated[name].is_number()) return nullptr;
    camera.params.push_back(estimated[name].get<double>());
  }
  camera.frame.pixel_size_mm = file.at("pixel_size_mm").get<double>();
  camera.frame.width_px = file.at("format_px").at(0).get<int>();  // at(): a short list is bad input
  camera.frame.height_px = file.at("format_px").at(1).get<int>();
  if (!(camera.frame.pixel_size_mm > 0) || camera.frame.width_px < 2 || camera.frame.height_px < 2)
    return nullptr;
  const triangulation::DistortionFigure figure = triangulation::DistortionOverFormat(camera);
  if (figure.profile.empty()) return nullptr;
  return {
      {"profile_kind", figure.profile_kind}, {"profile", figure.profile}, {"grid", figure.grid}};
}

// The certificate's data from a checked `calibrate` result (or a flight's in that form): the
// method, camera, data, adjustment statistics, budget, interior, groups, check and control
// statistics, the distortion samples and the used residual vectors.
nlohmann::json CertificateData(const nlohmann::json& result,
                               const nlohmann::json& lab,
                               const std::string& source) {
  const nlohmann::json& cal = result["calibration"];
  nlohmann::json cert;
  cert["kind"] = "certificate";
  cert["lab"] = lab;
  cert["source"] = source;
  cert["method"] = cal.at("method");
  cert["camera_file"] = cal.at("camera");
  cert["data"] = cal.at("data");
  cert["adjustment"] = {
      {"sigma0", result["sigma0"]},
      {"sigma0_px", result["sigma0_px"]},
      {"sigma0_um", result["sigma0_um"]},
      {"redundancy", result["redundancy"]},
      {"converged", result["converged"]},
      {"valid", result.value("valid", false)},
      {"invalid_reasons", result.value("invalid_reasons", nlohmann::json::array())},
      {"warnings", result.value("warnings", nlohmann::json::array())},
      {"self_calibration", result.value("self_calibration", nlohmann::json())},
      {"rms_px", cal.at("rms_px")}};
  cert["results"] = cal.at("uncertainty");
  cert["interior"] = result["cameras"][0];
  cert["camera_model"] = result.value("camera_model", nlohmann::json());
  cert["correlation"] = cal.value("interior_covariance", nlohmann::json());
  cert["groups"] = cal.at("groups");
  cert["stability"] = cal.at("stability");
  cert["check"] = result["check"];
  cert["control"] = result["control"];
  cert["radii_mm"] = cal.value("radii_mm", nlohmann::json::array());
  cert["opencv"] = cal.value("opencv", nlohmann::json());
  cert["distortion"] = DistortionJson(cert);
  // Residual vectors (image pixels) for the vector field plot.
  nlohmann::json residuals = nlohmann::json::array();
  for (const auto& r : result.value("residuals", nlohmann::json::array()))
    if (r.value("used", true))
      residuals.push_back({r.at("col"), r.at("row"), r.at("v_col_px"), r.at("v_row_px")});
  cert["residuals"] = residuals;
  // Several units from directions (a rig's heads, a multi-CCD camera's sub-images): each unit's
  // values with U are rows "UNIT.quantity" of `results`; the units themselves listed here.
  if (cal.contains("units")) cert["units"] = cal["units"];
  if (cal.contains("subimages")) cert["units"] = cal["subimages"];
  if (cal.contains("gauge")) cert["gauge"] = cal["gauge"];
  return cert;
}

// The certificate of args.result (a calibrate or flight result), checked through its schema and
// every statement against its numbers; `valid`: the calibration is valid and its groups agree.
nlohmann::json CertificateOfResult(const CertificateArgs& args,
                                   const nlohmann::json& lab,
                                   bool* valid) {
  // The result of `aerocal calibrate` (kind "adjust", command "calibrate") or of `aerocal flight`.
  nlohmann::json result = ReadResult(args.result, {"adjust", "flight"}, "`aerocal calibrate`");
  return ReadTyped(args.result, "--result", [&] {
    if (result.is_object() && result.value("kind", "") == "flight") {
      InflateResidualTables(&result, args.result);  // `flight --residuals-csv`
      result = CalibrateFormOfFlight(result, args.result);
    }
    if (!result.is_object() || result.value("command", "") != "calibrate" ||
        !result.contains("calibration"))
      throw InputError(args.result + ": not a result of `aerocal calibrate` (--result)");
    // Through its schema (key path in the message), and every statement against its numbers.
    ValidateJson(result, InputSchema("calibrate_result"), args.result);
    CheckStatements(result["calibration"]["uncertainty"], args.result, "calibration.uncertainty");
    nlohmann::json cert =
        CertificateData(result, lab, args.result_name.empty() ? args.result : args.result_name);
    *valid = cert["adjustment"]["valid"].get<bool>() &&
             result["calibration"].at("stability").value("agree", true);
    return cert;
  });
}

// The comparison with args.previous (a certificate.json or calibrate result) against the
// tolerances, into cert["comparison"]; whether it passes.
bool CompareWithPrevious(const CertificateArgs& args,
                         const std::map<std::string, double>& tolerances,
                         nlohmann::json* cert) {
  const nlohmann::json previous = ReadResult(
      args.previous, {"certificate", "adjust"}, "`aerocal certificate` or `aerocal calibrate`");
  return ReadTyped(args.previous, "--previous", [&] {
    const nlohmann::json* old = Uncertainty(previous);
    if (!old)
      throw InputError(args.previous +
                       ": neither a certificate.json nor a calibrate result (--previous)");
    ValidateJson(previous, InputSchema("previous"), args.previous);
    CheckStatements(
        *old, args.previous, previous.contains("results") ? "results" : "calibration.uncertainty");
    (*cert)["comparison"] = Compare((*cert)["results"], *old, tolerances, args.previous);
    (*cert)["comparison"]["previous"] = args.previous;
    if (previous.contains("lab"))
      (*cert)["comparison"]["previous_certificate"] = previous["lab"].at("certificate");
    return (*cert)["comparison"]["pass"].get<bool>();
  });
}

// certificate.json, .html and .pdf are one set (tools/output_set.h): all are written into a
// staging folder and moved into args.out only when every part was written, so a failing
// renderer replaces nothing of the previous certificate. kExitInternal when rendering failed.
int WriteCertificateFiles(const CertificateArgs& args, const nlohmann::json& cert) {
  OutputSet set(args.out);
  const std::string json_path = set.Staged("certificate.json");
  WriteResult(json_path, "certificate", cert);
  if (args.no_render) {
    // certificate.json alone: an .html / .pdf of a previous certificate would not describe it.
    set.Commit({"certificate.json"}, {"certificate.html", "certificate.pdf"});
    return kExitOk;
  }
  const char* env = std::getenv("AEROCAL_CERTIFICATE_SCRIPT");
  const std::string script = env ? env : AEROCAL_CERTIFICATE_SCRIPT;
  if (!RunPythonScript(script, {json_path, set.staging()})) {
    std::fprintf(stderr,
                 "error: the certificate could not be rendered (%s); nothing written, the "
                 "previous certificate in %s is left as it was\n",
                 PythonCommandLine(script, {json_path, set.staging()}).c_str(),
                 args.out.c_str());
    return kExitInternal;
  }
  set.Commit({"certificate.json", "certificate.html", "certificate.pdf"});
  return kExitOk;
}

// What was written, every statement, and the comparison's verdict.
void PrintCertificate(const CertificateArgs& args, const nlohmann::json& cert, bool pass) {
  const std::string shown = args.out_name.empty() ? args.out : args.out_name;
  std::printf("certificate data -> %s/certificate.json\n", shown.c_str());
  for (const auto& q : cert["results"])
    std::printf("  %s\n", q.at("statement").get<std::string>().c_str());
  if (cert.contains("comparison"))
    std::printf("comparison with %s: %s\n", args.previous.c_str(), pass ? "pass" : "FAIL");
  if (!args.no_render)
    std::printf(
        "certificate -> %s/certificate.html, %s/certificate.pdf\n", shown.c_str(), shown.c_str());
}

}  // namespace

int WriteCertificate(const CertificateArgs& args) {
  CheckOutputFolder(args.out, "--out");
  if (!args.tolerances.empty() && args.previous.empty())
    throw ConfigError("--tolerances needs --previous");
  const nlohmann::json lab = ReadCertificateLab(args.lab);
  const auto tolerances = ReadTolerances(args.tolerances);
  bool valid = false;
  nlohmann::json cert = CertificateOfResult(args, lab, &valid);
  if (!args.quality.empty()) cert["dynamic_image_resolution"] = DynamicResolutionJson(args.quality);
  const bool comparison_pass =
      args.previous.empty() || CompareWithPrevious(args, tolerances, &cert);
  // Everything is checked before anything is written.
  if (WriteCertificateFiles(args, cert) == kExitInternal) return kExitInternal;
  PrintCertificate(args, cert, comparison_pass);
  return valid && comparison_pass ? kExitOk : kExitNotConverged;
}

}  // namespace aerocal::tools
