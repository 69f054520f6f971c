#include "triangulation/adjustment/adjustment_result.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/problem/solve_statistics_json.h"
#include "triangulation/adjustment/determinability.h"
#include "triangulation/adjustment/mounted_json.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace aerocal::triangulation {
namespace {

using Model = calib::Camera::Model;
constexpr double kRadToDeg = 180.0 / M_PI;

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// A number, or null when it is not finite (untestable component, unknown sigma).
nlohmann::json Finite(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

// "platform": each parameter in the one mounted-block form (MountedToJson: mode,
// value, sigma null when fixed or unknown), in the units of the project YAML's `platform:` keys
// (m, deg, ms).
nlohmann::json PlatformToJson(const PlatformEstimate& p) {
  nlohmann::json j;
  if (p.gnss) {
    j["lever_arm_m"] = MountedToJson(p.spec.lever_arm, p.lever_arm_m, p.lever_arm_sigma_m, 1.0);
    j["time_offset_ms"] =
        MountedToJson(p.spec.time_offset, p.time_offset_s, p.time_offset_sigma_s, 1e3);
  }
  if (p.imu)
    j["boresight_deg"] =
        MountedToJson(p.spec.boresight, p.boresight_rad, p.boresight_sigma_rad, kRadToDeg);
  return j;
}
nlohmann::json Pair(const Eigen::Vector2d& v) { return {Finite(v.x()), Finite(v.y())}; }

// r, w, MDB and group size of one tested observation (FORMATS.md keys are kept beside these).
void AddTest(const ObservationTest& t, nlohmann::json* j) {
  if (!t.tested) return;
  (*j)["r"] = Pair(t.redundancy);
  (*j)["w_xy"] = Pair(t.w);
  (*j)["mdb_sigma"] = Pair(t.mdb_sigma);
  (*j)["mdb_px"] = Pair(t.mdb_px);
  (*j)["group_size"] = t.group_size;
  (*j)["verdict"] = t.verdict;
  if (!t.reason.empty()) (*j)["reason"] = t.reason;
}

// "self_calibration_choice" (`--self-calibration auto`): candidates, chosen, each held parameter.
nlohmann::json FreeSetChoiceJson(const FreeSetChoice& c) {
  nlohmann::json j = {{"candidates", c.candidates},
                      {"chosen", c.chosen},
                      {"significance_t", c.significance_t},
                      {"correlation_limit", c.correlation_limit},
                      {"rounds", c.rounds}};
  j["held"] = nlohmann::json::array();
  for (const auto& h : c.held) {
    nlohmann::json e = {{"parameter", h.parameter},
                        {"reason", h.reason},
                        {"statistic", Finite(h.statistic)},
                        {"round", h.round}};
    if (!h.with.empty()) e["with"] = h.with;
    j["held"].push_back(e);
  }
  return j;
}

nlohmann::json SnoopingToJson(const SnoopingSummary& s) {
  nlohmann::json j = {{"run", s.run},
                      {"alpha", s.alpha},
                      {"alpha0", s.alpha0},
                      {"critical_value", s.critical_value},
                      {"power", s.power},
                      {"delta0", s.delta0},
                      {"delta0_joint", s.delta0_joint},
                      {"min_redundancy", s.min_redundancy},
                      {"group_correlation", s.group_correlation},
                      {"reference_sigma", s.reference_sigma},
                      {"cofactor_method", s.cofactor_method},
                      {"cofactors_ok", s.cofactors_ok},
                      {"n_tested_components", s.n_tested_components},
                      {"rounds", s.rounds},
                      {"max_rejections", s.max_rejections},
                      {"cap_reached", s.cap_reached},
                      {"remaining_above_critical", s.remaining_above_critical},
                      {"n_weakly_controlled", s.n_weakly_controlled},
                      {"n_untestable", s.n_untestable},
                      {"n_in_groups", s.n_in_groups},
                      {"model_error_suspected", s.model_error_suspected},
                      {"model_error_evidence", s.model_error_evidence},
                      {"suggestion", s.suggestion},
                      {"findings", s.findings},
                      {"seconds_testing", s.seconds_testing},
                      {"robust_start", s.robust_start},
                      {"robust_start_reason", s.robust_start_reason},
                      {"gross_share", s.gross_share},
                      {"robust_excluded", s.robust_excluded},
                      {"robust_readmitted", s.robust_readmitted},
                      {"robust_retested", s.robust_retested},
                      {"unresolved_reason", s.unresolved_reason}};
  j["unresolved_surveys"] = nlohmann::json::array();
  for (const auto& u : s.unresolved_surveys)
    j["unresolved_surveys"].push_back({{"survey", u.survey},
                                       {"w", u.w},
                                       {"r", u.redundancy},
                                       {"residual_sigma", u.residual_sigma}});
  if (!s.unresolved_surveys.empty())
    j["unresolved_effect"] = calib::SuspectEffectJson(s.unresolved_effect);
  j["uncontrolled"] = nlohmann::json::array();
  for (const auto& u : s.uncontrolled)
    j["uncontrolled"].push_back({{"image", u.image},
                                 {"point", u.point},
                                 {"r", Pair(u.redundancy)},
                                 {"mdb_px", Pair(u.mdb_px)},
                                 {"rays", u.rays},
                                 {"untestable", u.untestable},
                                 {"reason", u.reason}});
  j["flagged"] = nlohmann::json::array();
  for (const auto& f : s.flagged)
    j["flagged"].push_back({{"observation", f.what},
                            {"verdict", f.verdict},
                            {"reason", f.reason},
                            {"w", Finite(f.w)},
                            {"r", f.redundancy},
                            {"mdb_sigma", Finite(f.mdb_sigma)},
                            {"group_size", f.group_size}});
  return j;
}

nlohmann::json Interior(calib::CameraModelId model, const calib::InteriorParams& p) {
  nlohmann::json j = nlohmann::json::object();
  const std::vector<calib::ParamInfo> table = calib::CameraModelParams(model);
  for (size_t k = 0; k < table.size(); ++k) j[std::string(table[k].name)] = p[k];
  return j;
}

std::string StatisticsLine(const char* what, const PointStatistics& s) {
  return StringPrintf("%-8s n=%3d  RMSE X %.4f  Y %.4f  Z %.4f  plan %.4f  spatial %.4f m\n",
                      what,
                      s.n,
                      s.rmse_m.x(),
                      s.rmse_m.y(),
                      s.rmse_m.z(),
                      s.planimetric_rmse_m,
                      s.spatial_rmse_m);
}

// |correction| / sigma of a free parameter: above 1.96 the correction is significant at 5 %
// (the test of additional parameters); NaN when fixed or without a covariance.
double CorrectionInSigmas(const CameraEstimate& c, int k) {
  if (!c.free[k] || !(c.sigma[k] > 0)) return std::numeric_limits<double>::quiet_NaN();
  return std::abs(c.estimated[k] - c.initial[k]) / c.sigma[k];
}

std::string CalibrationTable(const AdjustmentResult& r) {
  std::string out;
  for (const auto& c : r.cameras) {
    out += "camera " + c.id + "\n";
    out += StringPrintf("  %-4s %-6s %16s %16s %16s %14s %8s\n",
                        "par",
                        "unit",
                        "initial",
                        "correction",
                        "estimate",
                        "sigma",
                        "|t|");
    std::string insignificant;
    const std::vector<calib::ParamInfo> table = calib::CameraModelParams(c.model);
    for (int k = 0; k < static_cast<int>(table.size()); ++k) {
      const auto& info = table[k];
      const double t = CorrectionInSigmas(c, k);
      out += StringPrintf("  %-4s %-6s %16.8g %16.8g %16.8g %14s %8s\n",
                          std::string(info.name).c_str(),
                          std::string(info.unit).c_str(),
                          c.initial[k],
                          c.estimated[k] - c.initial[k],
                          c.estimated[k],
                          c.free[k] ? StringPrintf("%.3g", c.sigma[k]).c_str() : "fixed",
                          std::isnan(t) ? "-" : StringPrintf("%.1f", t).c_str());
      if (t < 1.96) insignificant += (insignificant.empty() ? "" : ", ") + std::string(info.name);
    }
    if (!insignificant.empty())
      out +=
          "  corrections not significant at 5 % (|t| < 1.96, one parameter at a time; correlated "
          "terms such as K1-K3 may be significant together): " +
          insignificant + "\n";
  }
  return out;
}

// One line per observation rejected as a gross error (its sub-image when measured in one).
std::string RejectedLines(const AdjustmentResult& r) {
  std::string out;
  for (const auto& o : r.rejected)
    out += StringPrintf(
        "rejected%s: image %s%s point %s at (%.1f, %.1f), residual %.2f px (w = %.1f%s)\n",
        o.by == "snooping" ? "" : (" by the " + o.by).c_str(),
        o.image.c_str(),
        ((o.subimage.empty() ? "" : " sub-image " + o.subimage) +
         (o.head.empty() ? "" : " head " + o.head))
            .c_str(),
        o.point.c_str(),
        o.measured_px.x(),
        o.measured_px.y(),
        o.residual_px.norm(),
        o.w,
        o.test.tested ? StringPrintf(", r = (%.2f, %.2f), MDB (%.3g, %.3g) px, group of %d",
                                     o.test.redundancy.x(),
                                     o.test.redundancy.y(),
                                     o.test.mdb_px.x(),
                                     o.test.mdb_px.y(),
                                     o.test.group_size)
                            .c_str()
                      : "");
  return out;
}

// What snooping could not decide or suspects, one line each.
std::string SnoopingLines(const AdjustmentResult& r) {
  const SnoopingSummary& s = r.snooping;
  std::string out;
  if (s.robust_start)
    out += StringPrintf(
        "robust start (%s): %d observation(s) excluded, %d re-admitted after the clean solution, "
        "%d on points it could not hold left to snooping\n",
        s.robust_start_reason.c_str(),
        s.robust_excluded,
        s.robust_readmitted,
        s.robust_retested);
  if (!s.run) return out;
  out += StringPrintf(
      "data snooping: %d components tested, critical |w| %.2f (alpha %.3g family-wise), power "
      "%.0f %% (delta0 %.2f), %d round(s), %zu rejected; %d observation(s) weakly controlled "
      "(r < %.2f), %d in correlated groups; cofactors: %s\n",
      s.n_tested_components,
      s.critical_value,
      s.alpha,
      100 * s.power,
      s.delta0,
      s.rounds,
      r.rejected.size(),
      s.n_weakly_controlled,
      s.min_redundancy,
      s.n_in_groups,
      s.cofactor_method.c_str());
  for (const auto& f : s.findings) out += "snooping: " + f + "\n";
  if (!s.uncontrolled.empty()) {
    const auto untestable = std::count_if(
        s.uncontrolled.begin(), s.uncontrolled.end(), [](const auto& u) { return u.untestable; });
    out += StringPrintf(
        "uncontrolled: %zu observation(s) no test can judge (%d with r = 0, a blunder there "
        "is invisible); all in the result's snooping.uncontrolled:\n",
        s.uncontrolled.size(),
        static_cast<int>(untestable));
    constexpr size_t kShown = 10;
    for (size_t i = 0; i < s.uncontrolled.size() && i < kShown; ++i) {
      const auto& u = s.uncontrolled[i];
      out += StringPrintf("  image %s point %s (%d rays) r (%.2f, %.2f): %s\n",
                          u.image.c_str(),
                          u.point.c_str(),
                          u.rays,
                          u.redundancy.x(),
                          u.redundancy.y(),
                          u.reason.c_str());
    }
    if (s.uncontrolled.size() > kShown)
      out += StringPrintf("  ... %zu more\n", s.uncontrolled.size() - kShown);
  }
  if (s.model_error_suspected && !s.suggestion.empty())
    out += "warning: model error suspected: " + s.suggestion + "\n";
  if (s.cap_reached)
    out += StringPrintf(
        "warning: rejection cap (%d) reached: %d candidate(s) left above the "
        "critical value\n",
        s.max_rejections,
        s.remaining_above_critical);
  return out;
}

std::string ValidityLines(const AdjustmentResult& r) {
  std::string out;
  for (const auto& reason : r.invalid_reasons) out += "NOT VALID: " + reason + "\n";
  return out;
}

}  // namespace

std::optional<double> LeftOutControl::LargestW() const {
  std::optional<double> w;
  for (const auto& component : components)
    if (!w || component.second > *w) w = component.second;
  return w;
}

std::string LeftOutControl::ComponentNames() const {
  std::string names;
  for (const auto& component : components)
    names += (names.empty() ? "" : " and ") + component.first;
  return names;
}

void AdjustmentResult::Invalidate(const std::string& reason) {
  valid = false;
  if (std::find(invalid_reasons.begin(), invalid_reasons.end(), reason) == invalid_reasons.end())
    invalid_reasons.push_back(reason);
}

void ClassifyUncontrolled(double min_redundancy, AdjustmentResult* result) {
  constexpr double kUntestable = 1e-6;  // as data_snooping.cc: r below, no test sees anything
  const char* axis[2] = {"x", "y"};
  std::map<std::string, int> rays;
  for (const auto& v : result->residuals) rays[v.point] += v.used;
  std::map<std::string, std::string> point_reason;  // the first uncontrolled ray of each point
  SnoopingSummary& s = result->snooping;
  s.uncontrolled.clear();
  for (const auto& v : result->residuals) {
    if (!v.used || !v.test.tested) continue;
    Eigen::Index k = 0;
    const double r = v.test.redundancy.minCoeff(&k);
    if (!(r < min_redundancy)) continue;
    UncontrolledObservation u;
    u.image = v.image;
    u.point = v.point;
    u.redundancy = v.test.redundancy;
    u.mdb_px = v.test.mdb_px;
    u.rays = rays[v.point];
    u.untestable = r < kUntestable;
    if (u.untestable && u.rays == 2)
      u.reason = StringPrintf(
          "r = 0 on photo %s: the component along the base of a two-ray point; no "
          "test can see a blunder there",
          axis[k]);
    else if (u.untestable)
      u.reason =
          StringPrintf("r = 0 on photo %s: no other observation checks this component", axis[k]);
    else
      u.reason = StringPrintf(
          "r = %.3f on photo %s < %.2f: weakly controlled; a blunder below the "
          "MDB of %.3g px is not found",
          r,
          axis[k],
          min_redundancy,
          v.test.mdb_px(k));
    point_reason.try_emplace(v.point, "ray " + v.image + ": " + u.reason);
    s.uncontrolled.push_back(u);
  }
  std::vector<PointDifference> controlled;
  for (auto& d : result->check_points) {
    const auto it = point_reason.find(d.point);
    d.uncontrolled = it == point_reason.end() ? std::string() : it->second;
    if (d.uncontrolled.empty()) controlled.push_back(d);
  }
  result->check_controlled = ComputePointStatistics(controlled);
}

PointStatistics ComputePointStatistics(const std::vector<PointDifference>& points) {
  PointStatistics s;
  s.n = static_cast<int>(points.size());
  if (s.n == 0) return s;
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero();
  for (const auto& p : points) {
    sum2 += p.difference_m.cwiseAbs2();
    s.mean_m += p.difference_m;
    s.max_abs_m = s.max_abs_m.cwiseMax(p.difference_m.cwiseAbs());
  }
  s.mean_m /= s.n;
  s.rmse_m = (sum2 / s.n).cwiseSqrt();
  s.planimetric_rmse_m = s.rmse_m.head<2>().norm();
  s.spatial_rmse_m = s.rmse_m.norm();
  return s;
}

nlohmann::json PointStatisticsToJson(const PointStatistics& s) {
  return {{"n", s.n},
          {"rmse_m", Vec(s.rmse_m)},
          {"mean_m", Vec(s.mean_m)},
          {"max_abs_m", Vec(s.max_abs_m)},
          {"planimetric_rmse_m", s.planimetric_rmse_m},
          {"spatial_rmse_m", s.spatial_rmse_m}};
}

std::vector<ResultWarning> GroupRmsWarnings(const calib::SolveReport& solve, double limit) {
  std::vector<ResultWarning> out;
  for (const auto& g : solve.groups) {
    if (g.n_observations == 0 || !(g.rms > limit)) continue;
    out.push_back(
        {kWarningGroupRms,
         g.name,
         g.rms,
         limit,
         StringPrintf("residual group %s: RMS %.3g sigma over %d observations (limit %.3g): the "
                      "model does not fit these observations, or their sigmas are too small",
                      g.name.c_str(),
                      g.rms,
                      g.n_observations,
                      limit)});
  }
  return out;
}

namespace {

// `cameras`: per camera its model, initial and estimated interior, the free parameters and their
// sigmas (null without a covariance).
nlohmann::json CamerasToJson(const AdjustmentResult& r) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const auto& c : r.cameras) {
    nlohmann::json sigma = nlohmann::json::object(), free = nlohmann::json::array();
    const std::vector<calib::ParamInfo> table = calib::CameraModelParams(c.model);
    for (int k = 0; k < static_cast<int>(table.size()); ++k) {
      const std::string name(table[k].name);
      if (c.free[k]) {
        free.push_back(name);
        sigma[name] =
            r.determinability.covariance_ok ? nlohmann::json(c.sigma[k]) : nlohmann::json();
      }
    }
    cameras.push_back({{"id", c.id},
                       {"model", std::string(calib::CameraModelName(c.model))},
                       {"initial", Interior(c.model, c.initial)},
                       {"estimated", Interior(c.model, c.estimated)},
                       {"sigma", sigma},
                       {"free", free}});
  }
  return cameras;
}

