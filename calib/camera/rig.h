// A multi-head rig (CONVENTIONS.md "Multi-head rigs"; file: FORMATS.md "Multi-head rig"): several
// heads, each an ordinary camera with its own interior in any registered model (camera.h, the
// heads of one rig may differ), fixed to one body,
// whose images are converted into ONE virtual image of an equivalent single-centre camera.
//
// Frames: the rig frame is the frame of the virtual camera (origin at the virtual projection
// centre, x right, y up in the virtual photo, looking along -z). Head k: mount rotation
// M_k = Rx(omega_k) Ry(phi_k) Rz(kappa_k) turns head-frame vectors into the rig frame; lever arm
// t_k (m) is the head's projection centre in the rig frame.
//
// One exposure: rig attitude R (rig frame -> object frame, R = Rx Ry Rz of the rig's opk) and
// virtual centre O (m). Head k:
//   R_k = R M_k E_k,   O_k = O + R t_k + v dT_k
// with E_k = Rx(domega_k) Ry(dphi_k) Rz(dkappa_k) the in-flight attitude increment of head k (about
// its own axes; E_ref = I), dT_k (s) its exposure time minus the reference head's, v (m/s) the
// platform velocity in the object frame. The head then obeys the collinearity of CONVENTIONS.md
// with (R_k, O_k): ideal photo coordinates = -c_k [U V] / W, [U V W] = R_k^T (X - O_k).
//
// The rig model lives in calib (not stitch) because the rig residual of the bundle adjustment
// (calib/residuals) projects through HeadPose/ProjectHeadIdeal with ceres::Jet, and calib is the
// bottom of the module arrows; the conversion to the virtual image is in stitch/rig/.
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/camera.h"
#include "calib/camera/rotation.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::calib {

/// One head: an ordinary camera (its own pixel frame, format and interior in any registered model)
/// and its place in the rig.
struct RigHead {
  std::string id;
  Camera camera;                                          // name = id; no sub-images
  Eigen::Vector3d mount_rad = Eigen::Vector3d::Zero();    // omega, phi, kappa: head -> rig (rad)
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();  // head centre in the rig frame (m)
  std::optional<Eigen::Vector3d> mount_sigma_rad;         // a-priori sigmas (rad), absent = free
  std::optional<Eigen::Vector3d> lever_arm_sigma_m;       // a-priori sigmas (m), absent = free

  /// M_k = Rx(omega) Ry(phi) Rz(kappa): head-frame vectors into the rig frame.
  Eigen::Matrix3d RigFromHead() const { return RotationFromOpk(mount_rad); }
};

/// Attitude of the virtual camera: the rig's (R_v = R) or level with the rig's heading
/// (R_v = Rz(kappa_rig)).
enum class VirtualOrientation { kRig, kLevel };

/// The virtual camera: a camera in any registered model at the rig origin, whose image the heads
/// are converted into. The default (a rig file's `virtual` with `c`, `x0`, `y0`, or no `virtual`
/// at all: RigFromCamera) is the distortion-free central projection, the 10-parameter model with
/// only c and the principal point (PinholeCamera); a `virtual` with `interior` (and `model`) is any
/// camera, e.g. one whose distortion the converted image keeps.
struct VirtualCamera {
  VirtualOrientation orientation = VirtualOrientation::kRig;
  Camera camera;  // format, pixel size and interior; no sub-images, no sigmas
  /// Nominal relative flying height (m) of the rectification plane below the virtual centre, used
  /// when neither the exposure nor the command line gives one; absent = not given.
  std::optional<double> height_m;

  /// The distortion-free virtual camera: PinholeCamera(c_mm, x0_mm, y0_mm) on the format.
  static VirtualCamera Pinhole(VirtualOrientation orientation,
                               double c_mm,
                               double pixel_size_mm,
                               int width_px,
                               int height_px,
                               double x0_mm = 0.0,
                               double y0_mm = 0.0,
                               std::optional<double> height_m = std::nullopt);

  /// Direction (virtual camera frame, not normalised) of the ray through a virtual pixel:
  /// (ideal x, ideal y, -c) of the camera's model; nullopt where its inversion does not converge.
  std::optional<Eigen::Vector3d> RayFromPixel(const Eigen::Vector2d& pixel) const;
  /// Virtual pixel of a direction in the virtual camera frame; false when it does not point
  /// forward (z >= 0) or the model's inversion does not converge.
  bool PixelFromRay(const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) const;
};

/// Most heads a rig may have: the coverage of the rig design and the error analysis is a bit mask
/// per ground cell (stitch/rig/rig_design.cc). The rig reader refuses more with FILE:LINE.
inline constexpr size_t kMaxRigHeads = 32;

struct Rig {
  std::string name;
  std::string reference_head;  // id of the head the others are relative to
  VirtualCamera virtual_camera;
  std::vector<RigHead> heads;

