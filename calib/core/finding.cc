#include "calib/core/finding.h"

namespace aerocal {
namespace {

nlohmann::json NumberOrNull(double x) { return std::isfinite(x) ? nlohmann::json(x) : nullptr; }

}  // namespace

nlohmann::json FindingToJson(const Finding& f) {
  return {{"name", f.name},
          {"subject", f.subject},
          {"value", NumberOrNull(f.value)},
          {"limit", NumberOrNull(f.limit)},
          {"message", f.message}};
}

nlohmann::json FindingsToJson(const std::vector<Finding>& findings) {
  nlohmann::json out = nlohmann::json::array();
  for (const Finding& f : findings) out.push_back(FindingToJson(f));
  return out;
}

}  // namespace aerocal