nlohmann::json PointTableToJson(const std::vector<PointDifference>& points) {
  nlohmann::json t = nlohmann::json::array();
  for (const auto& p : points) {
    t.push_back({{"point", p.point},
                 {"surveyed", Vec(p.surveyed_m)},
                 {"adjusted", Vec(p.adjusted_m)},
                 {"difference_m", Vec(p.difference_m)},
                 {"rays", p.rays}});
    if (!p.uncontrolled.empty()) t.back()["uncontrolled"] = p.uncontrolled;
  }
  return t;
}

// Control points the adjustment left out, each with its largest w and w per component.
nlohmann::json ControlLeftOutToJson(const AdjustmentResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& left : r.control_left_out) {
    const PointDifference& p = left.difference;
    nlohmann::json components = nlohmann::json::object();
    for (const auto& [component, w_component] : left.components)
      components[component] = w_component;
    const std::optional<double> largest = left.LargestW();
    const nlohmann::json w = largest ? nlohmann::json(*largest) : nlohmann::json();
    out.push_back({{"point", p.point},
                   {"surveyed_m", Vec(p.surveyed_m)},
                   {"adjusted_m", Vec(p.adjusted_m)},
                   {"difference_m", Vec(p.difference_m)},
                   {"rays", p.rays},
                   {"w", w},
                   {"components", components}});
  }
  return out;
}

