#include "triangulation/adjustment/plausibility.h"

#include "calib/core/string_printf.h"

#include <cmath>

namespace aerocal::triangulation {
namespace {

// c / d with d the format's diagonal: 0.5 / tan(fov / 2) for the full diagonal field of view.
void CheckPrincipalDistance(const std::string& subject,
                            const calib::Camera& camera,
                            std::vector<ResultWarning>* out) {
  const double c_mm = camera.c_mm();
  const double diagonal_mm = camera.pixel_size_mm * std::hypot(camera.width_px, camera.height_px);
  if (!(diagonal_mm > 0) || !(c_mm > 0)) return;
  const double ratio = c_mm / diagonal_mm;
  if (ratio <= kMaxPrincipalDistanceRatio) return;
  const double fov_deg = 2.0 * std::atan(0.5 / ratio) * 180.0 / M_PI;
  out->push_back(
      {kWarningImplausiblePrincipalDistance,
       subject,
       ratio,
       kMaxPrincipalDistanceRatio,
       StringPrintf("c = %.6g mm is %.0f times the %.3g mm format diagonal (a field of view of "
                    "%.2g deg): if c was given in pixels, it is %.6g mm with %.6g mm pixels",
                    c_mm,
                    ratio,
                    diagonal_mm,
                    fov_deg,
                    c_mm * camera.pixel_size_mm,
                    camera.pixel_size_mm)});
}

}  // namespace

std::vector<ResultWarning> PlausibilityWarnings(const Project& project) {
  std::vector<ResultWarning> out;
  for (const auto& [id, camera] : project.cameras) {
    const auto rig = project.rigs.find(id);
    if (rig == project.rigs.end()) {
      CheckPrincipalDistance("camera " + id, camera, &out);
      continue;
    }
    for (const auto& head : rig->second.heads)
      CheckPrincipalDistance("camera " + id + " head " + head.id, head.camera, &out);
  }
  return out;
}

}  // namespace aerocal::triangulation
