#include "stitch/rig/error_analysis_json.h"

#include "calib/core/error.h"
#include "stitch/rig/rig_conversion.h"

#include <cstdio>

namespace aerocal::stitch {
namespace {

using nlohmann::json;

json Pair(const Eigen::Vector2d& v) { return json::array({v.x(), v.y()}); }

// Limit of a source in the units of the limits file.
std::pair<double, std::string> FileLimit(const ErrorSource& s, const ErrorLimits& limits) {
  switch (s.kind) {
    case ErrorSourceKind::kPrincipalPoint:
      return {limits.principal_point_px, "px"};
    case ErrorSourceKind::kPrincipalDistance:
      return {limits.principal_distance_px, "px"};
    case ErrorSourceKind::kOmega:
    case ErrorSourceKind::kPhi:
    case ErrorSourceKind::kKappa:
      return {limits.angles_arcsec, "arcsec"};
    case ErrorSourceKind::kTx:
    case ErrorSourceKind::kTy:
    case ErrorSourceKind::kTz:
      return {limits.lever_arm_mm, "mm"};
    case ErrorSourceKind::kHeight:
      return {limits.height_m, "m"};
  }
  return {0.0, ""};
}

json OptionalNumber(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::string Number(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.10g", v);
  return buffer;
}

json TargetJson(const calib::Rig& rig, const TargetAnalysis& t) {
  return {{"head", rig.heads[t.head].id},
          {"head_px", Pair(t.head_px)},
          {"virtual_px", Pair(t.virtual_px)},
          {"reference_head", rig.reference_head},
          {"reference_px", Pair(t.reference_px)}};
}

json LinearJson(const std::vector<ErrorSource>& sources, const LinearPropagation& linear) {
  json share = json::object();
  for (size_t i = 0; i < sources.size(); ++i)
    share[sources[i].name] =
        json::array({OptionalNumber(linear.share_x[i]), OptionalNumber(linear.share_y[i])});
  return {{"sigma_px", Pair(linear.sigma_px)},
          {"bound_px", Pair(linear.bound_px)},
          {"bound_radial_px", linear.bound_radial_px},
          {"probability", 0.9975},
          {"z", NormalBound99_75()},
          {"share", share}};
}

json MonteCarloJson(const MonteCarloResult& mc, const ErrorAnalysisFiles& files) {
  json out = {{"n", mc.n},
              {"seed", mc.seed},
              {"failed", mc.failed},
              {"sigma_px", Pair(mc.sigma_px)},
              {"mean_px", Pair(mc.mean_px)},
              {"bound_px", Pair(mc.bound_px)},
              {"bound_radial_px", mc.bound_radial_px},
              {"max_abs_px", Pair(mc.max_abs_px)},
              {"max_radial_px", mc.max_radial_px},
              {"probability", 0.9975}};
  if (!files.histogram_csv.empty()) out["histogram_csv"] = files.histogram_csv;
  if (!files.histogram_png.empty()) out["histogram_png"] = files.histogram_png;
  return out;
}

void AppendHistogram(const std::string& quantity,
                     const std::vector<double>& values,
                     double lo,
                     double hi,
                     int bins,
                     std::string* out) {
  const std::vector<long> counts = Histogram(values, lo, hi, bins);
  for (int b = 0; b < bins; ++b)
    *out += quantity + "," + Number(lo + (hi - lo) * b / bins) + "," +
            Number(lo + (hi - lo) * (b + 1) / bins) + "," + std::to_string(counts[b]) + "\n";
}

json SourcesJson(const std::vector<ErrorSource>& sources, const ErrorLimits& limits) {
  json source_list = json::array();
  for (const ErrorSource& s : sources) {
    const auto [limit, unit] = FileLimit(s, limits);
    source_list.push_back(
        {{"source", s.name}, {"limit", limit}, {"sigma", limit / limits.sigmas}, {"unit", unit}});
  }
  return source_list;
}

json WorstCasesJson(const std::vector<WorstCase>& worst_cases) {
  json worst = json::array();
  for (const WorstCase& w : worst_cases) {
    json signs = json::object();
    for (size_t j = 0; j < w.sources.size(); ++j) signs[w.sources[j]] = w.signs[j];
    worst.push_back({{"group", w.group},
                     {"sources", w.sources},
                     {"exhaustive", w.exhaustive},
                     {"max_abs_px", Pair(w.max_abs_px)},
                     {"max_radial_px", w.max_radial_px},
                     {"signs", signs},
                     {"sum_abs_px", Pair(w.sum_abs_px)}});
  }
  return worst;
}

// Relief: displacement between the reference head and each other head of a point relief_m off
// the plane (CONVENTIONS.md formula).
json ReliefJson(const calib::Rig& rig, double height_m, double relief_m) {
  json relief = {{"dh_m", relief_m}, {"pairs", json::array()}};
  const int reference = rig.ReferenceIndex();
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k) {
    if (k == reference) continue;
    relief["pairs"].push_back(
        {{"heads", json::array({rig.reference_head, rig.heads[k].id})},
         {"displacement_px",
          relief_m < height_m ? json(ReliefDisplacementPx(rig, reference, k, height_m, relief_m))
                              : json(nullptr)}});
  }
  return relief;
}

json GridPointJson(const calib::Rig& rig, const TargetAnalysis& t) {
  const WorstCase& all = t.worst_cases.back();
  json point = TargetJson(rig, t);
  point["linear"] = {{"sigma_px", Pair(t.linear.sigma_px)},
                     {"bound_px", Pair(t.linear.bound_px)},
                     {"bound_radial_px", t.linear.bound_radial_px}};
  point["max_error"] = {{"max_radial_px", all.max_radial_px}, {"max_abs_px", Pair(all.max_abs_px)}};
  point["monte_carlo"] = t.monte_carlo ? json{{"sigma_px", Pair(t.monte_carlo->sigma_px)},
                                              {"bound_px", Pair(t.monte_carlo->bound_px)},
                                              {"bound_radial_px", t.monte_carlo->bound_radial_px},
                                              {"max_abs_px", Pair(t.monte_carlo->max_abs_px)}}
                                       : json(nullptr);
  return point;
}

json GridJson(const calib::Rig& rig, const GridAnalysis& grid, const ErrorAnalysisFiles& files) {
  json points = json::array();
  for (const TargetAnalysis& t : grid.points) points.push_back(GridPointJson(rig, t));
  json unseen = json::array();
  for (const auto& p : grid.unseen) unseen.push_back(Pair(p));
  json out = {{"n", grid.n},
              {"points", points},
              {"unseen_virtual_px", unseen},
              {"worst_index", grid.worst}};
  if (!files.bound_map_csv.empty()) out["bound_map_csv"] = files.bound_map_csv;
  if (!files.bound_map_png.empty()) out["bound_map_png"] = files.bound_map_png;
  return out;
}

}  // namespace

GridAnalysis AnalyseGrid(const calib::Rig& rig,
                         double height_m,
                         const ErrorLimits& limits,
                         int n,
                         int samples,
                         std::uint64_t seed) {
  AEROCAL_CHECK(n >= 1) << "grid " << n;
  GridAnalysis grid;
  grid.n = n;
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, height_m));
  const calib::Camera& v = rig.virtual_camera.camera;
  const int reference = rig.ReferenceIndex();
  std::uint64_t index = 0;
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const Eigen::Vector2d virtual_px((col + 0.5) * v.width_px / n - 0.5,
                                       (row + 0.5) * v.height_px / n - 0.5);
      bool seen = false;
      for (int head = 0; head < static_cast<int>(rig.heads.size()); ++head) {
        if (head == reference) continue;
        const auto pixel = converter.HeadFromVirtual(head, virtual_px);
        if (!pixel || !converter.InHeadFormat(head, *pixel)) continue;
        seen = true;
        grid.points.push_back(
            AnalyseTarget(rig, height_m, limits, head, virtual_px, samples, seed + index, false));
        ++index;
        const TargetAnalysis& added = grid.points.back();
        if (grid.worst < 0 ||
            added.linear.bound_radial_px > grid.points[grid.worst].linear.bound_radial_px)
          grid.worst = static_cast<int>(grid.points.size()) - 1;
      }
      if (!seen) grid.unseen.push_back(virtual_px);
    }
  }
  return grid;
}