// The check statistics over the controlled check points, with the others and why.
nlohmann::json CheckControlledToJson(const AdjustmentResult& r) {
  nlohmann::json c = PointStatisticsToJson(*r.check_controlled);
  c["uncontrolled_points"] = nlohmann::json::array();
  for (const auto& p : r.check_points)
    if (!p.uncontrolled.empty())
      c["uncontrolled_points"].push_back({{"point", p.point},
                                          {"difference_m", Vec(p.difference_m)},
                                          {"rays", p.rays},
                                          {"reason", p.uncontrolled}});
  return c;
}

// `control`, `check`, `control_left_out` and `check_controlled` (when there is one).
void WritePoints(const AdjustmentResult& r, nlohmann::json* j) {
  nlohmann::json control = PointStatisticsToJson(r.control), check = PointStatisticsToJson(r.check);
  control["points"] = PointTableToJson(r.control_points);
  check["points"] = PointTableToJson(r.check_points);
  (*j)["control"] = control;
  (*j)["check"] = check;
  (*j)["control_left_out"] = ControlLeftOutToJson(r);
  if (r.check_controlled) (*j)["check_controlled"] = CheckControlledToJson(r);
}

nlohmann::json ExposuresToJson(const std::vector<ExposureEstimate>& exposures) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : exposures) {
    nlohmann::json x = {{"image", e.image},
                        {"X", e.center_m.x()},
                        {"Y", e.center_m.y()},
                        {"Z", e.center_m.z()},
                        {"omega", e.opk_rad.x() * kRadToDeg},
                        {"phi", e.opk_rad.y() * kRadToDeg},
                        {"kappa", e.opk_rad.z() * kRadToDeg}};
    // Unknown (left out, or no covariance): null, never 0.
    nlohmann::json sigma = {{"X", nullptr},
                            {"Y", nullptr},
                            {"Z", nullptr},
                            {"omega", nullptr},
                            {"phi", nullptr},
                            {"kappa", nullptr}};
    if (e.center_sigma_m && e.opk_sigma_rad)
      sigma = {{"X", e.center_sigma_m->x()},
               {"Y", e.center_sigma_m->y()},
               {"Z", e.center_sigma_m->z()},
               {"omega", Finite(e.opk_sigma_rad->x() * kRadToDeg)},  // null at phi = +-90 deg
               {"phi", Finite(e.opk_sigma_rad->y() * kRadToDeg)},
               {"kappa", Finite(e.opk_sigma_rad->z() * kRadToDeg)}};
    x["sigma"] = sigma;
    x["used"] = e.used;
    out.push_back(x);
  }
  return out;
}

