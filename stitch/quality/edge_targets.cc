#include "stitch/quality/edge_targets.h"

#include "calib/core/error.h"

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {

EdgeTargetRegion RegionOfEdgeTarget(const calib::Camera& camera,
                                    const Eigen::Vector3d& opk_rad,
                                    const Eigen::Vector3d& center_m,
                                    const EdgeTarget& target,
                                    const EdgeTargetRegionOptions& options) {
  Eigen::Vector2d start_px, end_px;
  if (!camera.ProjectToPixel(opk_rad, center_m, target.start_m, &start_px) ||
      !camera.ProjectToPixel(opk_rad, center_m, target.end_m, &end_px)) {
    EdgeTargetRegion out;
    out.id = target.id;
    out.reason = "an end of the edge is not seen by the camera";
    return out;
  }
  return RegionOfImageEdge(target.id,
                           start_px,
                           end_px,
                           (target.end_m - target.start_m).norm(),
                           camera.width_px,
                           camera.height_px,
                           options);
}

EdgeTargetRegion RegionOfImageEdge(const std::string& id,
                                   const Eigen::Vector2d& start_px,
                                   const Eigen::Vector2d& end_px,
                                   double ground_length_m,
                                   int width_px,
                                   int height_px,
                                   const EdgeTargetRegionOptions& options) {
  AEROCAL_CHECK(options.half_width_px >= 8.0 && options.used_fraction > 0.0 &&
                options.used_fraction <= 1.0 &&
                (options.max_length_px == 0.0 || options.max_length_px >= 16.0))
      << "half_width_px >= 8, 0 < used_fraction <= 1, max_length_px 0 or >= 16";
  EdgeTargetRegion out;
  out.id = id;
  out.start_px = start_px, out.end_px = end_px;
  const Eigen::Vector2d d = out.end_px - out.start_px;
  const double length_px = d.norm();
  if (length_px < 16.0) {
    out.reason = "the edge is shorter than 16 px in the image";
    return out;
  }
  out.gsd_m = ground_length_m / length_px;
  // An edge running more along the rows than the columns has its normal nearer the x axis.
  out.axis = std::abs(d.y()) >= std::abs(d.x()) ? MtfAxis::kX : MtfAxis::kY;
  out.slant_deg = std::atan2(std::min(std::abs(d.x()), std::abs(d.y())),
                             std::max(std::abs(d.x()), std::abs(d.y()))) *
                  180.0 / 3.14159265358979323846;
  const Eigen::Vector2d middle = 0.5 * (out.start_px + out.end_px);
  double fraction = options.used_fraction;
  if (options.max_length_px > 0.0) fraction = std::min(fraction, options.max_length_px / length_px);
  const Eigen::Vector2d half = 0.5 * fraction * d;
  const Eigen::Vector2d a = middle - half, b = middle + half;
  // Along the edge: the used part; across it: half_width to each side of the edge's extreme
  // positions.
  const double w = options.half_width_px;
  double col0, col1, row0, row1;
  if (out.axis == MtfAxis::kX) {
    row0 = std::min(a.y(), b.y()), row1 = std::max(a.y(), b.y());
    col0 = std::min(a.x(), b.x()) - w, col1 = std::max(a.x(), b.x()) + w;
  } else {
    col0 = std::min(a.x(), b.x()), col1 = std::max(a.x(), b.x());
    row0 = std::min(a.y(), b.y()) - w, row1 = std::max(a.y(), b.y()) + w;
  }
  out.region.col = static_cast<int>(std::ceil(col0));
  out.region.row = static_cast<int>(std::ceil(row0));
  out.region.width = static_cast<int>(std::floor(col1)) - out.region.col + 1;
  out.region.height = static_cast<int>(std::floor(row1)) - out.region.row + 1;
  if (out.region.col < 0 || out.region.row < 0 || out.region.col + out.region.width > width_px ||
      out.region.row + out.region.height > height_px) {
    out.reason = "the region leaves the image";
    return out;
  }
  out.usable = true;
  return out;
}

}  // namespace aerocal::stitch
