#include "stitch/rig/rig_conversion.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"

#include <cmath>

namespace aerocal::stitch {
namespace {

Eigen::Matrix3d FromRowMajor(const double* r) {
  Eigen::Matrix3d m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  return m;
}

Eigen::Matrix3d VirtualAttitude(const calib::Rig& rig, const RigExposure& exposure) {
  const Eigen::Matrix3d rig_attitude = calib::RotationFromOpk(exposure.rig_opk_rad);
  if (rig.virtual_camera.orientation == calib::VirtualOrientation::kRig) return rig_attitude;
  const double kappa = calib::OpkFromRotation(rig_attitude)[2];
  return calib::RotationFromOpk(Eigen::Vector3d(0, 0, kappa));
}

}  // namespace

RectificationPlane MakeRectificationPlane(const calib::Rig& rig,
                                          const RigExposure& exposure,
                                          double height_m) {
  AEROCAL_CHECK(height_m > 0) << "relative flying height must be > 0 (got " << height_m << ")";
  RectificationPlane plane;
  if (rig.virtual_camera.orientation == calib::VirtualOrientation::kRig) {
    // Perpendicular to the virtual axis (the rig's z), H along -z from O.
    plane.normal = VirtualAttitude(rig, exposure).col(2);
  } else {
    plane.normal = Eigen::Vector3d::UnitZ();
  }
  plane.offset = plane.normal.dot(exposure.rig_center_m) - height_m;
  return plane;
}

RigConverter::RigConverter(const calib::Rig& rig,
                           const RigExposure& exposure,
                           const RectificationPlane& plane)
    : rig_(rig), plane_(plane) {
  const int n = static_cast<int>(rig.heads.size());
  AEROCAL_CHECK(exposure.increment_rad.empty() ||
                static_cast<int>(exposure.increment_rad.size()) == n)
      << "one increment per head";
  AEROCAL_CHECK(exposure.dt_s.empty() || static_cast<int>(exposure.dt_s.size()) == n)
      << "one time offset per head";
  for (int k = 0; k < n; ++k) {
    const calib::RigHead& head = rig.heads[k];
    const Eigen::Vector3d increment =
        exposure.increment_rad.empty() ? Eigen::Vector3d::Zero() : exposure.increment_rad[k];
    const double dt = exposure.dt_s.empty() ? 0.0 : exposure.dt_s[k];
    double rotation[9];
    Eigen::Vector3d center;
    calib::HeadPose(exposure.rig_opk_rad.data(),
                    exposure.rig_center_m.data(),
                    head.mount_rad.data(),
                    head.lever_arm_m.data(),
                    increment.data(),
                    &dt,
                    exposure.velocity_mps.data(),
                    rotation,
                    center.data());
    object_from_head_.push_back(FromRowMajor(rotation));
    head_center_.push_back(center);
  }
  object_from_virtual_ = VirtualAttitude(rig, exposure);
  virtual_center_ = exposure.rig_center_m;
}

namespace {
std::optional<Eigen::Vector3d> IntersectPlane(const RectificationPlane& plane,
                                              const Eigen::Vector3d& origin,
                                              const Eigen::Vector3d& direction) {
  const double denominator = plane.normal.dot(direction);
  if (denominator == 0.0) return std::nullopt;
  const double s = (plane.offset - plane.normal.dot(origin)) / denominator;
  if (!(s > 0) || !std::isfinite(s)) return std::nullopt;
  return origin + s * direction;
}
}  // namespace

std::optional<Eigen::Vector3d> RigConverter::PlanePointOfHeadPixel(
    int head, const Eigen::Vector2d& pixel) const {
  const calib::Camera& camera = rig_.heads[head].camera;
  Eigen::Vector2d ideal;
  if (!camera.IdealFromPixel(pixel, &ideal)) return std::nullopt;
  const Eigen::Vector3d ray_in_head(ideal.x(), ideal.y(), -camera.c_mm());
  return IntersectPlane(plane_, head_center_[head], object_from_head_[head] * ray_in_head);
}

std::optional<Eigen::Vector3d> RigConverter::PlanePointOfVirtualPixel(
    const Eigen::Vector2d& pixel) const {
  const std::optional<Eigen::Vector3d> ray = rig_.virtual_camera.RayFromPixel(pixel);
  if (!ray) return std::nullopt;
  return IntersectPlane(plane_, virtual_center_, object_from_virtual_ * *ray);
}

std::optional<Eigen::Vector2d> RigConverter::HeadPixelOfPoint(
    int head, const Eigen::Vector3d& point_m) const {
  // Camera::ProjectToPixel with the head's pose: collinearity, then the correction inverted.
  const Eigen::Vector3d opk = calib::OpkFromRotation(object_from_head_[head]);
  Eigen::Vector2d pixel;
  if (!rig_.heads[head].camera.ProjectToPixel(opk, head_center_[head], point_m, &pixel))
    return std::nullopt;
  return pixel;
}

std::optional<Eigen::Vector2d> RigConverter::VirtualPixelOfPoint(
    const Eigen::Vector3d& point_m) const {
  Eigen::Vector2d pixel;
  if (!rig_.virtual_camera.PixelFromRay(
          object_from_virtual_.transpose() * (point_m - virtual_center_), &pixel))
    return std::nullopt;
  return pixel;
}

std::optional<Eigen::Vector2d> RigConverter::VirtualFromHead(int head,
                                                             const Eigen::Vector2d& pixel) const {
  const auto g = PlanePointOfHeadPixel(head, pixel);
  if (!g) return std::nullopt;
  return VirtualPixelOfPoint(*g);
}

std::optional<Eigen::Vector2d> RigConverter::HeadFromVirtual(int head,
                                                             const Eigen::Vector2d& pixel) const {
  const auto g = PlanePointOfVirtualPixel(pixel);
  if (!g) return std::nullopt;
  return HeadPixelOfPoint(head, *g);
}

bool RigConverter::InHeadFormat(int head, const Eigen::Vector2d& pixel) const {
  const calib::Camera& camera = rig_.heads[head].camera;
  return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= camera.width_px - 1 &&
         pixel.y() <= camera.height_px - 1;
}

double ReliefDisplacementPx(
    const calib::Rig& rig, int head_j, int head_k, double height_m, double dh_m) {
  const double baseline_m = (rig.heads[head_j].lever_arm_m - rig.heads[head_k].lever_arm_m).norm();
  const calib::Camera& v = rig.virtual_camera.camera;
  return v.c_mm() / v.pixel_size_mm * baseline_m * dh_m / (height_m * (height_m - dh_m));
}

}  // namespace aerocal::stitch