nlohmann::json RejectedToJson(const AdjustmentResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& o : r.rejected) {
    nlohmann::json x = {{"image", o.image},
                        {"point", o.point},
                        {"measured_px", {o.measured_px.x(), o.measured_px.y()}},
                        {"residual_px", o.residual_px.norm()},
                        {"residual_col_row_px", {o.residual_px.x(), -o.residual_px.y()}},
                        {"w", o.w},
                        {"by", o.by},
                        {"group", o.group}};
    if (!o.subimage.empty()) x["subimage"] = o.subimage;
    if (!o.head.empty()) x["head"] = o.head;
    AddTest(o.test, &x);
    out.push_back(x);
  }
  return out;
}

// Every image observation: where it was measured (virtual pixels) and its residual, for the
// residual plots of the report. Built in place (reserved, each record moved in): the records
// are the bulk of the document, and a copy per record doubled their share of the peak.
nlohmann::json ResidualsToJson(const AdjustmentResult& r) {
  nlohmann::json::array_t out;
  out.reserve(r.residuals.size());
  for (const auto& o : r.residuals) {
    nlohmann::json v = {{"image", o.image},
                        {"point", o.point},
                        {"col", o.measured_px.x()},
                        {"row", o.measured_px.y()},
                        {"v_col_px", o.residual_px.x()},
                        {"v_row_px", o.residual_px.y()},
                        {"sigma_px", o.sigma_px},
                        {"used", o.used}};
    if (!o.subimage.empty()) {
      v["subimage"] = o.subimage;
      v["u"] = o.subimage_px.x();
      v["v"] = o.subimage_px.y();
    }
    if (!o.head.empty()) v["head"] = o.head;
    AddTest(o.test, &v);
    out.push_back(std::move(v));
  }
  return out;
}

