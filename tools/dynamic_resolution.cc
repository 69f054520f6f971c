// The "dynamic image resolution" section from `aerocal quality` results (dynamic_resolution.h):
// per edge the slanted-edge MTF50 with U (and its units), MTF at Nyquist and the curve; per axis
// the repeated edges combined; per bar target and per Siemens star the limiting frequency; per
// axis the resampling loss of the virtual image. Values are copied, only the loss is computed.
#include "tools/dynamic_resolution.h"

#include "calib/core/error.h"
#include "calib/core/result_file.h"

#include <cmath>
#include <initializer_list>
#include <map>

namespace aerocal::tools {
namespace {

void CopyKeys(const nlohmann::json& from,
              nlohmann::json* to,
              std::initializer_list<const char*> keys) {
  for (const char* key : keys)
    if (from.contains(key)) (*to)[key] = from[key];
}

nlohmann::json StarJson(const nlohmann::json& doc, const std::string& path) {
  nlohmann::json star = {{"source", path}};
  CopyKeys(doc,
           &star,
           {"method",
            "star",
            "options",
            "reference_modulation",
            "rings",
            "limiting_frequency_cy_px",
            "limit_in_range",
            "limiting_radius_px",
            "limiting_lp_per_mm",
            "limiting_resolved_distance_m"});
  return star;
}

nlohmann::json BarsJson(const nlohmann::json& doc, const std::string& path) {
  nlohmann::json bars = {{"source", path}};
  CopyKeys(doc,
           &bars,
           {"method",
            "options",
            "reference_modulation",
            "groups",
            "limiting_frequency_cy_px",
            "limit_in_range",
            "limiting_lp_per_mm",
            "limiting_resolved_distance_m"});
  return bars;
}

// A `quality mtf` result's edges and axes into the section, each with its source and which image
// (raw sub-image / virtual) it was measured in.
void AddMtfResult(const nlohmann::json& doc, const std::string& path, nlohmann::json* section) {
  (*section)["method"] = doc.at("method");
  nlohmann::json origin = {{"source", path}};
  CopyKeys(doc, &origin, {"image_kind", "sub_image"});
  if (doc.contains("targets")) CopyKeys(doc.at("targets"), &origin, {"image_id"});
  if (doc.contains("virtual_format_px") && !section->contains("virtual_format_px"))
    (*section)["virtual_format_px"] = doc["virtual_format_px"];
  for (const auto& e : doc.at("edges")) {
    nlohmann::json edge = origin;
    CopyKeys(e,
             &edge,
             {"roi",
              "axis",
              "direction",
              "angle_deg",
              "mtf50_cy_px",
              "mtf50_expanded_cy_px",
              "coverage_factor",
              "mtf_nyquist",
              "mtf50_lp_per_mm",
              "mtf50_lp_per_mm_expanded",
              "mtf50_resolved_distance_m",
              "mtf50_resolved_distance_expanded_m",
              "curve",
              "budget",
              "target",
              "position_virtual_px",
              "resampling"});
    (*section)["edges"].push_back(edge);
  }
  for (const auto& [axis, c] : doc.at("axes").items()) {
    nlohmann::json combined = origin;
    combined["axis"] = axis;
    CopyKeys(c,
             &combined,
             {"direction",
              "count",
              "mtf50_cy_px",
              "type_a_u_cy_px",
              "type_b_u_cy_px",
              "mtf50_u_cy_px",
              "mtf50_expanded_cy_px",
              "mtf50_lp_per_mm",
              "mtf50_lp_per_mm_expanded",
              "mtf50_resolved_distance_m",
              "mtf50_resolved_distance_expanded_m"});
    (*section)["axes"].push_back(combined);
  }
}

// The mean of independent values and its standard uncertainty sqrt(sum u_i^2) / n.
struct Mean {
  double sum = 0.0, sum_u2 = 0.0;
  int n = 0;
  void Add(double value, double u) { sum += value, sum_u2 += u * u, ++n; }
  double Value() const { return sum / n; }
  double U() const { return std::sqrt(sum_u2) / n; }
};

// A number of a JSON object, NaN when absent or null.
double NumberAt(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

// Plain means of values (NaN ones left out); null when there are none.
struct PlainMean {
  double sum = 0.0;
  int n = 0;
  void Add(double v) {
    if (std::isfinite(v)) sum += v, ++n;
  }
  nlohmann::json Json() const { return n > 0 ? nlohmann::json(sum / n) : nlohmann::json(); }
};

}  // namespace

nlohmann::json ResamplingPerSubImageJson(const nlohmann::json& edges) {
  struct Row {
    nlohmann::json direction;
    PlainMean raw, virtual_image, loss, predicted, uniform;
    int edges = 0, measured = 0;
  };
  std::map<std::pair<std::string, std::string>, Row> rows;  // by sub-image and axis
  for (const auto& e : edges) {
    if (!e.contains("resampling") || !e["resampling"].is_object()) continue;
    const nlohmann::json& r = e["resampling"];
    Row& row = rows[{e.value("sub_image", ""), e.value("axis", "")}];
    if (e.contains("direction")) row.direction = e["direction"];
    ++row.edges;
    row.raw.Add(NumberAt(e, "mtf50_cy_px"));
    row.predicted.Add(NumberAt(r, "predicted_loss_percent"));
    row.uniform.Add(NumberAt(r, "uniform_phase_loss_percent"));
    if (!std::isfinite(NumberAt(r, "virtual_mtf50_cy_px"))) continue;
    ++row.measured;
    row.virtual_image.Add(NumberAt(r, "virtual_mtf50_cy_px"));
    row.loss.Add(NumberAt(r, "loss_percent"));
  }
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [key, row] : rows)
    out.push_back({{"sub_image", key.first},
                   {"axis", key.second},
                   {"direction", row.direction},
                   {"edges", row.edges},
                   {"raw_mean_mtf50_cy_px", row.raw.Json()},
                   {"virtual_measured", row.measured},
                   {"virtual_mean_mtf50_cy_px", row.virtual_image.Json()},
                   {"mean_loss_percent", row.loss.Json()},
                   {"mean_predicted_loss_percent", row.predicted.Json()},
                   {"mean_uniform_phase_loss_percent", row.uniform.Json()}});
  return out;
}

nlohmann::json ResamplingLossJson(const nlohmann::json& axes) {
  constexpr double kCoverage = 2.0;
  struct PerAxis {
    Mean raw, virtual_image;
    nlohmann::json sub_images = nlohmann::json::array(), direction;
  };
  std::map<std::string, PerAxis> by_axis;
  for (const auto& a : axes) {
    const std::string kind = a.value("image_kind", "");
    const nlohmann::json& m = a.value("mtf50_cy_px", nlohmann::json());
    const nlohmann::json& u = a.value("mtf50_u_cy_px", nlohmann::json());
    if ((kind != "raw" && kind != "virtual") || !m.is_number() || !u.is_number()) continue;
    // A `--targets` result (it names its exposure) holds edges of one exposure, each compared with
    // the virtual image in its own `resampling` block (ResamplingPerSubImageJson); taken here too,
    // its sub-image would count twice beside the whole-mosaic result of the same sub-image.
    if (a.contains("image_id")) continue;
    PerAxis& p = by_axis[a.at("axis").get<std::string>()];
    if (a.contains("direction")) p.direction = a["direction"];
    if (kind == "virtual") {
      p.virtual_image.Add(m.get<double>(), u.get<double>());
      continue;
    }
    p.raw.Add(m.get<double>(), u.get<double>());
    p.sub_images.push_back(a.value("sub_image", ""));
  }
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [axis, p] : by_axis) {
    if (p.raw.n == 0 || p.virtual_image.n == 0) continue;
    const double raw = p.raw.Value(), virt = p.virtual_image.Value();
    const double u = std::hypot(p.raw.U(), p.virtual_image.U());
    out.push_back({{"axis", axis},
                   {"direction", p.direction},
                   {"sub_images", p.sub_images},
                   {"raw_mean_mtf50_cy_px", raw},
                   {"raw_mean_u_cy_px", p.raw.U()},
                   {"virtual_results", p.virtual_image.n},
                   {"virtual_mtf50_cy_px", virt},
                   {"virtual_u_cy_px", p.virtual_image.U()},
                   {"loss_cy_px", raw - virt},
                   {"loss_u_cy_px", u},
                   {"loss_expanded_cy_px", kCoverage * u},
                   {"loss_percent", 100.0 * (raw - virt) / raw},
                   {"loss_expanded_percent", 100.0 * kCoverage * u / raw},
                   {"coverage_factor", kCoverage}});
  }
  return out;
}

nlohmann::json DynamicResolutionJson(const std::vector<std::string>& paths) {
  nlohmann::json section = {{"sources", paths},
                            {"edges", nlohmann::json::array()},
                            {"axes", nlohmann::json::array()},
                            {"bars", nlohmann::json::array()},
                            {"stars", nlohmann::json::array()}};
  for (const std::string& path : paths) {
    const nlohmann::json doc =
        ReadResult(path, {"quality_mtf", "quality_bars", "quality_star"}, "`aerocal quality`");
    // A value of the wrong JSON type or a missing table is bad input naming the file (exit 2).
    try {
      if (doc.at("kind") == "quality_star")
        section["stars"].push_back(StarJson(doc, path));
      else if (doc.at("kind") == "quality_bars")
        section["bars"].push_back(BarsJson(doc, path));
      else
        AddMtfResult(doc, path, &section);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(path + ": not a result written by aerocal (--quality): " + e.what());
    }
  }
  section["resampling_loss"] = ResamplingLossJson(section["axes"]);
  section["resampling_per_sub_image"] = ResamplingPerSubImageJson(section["edges"]);
  return section;
}

}  // namespace aerocal::tools
