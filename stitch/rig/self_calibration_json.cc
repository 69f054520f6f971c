#include "stitch/rig/self_calibration_json.h"

#include "calib/core/finding.h"
#include "calib/core/string_printf.h"
#include "calib/problem/solve_statistics_json.h"

#include <cmath>

namespace aerocal::stitch {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

nlohmann::json NumberOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json();
}

nlohmann::json RmsJson(const StitchRms& r) {
  return {{"per_coordinate", NumberOrNull(r.per_coordinate)},
          {"pair_2d", NumberOrNull(r.pair_2d)},
          {"pairs", r.pairs},
          {"ties", r.ties}};
}

nlohmann::json SetJson(const StitchRmsSet& s) {
  return {{"fit", RmsJson(s.fit)}, {"check", RmsJson(s.check)}};
}

nlohmann::json BeforeAfterJson(const StitchRmsSet& before, const StitchRmsSet& after) {
  return {{"before", SetJson(before)}, {"after", SetJson(after)}};
}

nlohmann::json ZonesJson(const std::vector<ZoneStitchRms>& zones) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& z : zones)
    out.push_back({{"zone", z.zone}, {"stitching_rms_px", BeforeAfterJson(z.before, z.after)}});
  return out;
}

std::string Px(double value) {
  return std::isfinite(value) ? StringPrintf("%.3f", value) : std::string("-");
}

// What the two RMS metrics, before / after and fit / check mean.
nlohmann::json MetricJson() {
  return {
      {"unit", "px of the level virtual image"},
      {"per_coordinate", "sqrt(sum(dx^2 + dy^2) / (2 n_pairs)) over the head pairs of each tie"},
      {"pair_2d",
       "sqrt(sum(dx^2 + dy^2) / n_pairs): the 2-D pair disagreement, sqrt(2) x "
       "per_coordinate"},
      {"before", "ground calibration alone (E = I, dT = 0)"},
      {"after", "the estimated increments and offsets"},
      {"fit", "ties used in the adjustment (their observations left after the snooping)"},
      {"check", "check ties (points.csv role check without coordinates): never adjusted"}};
}

// One exposure's head: increments in deg and dT in ms, each sigma null where held or not
// determinable (a zero increment sigma: no covariance).
nlohmann::json RigExposureJson(const std::string& image, const RigStitchHead& h) {
  const Eigen::Vector3d deg = h.increment_rad * kDegPerRad;
  nlohmann::json sigma = {
      {"domega", nullptr}, {"dphi", nullptr}, {"dkappa", nullptr}, {"dT_ms", nullptr}};
  if (!h.reference && h.increment_sigma_rad.norm() > 0) {  // 0: no covariance
    sigma["domega"] = h.increment_sigma_rad.x() * kDegPerRad;
    sigma["dphi"] = h.increment_sigma_rad.y() * kDegPerRad;
    sigma["dkappa"] = h.increment_sigma_rad.z() * kDegPerRad;
  }
  if (h.dt_sigma_s) sigma["dT_ms"] = *h.dt_sigma_s * 1e3;
  return {{"image", image},
          {"head", h.head},
          {"reference", h.reference},
          {"domega", deg.x()},
          {"dphi", deg.y()},
          {"dkappa", deg.z()},
          {"dT_ms", h.dt_s ? nlohmann::json(*h.dt_s * 1e3) : nlohmann::json()},
          {"sigma", sigma}};
}

// `exposures` (RMS per exposure and zone) and `rig_exposures` (per exposure and head).
void WriteExposures(const RigStitchResult& result, nlohmann::json* doc) {
  nlohmann::json exposures = nlohmann::json::array();
  nlohmann::json rig_exposures = nlohmann::json::array();
  for (const RigStitchExposureResult& e : result.exposures) {
    exposures.push_back({{"image", e.image},
                         {"stitching_rms_px", BeforeAfterJson(e.before, e.after)},
                         {"zones", ZonesJson(e.zones)}});
    for (const RigStitchHead& h : e.heads) rig_exposures.push_back(RigExposureJson(e.image, h));
  }
  (*doc)["exposures"] = exposures;
  (*doc)["rig_exposures"] = rig_exposures;
}

nlohmann::json TimeOffsetsJson(const RigStitchOptions& options, const RigStitchResult& result) {
  nlohmann::json correlations = nlohmann::json::array();
  for (const auto& c : result.dt_correlations)
    correlations.push_back({{"dT", c.dt}, {"angle", c.angle}, {"rho", c.rho}});
  return {{"held", result.dt_held},
          {"determinable", result.dt_determinable},
          {"correlation_threshold", options.correlation_threshold},
          {"correlations", correlations}};
}

nlohmann::json SnoopingJson(const RigStitchOptions& options, const RigStitchResult& result) {
  nlohmann::json positions = nlohmann::json::array();
  for (const auto& s : result.standard_positions)
    positions.push_back({{"image", s.image},
                         {"name", s.name},
                         {"ties_before", s.ties_before},
                         {"ties_after", s.ties_after}});
  return {{"enabled", options.snooping},
          {"alpha", options.alpha},
          {"rejected", result.rejected},
          {"stopped", result.stopped},
          {"stop_reasons", result.stop_reasons},
          {"stop_effect",
           result.stopped ? calib::SuspectEffectJson(result.stop_effect) : nlohmann::json()},
          {"standard_positions", positions}};
}