json ErrorAnalysisToJson(const calib::Rig& rig,
                         double height_m,
                         const ErrorLimits& limits,
                         const TargetAnalysis& target,
                         const GridAnalysis* grid,
                         double relief_m,
                         const ErrorAnalysisFiles& files) {
  const std::vector<ErrorSource> sources = MakeErrorSources(rig, limits);
  json doc;
  doc["kind"] = "rig_error_analysis";
  doc["rig"] = rig.name;
  doc["reference_head"] = rig.reference_head;
  doc["height_m"] = height_m;
  doc["limits"] = {{"principal_point_px", limits.principal_point_px},
                   {"principal_distance_px", limits.principal_distance_px},
                   {"angles_arcsec", limits.angles_arcsec},
                   {"lever_arm_mm", limits.lever_arm_mm},
                   {"height_m", limits.height_m},
                   {"sigmas", limits.sigmas}};
  doc["sources"] = SourcesJson(sources, limits);
  doc["target"] = TargetJson(rig, target);
  json rows = json::array();
  for (const SourceErrorRow& row : target.per_source)
    rows.push_back(
        {{"source", row.source}, {"plus_px", Pair(row.plus_px)}, {"minus_px", Pair(row.minus_px)}});
  doc["per_source"] = rows;
  doc["worst_case"] = WorstCasesJson(target.worst_cases);
  doc["linear"] = LinearJson(sources, target.linear);
  doc["monte_carlo"] =
      target.monte_carlo ? MonteCarloJson(*target.monte_carlo, files) : json(nullptr);
  doc["relief"] = ReliefJson(rig, height_m, relief_m);
  if (grid) doc["grid"] = GridJson(rig, *grid, files);
  return doc;
}

