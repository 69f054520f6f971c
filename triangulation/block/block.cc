#include "triangulation/block/block.h"

#include "calib/core/error.h"

namespace aerocal::triangulation {

std::string PointRoleName(PointRole role) {
  switch (role) {
    case PointRole::kControl:
      return "control";
    case PointRole::kCheck:
      return "check";
    case PointRole::kTie:
      break;
  }
  return "tie";
}

std::optional<PlatformParamMode> ParsePlatformParamMode(const std::string& text) {
  if (text == "fixed") return PlatformParamMode::kFixed;
  if (text == "free") return PlatformParamMode::kFree;
  if (text == "weighted") return PlatformParamMode::kWeighted;
  return std::nullopt;
}

PlatformParamMode PlatformParamModeOption(const std::string& text, const std::string& option) {
  const auto mode = ParsePlatformParamMode(text);
  if (!mode) throw ConfigError(option + " must be fixed, free or weighted (got '" + text + "')");
  return *mode;
}

std::string PlatformParamModeName(PlatformParamMode mode) {
  switch (mode) {
    case PlatformParamMode::kFree:
      return "free";
    case PlatformParamMode::kWeighted:
      return "weighted";
    case PlatformParamMode::kFixed:
      break;
  }
  return "fixed";
}

const Exposure* Project::FindExposure(const std::string& image) const {
  for (const auto& e : exposures)
    if (e.image == image) return &e;
  return nullptr;
}

const GroundPoint* Project::FindPoint(const std::string& id) const {
  for (const auto& p : points)
    if (p.id == id) return &p;
  return nullptr;
}

}  // namespace aerocal::triangulation
