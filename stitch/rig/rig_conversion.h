// Conversion between the head images of one rig exposure and the single-centre virtual image
// (CONVENTIONS.md "Multi-head rigs", "Conversion of a head pixel to the virtual image"):
//
//   head pixel -> photo (x, y) -> ideal photo (xb + dx, yb + dy) (the head's model, any registered)
//   -> ray d = R_k [xb + dx, yb + dy, -c_k]^T from O_k -> its intersection G with the
//   rectification plane -> G projected into the virtual camera at O with attitude R_v.
//
// and back (virtual pixel -> ray from O with R_v -> G on the plane -> head k's measured pixel,
// the model's measured-from-ideal map, as Camera::ProjectToPixel does).
// The rectification plane lies at the relative flying height H below the virtual centre:
// perpendicular to the virtual axis for `orientation: rig` (R_v = R), the horizontal plane
// Z = O_Z - H for `orientation: level` (R_v = Rz(kappa_rig)).
//
// Relief: a point dh above the plane is displaced on the virtual image between heads j and k by
// about (c_v / p) |t_j - t_k| dh / (H (H - dh)) px (exact for heads with parallel axes whose lever
// arms differ perpendicular to the axis; ReliefDisplacementPx).
//
// Units: pixels per CONVENTIONS.md pixel frame of each image; metres in the object frame.
#pragma once

#include "calib/camera/rig.h"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace aerocal::stitch {

/// One exposure of a rig: its attitude and centre in the object frame, the platform velocity and
/// the per-head attitude increments E_k and time offsets dT_k (empty = all zero).
struct RigExposure {
  Eigen::Vector3d rig_opk_rad = Eigen::Vector3d::Zero();   // R = Rx Ry Rz: rig -> object
  Eigen::Vector3d rig_center_m = Eigen::Vector3d::Zero();  // virtual centre O (m)
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();  // v, object frame (m/s)
  std::vector<Eigen::Vector3d> increment_rad;              // E_k angles per head (rad)
  std::vector<double> dt_s;                                // dT_k per head (s)
};

/// A plane n . X = offset in the object frame (n unit length).
struct RectificationPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
};

/// The rectification plane of CONVENTIONS.md at relative flying height `height_m` (> 0) below the
/// virtual centre for the rig's virtual orientation.
RectificationPlane MakeRectificationPlane(const calib::Rig& rig,
                                          const RigExposure& exposure,
                                          double height_m);

/// The converter of one exposure: the head poses are computed once (calib::HeadPose).
class RigConverter {
 public:
  RigConverter(const calib::Rig& rig, const RigExposure& exposure, const RectificationPlane& plane);

  /// Point G of the plane seen at a head's measured pixel; nullopt when the ray misses the plane
  /// (parallel or behind the head).
  std::optional<Eigen::Vector3d> PlanePointOfHeadPixel(int head,
                                                       const Eigen::Vector2d& pixel) const;
  /// Point G of the plane seen at a virtual pixel; nullopt when the ray misses the plane.
  std::optional<Eigen::Vector3d> PlanePointOfVirtualPixel(const Eigen::Vector2d& pixel) const;
  /// Measured pixel of an object point in head k; nullopt when it is behind the head or the
  /// correction cannot be inverted.
  std::optional<Eigen::Vector2d> HeadPixelOfPoint(int head, const Eigen::Vector3d& point_m) const;
  /// Virtual pixel of an object point; nullopt when it is behind the virtual camera.
  std::optional<Eigen::Vector2d> VirtualPixelOfPoint(const Eigen::Vector3d& point_m) const;

  /// The two directions of the conversion (compositions of the above).
  std::optional<Eigen::Vector2d> VirtualFromHead(int head, const Eigen::Vector2d& pixel) const;
  std::optional<Eigen::Vector2d> HeadFromVirtual(int head, const Eigen::Vector2d& pixel) const;

  /// True when a pixel lies within a head's format (between the outer pixel centres).
  bool InHeadFormat(int head, const Eigen::Vector2d& pixel) const;

  const calib::Rig& rig() const { return rig_; }
  const RectificationPlane& Plane() const { return plane_; }
  /// R_k (head -> object) and O_k of head k for this exposure.
  const Eigen::Matrix3d& ObjectFromHead(int head) const { return object_from_head_[head]; }
  const Eigen::Vector3d& HeadCenter(int head) const { return head_center_[head]; }
  /// R_v (virtual camera -> object) and O.
  const Eigen::Matrix3d& ObjectFromVirtual() const { return object_from_virtual_; }
  const Eigen::Vector3d& VirtualCenter() const { return virtual_center_; }

 private:
  calib::Rig rig_;
  RectificationPlane plane_;
  std::vector<Eigen::Matrix3d> object_from_head_;
  std::vector<Eigen::Vector3d> head_center_;
  Eigen::Matrix3d object_from_virtual_;
  Eigen::Vector3d virtual_center_;
};

/// The CONVENTIONS.md estimate of the displacement (virtual px) between heads j and k of a point
/// `dh_m` above the rectification plane at relative flying height `height_m`:
/// (c_v / p) |t_j - t_k| dh / (H (H - dh)).
double ReliefDisplacementPx(
    const calib::Rig& rig, int head_j, int head_k, double height_m, double dh_m);

}  // namespace aerocal::stitch
