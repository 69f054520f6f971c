#include "calib/camera/distortion_folding.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"

#include <cmath>
#include <string>

namespace aerocal::calib {

DistortionFolding FindDistortionFolding(const ModelCamera& camera) {
  const PixelFrame& frame = camera.frame;
  AEROCAL_CHECK(frame.width_px > 0 && frame.height_px > 0 && frame.pixel_size_mm > 0)
      << "a camera format must be positive";
  DistortionFolding out;
  const double w_mm = frame.width_px * frame.pixel_size_mm,
               h_mm = frame.height_px * frame.pixel_size_mm;
  out.half_diagonal_mm = 0.5 * std::hypot(w_mm, h_mm);
  // The principal point (measured) is the pixel of the ideal origin.
  Eigen::Vector2d pp_px;
  if (!camera.PixelFromIdeal(Eigen::Vector2d::Zero(), &pp_px)) {
    out.radius_mm = 0.0;
    out.inside_format = true;
    return out;
  }
  const Eigen::Vector2d pp_mm = frame.PhotoFromPixel(pp_px);
  constexpr int kDirections = 16, kSteps = 3000;
  const double r_max = 1.5 * out.half_diagonal_mm, step = r_max / kSteps;
  // Per direction the first radius where the mapping stops being monotonic; the smallest one
  // inside the format wins, else the smallest one at all.
  for (int d = 0; d < kDirections; ++d) {
    const double angle = 2 * M_PI * d / kDirections;
    const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
    double previous = 0;
    for (int k = 1; k <= kSteps; ++k) {
      const double r = k * step;
      const Eigen::Vector2d xy_mm = pp_mm + r * dir;
      Eigen::Vector2d ideal, back;
      const bool ok = camera.IdealFromPixel(frame.PixelFromPhoto(xy_mm), &ideal) &&
                      camera.PixelFromIdeal(ideal, &back) &&
                      (frame.PhotoFromPixel(back) - xy_mm).norm() < 1e-3 * frame.pixel_size_mm;
      const double rho = ok ? ideal.norm() : NAN;
      if (ok && std::isfinite(rho) && rho > previous) {
        previous = rho;
        continue;
      }
      const bool inside = std::abs(xy_mm.x()) <= 0.5 * w_mm && std::abs(xy_mm.y()) <= 0.5 * h_mm;
      const bool better = !out.radius_mm || (inside && !out.inside_format) ||
                          (inside == out.inside_format && r < *out.radius_mm);
      if (better) {
        out.radius_mm = r;
        out.direction_deg = angle * 180 / M_PI;
        out.inside_format = inside;
      }
      break;
    }
  }
  return out;
}

std::string DistortionFoldingWarning(const DistortionFolding& folding) {
  if (!folding.radius_mm || !folding.inside_format) return "";
  return StringPrintf(
      "the distortion folds at r = %.4g mm from the principal point (direction %.0f deg), inside "
      "the format (half diagonal %.4g mm): beyond it two image points map to one ray; the "
      "distortion parameters are not those of a lens",
      *folding.radius_mm,
      folding.direction_deg,
      folding.half_diagonal_mm);
}

}  // namespace aerocal::calib
