#include "stitch/quality/quality_json.h"

#include <cmath>

namespace aerocal::stitch {
namespace {

nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json();
}

nlohmann::json Numbers(const std::vector<double>& values) {
  nlohmann::json array = nlohmann::json::array();
  for (double v : values) array.push_back(Number(v));
  return array;
}

}  // namespace

nlohmann::json SlantedEdgeToJson(const SlantedEdgeResult& r) {
  nlohmann::json budget = nlohmann::json::array();
  for (const auto& c : r.budget)
    budget.push_back({{"name", c.name},
                      {"type", c.type},
                      {"distribution", c.distribution},
                      {"u_cy_px", Number(c.u)}});
  return {{"axis", std::string(MtfAxisName(r.axis))},
          {"angle_deg", r.angle_deg},
          {"slope_sigma", r.slope_sigma},
          {"edge_offset_px", r.edge_offset_px},
          {"contrast", r.contrast},
          {"noise_sigma", r.noise_sigma},
          {"empty_bins", r.empty_bins},
          {"mtf50_cy_px", Number(r.mtf50_cy_px)},
          {"mtf10_cy_px", Number(r.mtf10_cy_px)},
          {"mtf_nyquist", Number(r.mtf_nyquist)},
          {"mtf50_u_cy_px", Number(r.mtf50_u_cy_px)},
          {"mtf50_expanded_cy_px", Number(r.mtf50_expanded_cy_px)},
          {"coverage_factor", r.coverage_factor},
          {"budget", budget},
          {"curve", {{"frequency_cy_px", Numbers(r.frequency_cy_px)}, {"mtf", Numbers(r.mtf)}}},
          {"esf", {{"distance_px", Numbers(r.esf_distance_px)}, {"value", Numbers(r.esf)}}}};
}

nlohmann::json EdgeCombinationToJson(const EdgeMtfCombination& c) {
  return {{"count", c.count},
          {"mtf50_cy_px", Number(c.mtf50_cy_px)},
          {"type_a_u_cy_px", Number(c.type_a_u_cy_px)},
          {"type_b_u_cy_px", Number(c.type_b_u_cy_px)},
          {"mtf50_u_cy_px", Number(c.mtf50_u_cy_px)},
          {"mtf50_expanded_cy_px", Number(c.mtf50_expanded_cy_px)},
          {"coverage_factor", 2.0}};
}

}  // namespace aerocal::stitch
