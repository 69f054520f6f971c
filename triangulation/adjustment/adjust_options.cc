#include "triangulation/adjustment/adjust_options.h"

#include "calib/camera/camera.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <algorithm>
#include <set>
#include <sstream>

namespace aerocal::triangulation {

void AdjustOptions::Validate() const {
  std::set<std::string> seen;
  for (const auto& name : free_interior) {
    // The names of any registered model; the frame camera checks them against each camera's own
    // model when the adjustment starts.
    bool known = false;
    calib::ForEachCameraModel([&](auto model) {
      known = known || calib::IndexOfParam(decltype(model)::kParams, name) >= 0;
    });
    if (!known)
      throw ConfigError("free_interior: unknown parameter '" + name +
                        "' (expected c, x0, y0, K1, K2, K3, P1, P2, B1, B2 or a parameter of the "
                        "camera's model)");
    if (!seen.insert(name).second)
      throw ConfigError("free_interior: parameter '" + name + "' listed twice");
  }
  if (snooping_critical_value < 0)
    throw ConfigError("snooping_critical_value must be >= 0 (got " +
                      FormatNumber(snooping_critical_value) + ")");
  if (!(robust_scale_sigma > 0))
    throw ConfigError("robust_scale_sigma must be > 0 (got " + FormatNumber(robust_scale_sigma) +
                      ")");
  if (!(robust_reject_sigma > 0))
    throw ConfigError("robust_reject_sigma must be > 0 (got " + FormatNumber(robust_reject_sigma) +
                      ")");
  auto in_range =
      [](const char* name, double value, double lo, double hi, bool lo_open, bool hi_open) {
        const bool ok =
            (lo_open ? value > lo : value >= lo) && (hi_open ? value < hi : value <= hi);
        if (!ok)
          throw ConfigError(std::string(name) + " must be in " + (lo_open ? "(" : "[") +
                            FormatNumber(lo) + ", " + FormatNumber(hi) + (hi_open ? ")" : "]") +
                            " (got " + FormatNumber(value) + ")");
      };
  in_range("snooping_alpha", snooping_alpha, 0, 1, true, true);
  in_range("snooping_power", snooping_power, 0.5, 1, true, true);
  in_range("min_redundancy", min_redundancy, 0, 1, false, true);
  in_range("group_correlation", group_correlation, 0, 1, true, false);
  in_range("robust_trigger_share", robust_trigger_share, 0, 1, false, true);
  if (!(robust_trigger_w > 0))
    throw ConfigError("robust_trigger_w must be > 0 (got " + FormatNumber(robust_trigger_w) + ")");
  if (!(model_error_sigma0 > 0))
    throw ConfigError("model_error_sigma0 must be > 0 (got " + FormatNumber(model_error_sigma0) +
                      ")");
  if (!(max_sigma0 > 0))
    throw ConfigError("max_sigma0 must be > 0 (got " + FormatNumber(max_sigma0) + ")");
  if (!(suspect_effect_limit > 0 && suspect_effect_limit <= 1e3))
    throw ConfigError("suspect_effect_limit must be in (0, 1000] sigmas (got " +
                      FormatNumber(suspect_effect_limit) + ")");
  if (max_rejections < 0)
    throw ConfigError(
        "max_rejections must be >= 0 (0: 10 % of the tested observations, at least "
        "100; got " +
        std::to_string(max_rejections) + ")");
  if (!(correlation_threshold > 0 && correlation_threshold < 1))
    throw ConfigError("correlation_threshold must be in (0, 1) (got " +
                      FormatNumber(correlation_threshold) + ")");
  if (solver.max_iterations < 1)
    throw ConfigError("solver.max_iterations must be > 0 (got " +
                      std::to_string(solver.max_iterations) + ")");
}

std::vector<std::string> ParseSelfCalibration(const std::string& text, calib::CameraModelId model) {
  if (text == "none" || text.empty()) return {};
  std::vector<std::string> names;
  const std::vector<calib::ParamInfo> table = calib::CameraModelParams(model);
  if (text == "all") {
    for (const auto& p : table) names.emplace_back(p.name);
    return names;
  }
  for (const std::string& name : SplitCommaList(text)) {
    if (std::none_of(table.begin(), table.end(), [&](const auto& p) { return p.name == name; }))
      throw ConfigError("--self-calibration: unknown parameter '" + name +
                        "' (expected none, all or a list of the parameters of model " +
                        std::string(calib::CameraModelName(model)) + ": " +
                        calib::JoinParamNames(table) + ")");
    names.push_back(name);
  }
  AdjustOptions probe;
  probe.free_interior = names;
  probe.Validate();
  return names;
}

}  // namespace aerocal::triangulation
