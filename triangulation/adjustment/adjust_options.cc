#include "triangulation/adjustment/adjust_options.h"

#include "calib/camera/camera.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <set>
#include <sstream>

namespace aerocal::triangulation {

using Model = calib::Camera::Model;

void AdjustOptions::Validate() const {
  std::set<std::string> seen;
  for (const auto& name : free_interior) {
    if (Model::IndexOf(name) < 0)
      throw ConfigError("free_interior: unknown parameter '" + name +
                        "' (expected c, x0, y0, K1, K2, K3, P1, P2, B1, B2)");
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
  if (max_rejections < 1)
    throw ConfigError("max_rejections must be > 0 (got " + std::to_string(max_rejections) + ")");
  if (!(correlation_threshold > 0 && correlation_threshold < 1))
    throw ConfigError("correlation_threshold must be in (0, 1) (got " +
                      FormatNumber(correlation_threshold) + ")");
  if (max_dense_parameters < 0)
    throw ConfigError("max_dense_parameters must be >= 0 (got " +
                      std::to_string(max_dense_parameters) + ")");
  if (solver.max_iterations < 1)
    throw ConfigError("solver.max_iterations must be > 0 (got " +
                      std::to_string(solver.max_iterations) + ")");
}

std::vector<std::string> ParseSelfCalibration(const std::string& text) {
  if (text == "none" || text.empty()) return {};
  std::vector<std::string> names;
  if (text == "all") {
    for (const auto& p : Model::kParams) names.emplace_back(p.name);
    return names;
  }
  for (const std::string& name : SplitCommaList(text)) {
    if (Model::IndexOf(name) < 0)
      throw ConfigError(
          "--self-calibration: unknown parameter '" + name +
          "' (expected none, all or a list of c, x0, y0, K1, K2, K3, P1, P2, B1, B2)");
    names.push_back(name);
  }
  AdjustOptions probe;
  probe.free_interior = names;
  probe.Validate();
  return names;
}

}  // namespace aerocal::triangulation