nlohmann::json InteriorCorrelationToJson(const AdjustmentResult& r) {
  nlohmann::json correlation = {{"names", r.interior_correlation_names},
                                {"matrix", nlohmann::json::array()}};
  for (int i = 0; i < r.interior_correlation.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int k = 0; k < r.interior_correlation.cols(); ++k)
      row.push_back(Finite(r.interior_correlation(i, k)));
    correlation["matrix"].push_back(row);
  }
  return correlation;
}

}  // namespace

nlohmann::json AdjustmentToJson(const AdjustmentResult& r) {
  nlohmann::json j;
  j["kind"] = "adjust";
  j["schema_version"] = ResultSchemaVersion("adjust");
  // The model of the cameras (the first camera's when they differ; each camera names its own).
  j["camera_model"] =
      calib::CameraModelTableToJson(r.cameras.empty() ? Model::kId : r.cameras.front().model);
  j["sigma0"] = r.sigma0;
  j["sigma0_px"] = r.sigma0_px;
  j["sigma0_um"] = r.sigma0_um;
  j.update(calib::SolveStatisticsToJson(r.solve));  // redundancy .. seconds, groups
  j["timing"] = {{"solve_s", r.timing.solve_s},
                 {"snooping_s", r.timing.snooping_s},
                 {"testing_s", r.timing.testing_s},
                 {"covariance_s", r.timing.covariance_s},
                 {"total_s", r.timing.total_s}};
  j["frame"] = r.frame;
  j["datum"] = r.datum;
  j["self_calibration"] = r.free_interior;
  j["n_observations"] = r.solve.n_observations;
  j["n_unknowns"] = r.solve.n_unknowns;
  j["warnings"] = FindingsToJson(r.warnings);
  j["cameras"] = CamerasToJson(r);
  WritePoints(r, &j);
  j["exposures"] = ExposuresToJson(r.exposures);
  j["rejected"] = RejectedToJson(r);
  j["residuals"] = ResidualsToJson(r);
  j["interior_correlation"] = InteriorCorrelationToJson(r);
  j["determinability"] = DeterminabilityToJson(r.determinability, r.determinability.covariance_ok);
  if (r.platform.gnss || r.platform.imu) j["platform"] = PlatformToJson(r.platform);
  j["notes"] = r.notes;
  if (r.free_set_choice) j["self_calibration_choice"] = FreeSetChoiceJson(*r.free_set_choice);
  j["snooping"] = SnoopingToJson(r.snooping);
  j["valid"] = r.valid;
  j["invalid_reasons"] = r.invalid_reasons;
  return j;
}