std::string HistogramCsv(const MonteCarloResult& mc, int bins) {
  std::vector<double> ex, ey, radial;
  for (const auto& e : mc.errors) {
    ex.push_back(e.x());
    ey.push_back(e.y());
    radial.push_back(e.norm());
  }
  std::string out = "quantity,bin_low_px,bin_high_px,count\n";
  const auto half = [](double v) { return v > 0 ? v : 1.0; };  // all-zero errors: one unit
  AppendHistogram("ex", ex, -half(mc.max_abs_px.x()), half(mc.max_abs_px.x()), bins, &out);
  AppendHistogram("ey", ey, -half(mc.max_abs_px.y()), half(mc.max_abs_px.y()), bins, &out);
  AppendHistogram("radial", radial, 0.0, half(mc.max_radial_px), bins, &out);
  return out;
}

std::string BoundMapCsv(const calib::Rig& rig, const GridAnalysis& grid) {
  std::string out =
      "virtual_col,virtual_row,head,head_col,head_row,linear_sigma_x_px,linear_sigma_y_px,"
      "linear_bound_radial_px,max_error_radial_px,mc_bound_radial_px\n";
  for (const TargetAnalysis& t : grid.points) {
    out += Number(t.virtual_px.x()) + "," + Number(t.virtual_px.y()) + "," + rig.heads[t.head].id +
           "," + Number(t.head_px.x()) + "," + Number(t.head_px.y()) + "," +
           Number(t.linear.sigma_px.x()) + "," + Number(t.linear.sigma_px.y()) + "," +
           Number(t.linear.bound_radial_px) + "," + Number(t.worst_cases.back().max_radial_px) +
           "," + (t.monte_carlo ? Number(t.monte_carlo->bound_radial_px) : std::string()) + "\n";
  }
  return out;
}

}  // namespace aerocal::stitch
