// Forward intersection of image rays: starting coordinates of ground points from the current
// exterior and interior orientation (CONVENTIONS.md collinearity, 10-parameter correction).
//
// Each measured photo point (x, y) is corrected to ideal coordinates (xb + dx, yb + dy); its ray
// leaves the projection centre C along d = R [xb + dx, yb + dy, -c]^T. The point minimising the
// sum of squared perpendicular distances to all rays solves
//   sum_i (I - d_i d_i^T) X = sum_i (I - d_i d_i^T) C_i      (d_i unit vectors).
#pragma once

#include "calib/camera/camera.h"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace aerocal::triangulation {

struct ImageRay {
  Eigen::Vector3d center_m;   // projection centre, object frame
  Eigen::Vector3d direction;  // unit vector, object frame
};

/// Ray of a virtual-image pixel (col, row) seen by `camera` from an exposure (opk rad, centre m).
ImageRay RayFromPixel(const calib::Camera& camera,
                      const Eigen::Vector3d& opk_rad,
                      const Eigen::Vector3d& center_m,
                      const Eigen::Vector2d& pixel);

/// Least-squares intersection of >= 2 rays; nullopt when fewer rays, when the rays are nearly
/// parallel (intersection angle below `min_angle_rad`) or when the point lies behind a camera.
std::optional<Eigen::Vector3d> IntersectRays(const std::vector<ImageRay>& rays,
                                             double min_angle_rad = 1e-3);

/// Fallback start: the mean of the rays' intersections with the horizontal plane Z = height_m.
Eigen::Vector3d IntersectWithHeight(const std::vector<ImageRay>& rays, double height_m);

}  // namespace aerocal::triangulation