std::string FormatSummary(const AdjustmentResult& r) {
  std::string out = StringPrintf(
      "%s adjustment: %s after %d iterations, sigma0 %.4f (%.4f px, %.3f um), redundancy %d\n",
      r.free_interior.empty() ? "conventional" : "self-calibrating",
      r.solve.converged ? "converged" : "NOT converged",
      r.solve.iterations,
      r.sigma0,
      r.sigma0_px,
      r.sigma0_um,
      r.solve.redundancy);
  out += "frame: " + r.frame + "\n";
  out += "datum: " + r.datum + "\n";
  out += StatisticsLine("control", r.control);
  for (const auto& left : r.control_left_out) {
    const PointDifference& p = left.difference;
    out += StringPrintf(
        "control %s LEFT OUT (%s survey; suspected control blunder): survey - block "
        "without it X %.3f  Y %.3f  Z %.3f m, %d rays kept\n",
        p.point.c_str(),
        left.ComponentNames().c_str(),
        -p.difference_m.x(),
        -p.difference_m.y(),
        -p.difference_m.z(),
        p.rays);
  }
  out += StatisticsLine("check", r.check);
  if (r.check_controlled && r.check_controlled->n < r.check.n) {
    out += StatisticsLine("check*", *r.check_controlled);
    out += StringPrintf(
        "  check* = the %d check point(s) whose rays are all controlled; %d rest on rays no test "
        "can judge (a blunder there moves the point unseen):",
        r.check_controlled->n,
        r.check.n - r.check_controlled->n);
    int shown = 0;
    for (const auto& p : r.check_points)
      if (!p.uncontrolled.empty() && shown++ < 10)
        out += StringPrintf(" %s (%.3f m)", p.point.c_str(), p.difference_m.norm());
    out += shown > 10 ? StringPrintf(" ... %d more\n", shown - 10) : std::string("\n");
  }
  if (!r.free_interior.empty()) out += CalibrationTable(r);
  out += RejectedLines(r);
  out += SnoopingLines(r);
  for (const auto& w : r.determinability.warnings) out += "warning: " + w + "\n";
  out += ValidityLines(r);
  for (const auto& w : r.warnings) out += "warning: " + w.message + "\n";
  return out;
}