  /// Index of a head by id; -1 when absent.
  int HeadIndex(const std::string& id) const;
  /// Index of the reference head (a valid rig always has one).
  int ReferenceIndex() const;
  /// Throws InputError("WHERE: what") when the rig is not usable: no heads, duplicate or empty
  /// ids, unknown reference head, non-positive c / pixel size / format, non-finite values.
  /// `where` names the source (the file) in the message.
  void Validate(const std::string& where) const;
};

/// A rig of one head with identity mount and zero lever arm whose virtual camera is the pinhole of
/// the camera's own format, principal distance and principal point: the ordinary camera as a rig.
/// Sub-images and reference points are not part of a rig head (LogicError when the camera has
/// them).
Rig RigFromCamera(const Camera& camera, const std::string& head_id = "A");

/// The ordinary camera equal to a rig of one head with identity mount and zero lever arm (the
/// head's camera); nullopt for any other rig.
std::optional<Camera> CameraFromSingleHeadRig(const Rig& rig);

// ---------------------------------------------------------------------------------------------
// The head projection, templated for ceres::Jet (the rig residual differentiates through it).

/// Row-major 3x3 product c = a b.
template <typename T>
void MultiplyRotations(const T* a, const T* b, T* c) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

/// Exterior orientation of head k for one exposure: R_k = R M_k E_k (row-major, object_from_head)
/// and O_k = O + R t_k + v dT_k (m).
///   object_from_rig[9] rig attitude R (row-major, rig -> object; the rig residual's quaternion
///                     block through ObjectFromImageRotationOfQuaternion)
///   rig_center_m[3]   virtual projection centre O in the object frame (m)
///   mount_opk[3]      M_k angles (rad)
///   lever_arm_m[3]    t_k in the rig frame (m)
///   increment_opk[3]  E_k angles (rad), zero for the reference head
///   dt_s[1]           exposure time offset dT_k (s)
///   velocity_mps[3]   platform velocity v in the object frame (m/s)
template <typename T>
void HeadPoseOfRotation(const T* object_from_rig,
                        const T* rig_center_m,
                        const T* mount_opk,
                        const T* lever_arm_m,
                        const T* increment_opk,
                        const T* dt_s,
                        const T* velocity_mps,
                        T* object_from_head,
                        T* head_center_m) {
  const T* r = object_from_rig;
  T m[9], e[9], rm[9];
  ObjectFromImageRotation(mount_opk, m);
  ObjectFromImageRotation(increment_opk, e);
  MultiplyRotations(r, m, rm);
  MultiplyRotations(rm, e, object_from_head);
  for (int i = 0; i < 3; ++i)
    head_center_m[i] = rig_center_m[i] + r[3 * i] * lever_arm_m[0] + r[3 * i + 1] * lever_arm_m[1] +
                       r[3 * i + 2] * lever_arm_m[2] + velocity_mps[i] * dt_s[0];
}

/// HeadPose(rig_opk, ...): the same with the rig attitude as rig_opk[3], omega, phi, kappa (rad),
/// R = Rx Ry Rz; the other arguments as above.
template <typename T, typename... Rest>
void HeadPose(const T* rig_opk, Rest... rest) {
  T object_from_rig[9];
  ObjectFromImageRotation(rig_opk, object_from_rig);
  HeadPoseOfRotation(static_cast<const T*>(object_from_rig), rest...);
}

/// Ideal photo coordinates reduced to head k's principal point, -c [U V] / W (mm), of an object
/// point seen in one rig exposure, for a head in the 10-parameter model (the rig residual itself,
/// calib/residuals/collinearity.h, works in any model). Blocks as in HeadPose, plus
/// interior[10] (table units; only c is used here) and point_m[3]. False when the point is not in
/// front of the head (W >= 0).
template <typename T>
bool ProjectHeadIdeal(const T* interior,
                      const T* rig_opk,
                      const T* rig_center_m,
                      const T* mount_opk,
                      const T* lever_arm_m,
                      const T* increment_opk,
                      const T* dt_s,
                      const T* velocity_mps,
                      const T* point_m,
                      T* ideal_mm) {
  T rotation[9], center[3], uvw[3];
  HeadPose(rig_opk,
           rig_center_m,
           mount_opk,
           lever_arm_m,
           increment_opk,
           dt_s,
           velocity_mps,
           rotation,
           center);
  ImageSpaceFromObjectByMatrix(rotation, center, point_m, uvw);  // head k's image space
  if (!(uvw[2] < T(0))) return false;
  const T& c = interior[BrownFraser10Model::kC];
  ideal_mm[0] = -c * uvw[0] / uvw[2];
  ideal_mm[1] = -c * uvw[1] / uvw[2];
  return true;
}

}  // namespace aerocal::calib