nlohmann::json ReliefJson(const RigStitchResult& result, const RigStitchSources& sources) {
  return {{"relief_m", sources.relief_m ? nlohmann::json(*sources.relief_m) : nlohmann::json()},
          {"height_m", result.height_m},
          {"largest_px",
           sources.relief_m ? nlohmann::json(result.relief_displacement_px) : nlohmann::json()},
          {"formula",
           "(c_v / p) |t_j - t_k| dh / (H (H - dh)), largest over the head pairs "
           "(CONVENTIONS.md \"Multi-head rigs\")"}};
}

}  // namespace

nlohmann::json RigStitchToJson(const calib::Rig& rig,
                               const RigStitchOptions& options,
                               const RigStitchResult& result,
                               const RigStitchSources& sources) {
  nlohmann::json doc;
  doc["kind"] = "rig_stitch";
  doc["camera"] = sources.camera;
  doc["project"] = sources.project;
  doc["mode"] = RigStitchModeName(options.mode);
  doc["reference_head"] = rig.reference_head;
  doc.update(calib::SolveStatisticsToJson(result.report));  // redundancy .. seconds, groups
  doc["sigma0"] = result.sigma0;
  doc["sigma0_px"] = result.sigma0_px;
  doc["valid"] = result.failures.empty();
  doc["invalid_reasons"] = result.failures;  // common.schema.json, as adjust
  doc["warnings"] = FindingsToJson(result.warnings);
  doc["metric"] = MetricJson();
  doc["stitching_rms_px"] = BeforeAfterJson(result.before, result.after);
  doc["zones"] = ZonesJson(result.zones);
  WriteExposures(result, &doc);
  doc["time_offsets"] = TimeOffsetsJson(options, result);
  doc["snooping"] = SnoopingJson(options, result);
  doc["dropped_ties"] = result.dropped_ties;
  doc["relief_displacement"] = ReliefJson(result, sources);
  return doc;
}

std::string FormatRigStitchSummary(const RigStitchOptions& options,
                                   const RigStitchResult& result,
                                   const RigStitchSources& sources) {
  std::string out = StringPrintf(
      "rig stitch (%s mode): %zu exposures, sigma0 %.3f (%.3f px), redundancy %d, %s in %d "
      "iterations\n",
      RigStitchModeName(options.mode),
      result.exposures.size(),
      result.sigma0,
      result.sigma0_px,
      result.redundancy,
      result.report.converged ? "converged" : "NOT converged",
      result.report.iterations);
  out += "stitching RMS, virtual px per coordinate (pair_2d = sqrt(2) x): before -> after\n";
  out += StringPrintf("%-10s %16s %16s\n", "exposure", "fit ties", "check ties");
  const auto row = [&](const std::string& name, const StitchRmsSet& b, const StitchRmsSet& a) {
    out += StringPrintf("%-10s %7s -> %-6s %7s -> %-6s\n",
                        name.c_str(),
                        Px(b.fit.per_coordinate).c_str(),
                        Px(a.fit.per_coordinate).c_str(),
                        Px(b.check.per_coordinate).c_str(),
                        Px(a.check.per_coordinate).c_str());
  };
  for (const auto& e : result.exposures) row(e.image, e.before, e.after);
  row("flight", result.before, result.after);
  if (!result.exposures.empty()) {
    out += "time offsets dT (ms, head - reference):";
    for (const RigStitchHead& h : result.exposures.front().heads) {
      if (h.reference) continue;
      out += " " + h.head + " ";
      if (result.dt_held) {
        out += "held 0";
      } else if (options.mode == RigStitchMode::kPerExposure) {
        out += "per exposure";
      } else {
        out += h.dt_s ? StringPrintf("%.3f", *h.dt_s * 1e3) : std::string("not determinable");
        if (h.dt_sigma_s) out += StringPrintf(" +- %.3f", *h.dt_sigma_s * 1e3);
      }
    }
    out += "\n";
  }
  double largest = 0.0;
  const DtCorrelation* worst = nullptr;
  for (const auto& c : result.dt_correlations)
    if (std::abs(c.rho) >= largest) {
      largest = std::abs(c.rho);
      worst = &c;
    }
  if (worst)
    out += StringPrintf("largest dT-angle correlation: %s with %s, rho %.3f%s\n",
                        worst->dt.c_str(),
                        worst->angle.c_str(),
                        worst->rho,
                        result.dt_determinable ? "" : " (dT not determinable: not reported)");
  out += StringPrintf("snooping: %zu observation(s) rejected%s\n",
                      result.rejected.size(),
                      result.stopped ? ", STOPPED at a standard position" : "");
  if (sources.relief_m)
    out += StringPrintf("relief of %g m off the plane at H = %.1f m: up to %.3f px between heads\n",
                        *sources.relief_m,
                        result.height_m,
                        result.relief_displacement_px);
  for (const auto& w : result.warnings) out += "warning: " + w.message + "\n";
  for (const auto& f : result.failures) out += "FAILED: " + f + "\n";
  return out;
}

}  // namespace aerocal::stitch