std::string FormatComparison(const AdjustmentResult& a, const AdjustmentResult& b) {
  std::string out = StringPrintf("%-26s %16s %16s\n", "", "conventional", "self-calibration");
  auto row = [&](const char* label, double x, double y) {
    out += StringPrintf("%-26s %16.4f %16.4f\n", label, x, y);
  };
  row("sigma0 [um]", a.sigma0_um, b.sigma0_um);
  row("sigma0 [px]", a.sigma0_px, b.sigma0_px);
  const char* axes[] = {"X", "Y", "Z"};
  for (int k = 0; k < 3; ++k)
    row(StringPrintf("control RMSE %s [m]", axes[k]).c_str(),
        a.control.rmse_m(k),
        b.control.rmse_m(k));
  for (int k = 0; k < 3; ++k)
    row(StringPrintf("check RMSE %s [m]", axes[k]).c_str(), a.check.rmse_m(k), b.check.rmse_m(k));
  row("check RMSE plan. [m]", a.check.planimetric_rmse_m, b.check.planimetric_rmse_m);
  row("check RMSE spatial [m]", a.check.spatial_rmse_m, b.check.spatial_rmse_m);
  out += StringPrintf("%-26s %16d %16d\n", "check points", a.check.n, b.check.n);
  out += StringPrintf("%-26s %16s %16s\n",
                      "converged",
                      a.solve.converged ? "yes" : "no",
                      b.solve.converged ? "yes" : "no");
  out += "calibration (self-calibrating run):\n" + CalibrationTable(b);
  out += RejectedLines(b);
  out += SnoopingLines(b);
  for (const auto& w : b.determinability.warnings) out += "warning: " + w + "\n";
  out += ValidityLines(a) + ValidityLines(b);
  for (const auto& w : a.warnings) out += "warning (conventional): " + w.message + "\n";
  for (const auto& w : b.warnings) out += "warning: " + w.message + "\n";
  return out;
}

