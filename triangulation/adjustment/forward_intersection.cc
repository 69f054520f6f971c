#include "triangulation/adjustment/forward_intersection.h"

#include "calib/camera/rotation.h"

#include <Eigen/Dense>

#include <cmath>

namespace aerocal::triangulation {

ImageRay RayFromPixel(const calib::Camera& camera,
                      const Eigen::Vector3d& opk_rad,
                      const Eigen::Vector3d& center_m,
                      const Eigen::Vector2d& pixel) {
  // In the camera's own model; where a forward model's inversion does not converge (far outside
  // its format), the pinhole ray is a starting value good enough.
  Eigen::Vector2d ideal;
  if (!camera.IdealFromPixel(pixel, &ideal))
    ideal = camera.PhotoFromPixel(pixel) - camera.PrincipalPointMm();
  const Eigen::Vector3d in_image(ideal.x(), ideal.y(), -camera.c_mm());
  return {center_m, (calib::RotationFromOpk(opk_rad) * in_image).normalized()};
}

std::optional<Eigen::Vector3d> IntersectRays(const std::vector<ImageRay>& rays,
                                             double min_angle_rad) {
  if (rays.size() < 2) return std::nullopt;
  double max_angle = 0.0;
  for (size_t i = 0; i < rays.size(); ++i)
    for (size_t k = i + 1; k < rays.size(); ++k)
      max_angle = std::max(
          max_angle, std::acos(std::clamp(rays[i].direction.dot(rays[k].direction), -1.0, 1.0)));
  if (max_angle < min_angle_rad) return std::nullopt;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& ray : rays) {
    const Eigen::Matrix3d p =
        Eigen::Matrix3d::Identity() - ray.direction * ray.direction.transpose();
    a += p;
    b += p * ray.center_m;
  }
  const Eigen::Vector3d x = a.ldlt().solve(b);
  if (!x.allFinite()) return std::nullopt;
  for (const auto& ray : rays)
    if ((x - ray.center_m).dot(ray.direction) <= 0) return std::nullopt;  // behind the camera
  return x;
}

Eigen::Vector3d IntersectWithHeight(const std::vector<ImageRay>& rays, double height_m) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& ray : rays) {
    if (std::abs(ray.direction.z()) < 1e-9) continue;
    const double t = (height_m - ray.center_m.z()) / ray.direction.z();
    if (t <= 0) continue;
    sum += ray.center_m + t * ray.direction;
    ++n;
  }
  if (n == 0) {  // no ray reaches the plane: below the first camera by its height above it
    const auto& ray = rays.front();
    return ray.center_m + std::abs(ray.center_m.z() - height_m) * ray.direction;
  }
  return sum / n;
}

}  // namespace aerocal::triangulation
