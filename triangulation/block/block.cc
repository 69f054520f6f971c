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