nlohmann::json ComparisonToJson(const AdjustmentResult& a, const AdjustmentResult& b) {
  auto brief = [](const AdjustmentResult& r) {
    return nlohmann::json{{"sigma0", r.sigma0},
                          {"sigma0_px", r.sigma0_px},
                          {"sigma0_um", r.sigma0_um},
                          {"converged", r.solve.converged},
                          {"control", PointStatisticsToJson(r.control)},
                          {"check", PointStatisticsToJson(r.check)}};
  };
  nlohmann::json j = {{"conventional", brief(a)}, {"self_calibration", brief(b)}};
  j["check_spatial_rmse_ratio"] =
      b.check.spatial_rmse_m > 0 ? a.check.spatial_rmse_m / b.check.spatial_rmse_m : 0.0;
  nlohmann::json table = nlohmann::json::array();
  for (const auto& c : b.cameras) {
    const std::vector<calib::ParamInfo> params = calib::CameraModelParams(c.model);
    for (int k = 0; k < static_cast<int>(params.size()); ++k) {
      const double t = CorrectionInSigmas(c, k);
      table.push_back({{"camera", c.id},
                       {"parameter", std::string(params[k].name)},
                       {"unit", std::string(params[k].unit)},
                       {"initial", c.initial[k]},
                       {"correction", c.estimated[k] - c.initial[k]},
                       {"estimate", c.estimated[k]},
                       {"sigma", c.free[k] ? nlohmann::json(c.sigma[k]) : nlohmann::json()},
                       {"t", std::isnan(t) ? nlohmann::json() : nlohmann::json(t)}});
    }
  }
  j["calibration"] = table;
  return j;
}

calib::Camera UpdatedCamera(const calib::Camera& camera, const CameraEstimate& estimate) {
  AEROCAL_CHECK(estimate.model == camera.model)
      << "camera " << camera.name << ": estimate in model "
      << calib::CameraModelName(estimate.model) << ", camera in "
      << calib::CameraModelName(camera.model);
  calib::Camera out = camera;
  out.interior = estimate.estimated;
  return out;
}

}  // namespace aerocal::triangulation
