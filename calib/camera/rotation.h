// Exterior-orientation rotation of CONVENTIONS.md: R = Rx(omega) Ry(phi) Rz(kappa) rotates image
// space into object space (object_from_image). Angles in radians in memory. Templated for Jets.
//
// Inside the solver an exposure's rotation is a unit quaternion q = [w, x, y, z] (Hamilton,
// R(q) = object_from_image), updated by a rotation increment (calib/problem/rotation_manifold.h);
// omega-phi-kappa exist only in files and reports (OpkFromQuaternion, OpkJacobianOfQuaternion).
// omega-phi-kappa are singular at phi = +-90 deg (gimbal lock: only omega + kappa, or
// omega - kappa at -90 deg, is defined); the quaternion is not.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>

namespace aerocal::calib {

/// Row-major 3x3 R = Rx(omega) Ry(phi) Rz(kappa) from opk = [omega, phi, kappa] (rad).
template <typename T>
void ObjectFromImageRotation(const T* opk, T* r) {
  using std::cos;
  using std::sin;
  const T so = sin(opk[0]), co = cos(opk[0]);
  const T sp = sin(opk[1]), cp = cos(opk[1]);
  const T sk = sin(opk[2]), ck = cos(opk[2]);
  r[0] = cp * ck;
  r[1] = -cp * sk;
  r[2] = sp;
  r[3] = co * sk + so * sp * ck;
  r[4] = co * ck - so * sp * sk;
  r[5] = -so * cp;
  r[6] = so * sk - co * sp * ck;
  r[7] = so * ck + co * sp * sk;
  r[8] = co * cp;
}

/// [U V W] = R^T (X - X0) with R row-major (object_from_image).
template <typename T>
void ImageSpaceFromObjectByMatrix(const T* r, const T* center, const T* point, T* uvw) {
  const T d[3] = {point[0] - center[0], point[1] - center[1], point[2] - center[2]};
  for (int i = 0; i < 3; ++i) uvw[i] = r[0 + i] * d[0] + r[3 + i] * d[1] + r[6 + i] * d[2];
}

/// [U V W] = R^T (X - X0): the object point in the image-space frame of the exposure.
template <typename T>
void ImageSpaceFromObject(const T* opk, const T* center, const T* point, T* uvw) {
  T r[9];
  ObjectFromImageRotation(opk, r);
  ImageSpaceFromObjectByMatrix(r, center, point, uvw);
}

/// |cos phi| at or below which omega and kappa are not separable (phi within 2e-4 arcsec of
/// +-90 deg): OpkFromRotation puts their sum into omega (kappa = 0), OpkJacobianOfQuaternion
/// gives NaN rows for them.
inline constexpr double kGimbalLockCosPhi = 1e-9;

/// omega, phi, kappa (rad) of a rotation matrix R = Rx Ry Rz (phi in [-pi/2, pi/2]). At gimbal
/// lock (|cos phi| <= kGimbalLockCosPhi) kappa = 0 and omega carries the defined combination.
/// phi = atan2(r02, hypot(r12, r22)), not asin(r02), which loses half the digits near +-90 deg.
inline Eigen::Vector3d OpkFromRotation(const Eigen::Matrix3d& r) {
  const double cos_phi = std::hypot(r(1, 2), r(2, 2));
  const double phi = std::atan2(r(0, 2), cos_phi);
  if (cos_phi <= kGimbalLockCosPhi) {
    // R = Rx(omega) Ry(+-90) with kappa = 0: r10 = +-sin(omega) ... see CONVENTIONS.md.
    const double omega = r(0, 2) > 0 ? std::atan2(r(1, 0), r(1, 1)) : std::atan2(-r(1, 0), r(1, 1));
    return {omega, phi, 0.0};
  }
  const double omega = std::atan2(-r(1, 2), r(2, 2));
  const double kappa = std::atan2(-r(0, 1), r(0, 0));
  return {omega, phi, kappa};
}

inline Eigen::Matrix3d RotationFromOpk(const Eigen::Vector3d& opk) {
  double r[9];
  ObjectFromImageRotation(opk.data(), r);
  Eigen::Matrix3d m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  return m;
}

/// Row-major 3x3 R(q) of a quaternion q = [w, x, y, z] (Hamilton, object_from_image). q need not
/// be unit: R(q) = R(q / |q|), as ceres::QuaternionToRotation.
template <typename T>
void ObjectFromImageRotationOfQuaternion(const T* q, T* r) {
  const T ww = q[0] * q[0], xx = q[1] * q[1], yy = q[2] * q[2], zz = q[3] * q[3];
  const T wx = q[0] * q[1], wy = q[0] * q[2], wz = q[0] * q[3];
  const T xy = q[1] * q[2], xz = q[1] * q[3], yz = q[2] * q[3];
  const T s = T(1) / (ww + xx + yy + zz);
  r[0] = (ww + xx - yy - zz) * s;
  r[1] = T(2) * (xy - wz) * s;
  r[2] = T(2) * (xz + wy) * s;
  r[3] = T(2) * (xy + wz) * s;
  r[4] = (ww - xx + yy - zz) * s;
  r[5] = T(2) * (yz - wx) * s;
  r[6] = T(2) * (xz - wy) * s;
  r[7] = T(2) * (yz + wx) * s;
  r[8] = (ww - xx - yy + zz) * s;
}

/// [U V W] = R(q)^T (X - X0) for a quaternion rotation block.
template <typename T>
void ImageSpaceFromObjectByQuaternion(const T* q, const T* center, const T* point, T* uvw) {
  T r[9];
  ObjectFromImageRotationOfQuaternion(q, r);
  ImageSpaceFromObjectByMatrix(r, center, point, uvw);
}

/// Unit quaternion [w, x, y, z] of a rotation matrix (w >= 0).
Eigen::Vector4d QuaternionFromRotation(const Eigen::Matrix3d& r);
Eigen::Matrix3d RotationFromQuaternion(const Eigen::Vector4d& q);
/// Unit quaternion [w, x, y, z] of R = Rx(omega) Ry(phi) Rz(kappa) (rad).
Eigen::Vector4d QuaternionFromOpk(const Eigen::Vector3d& opk);
/// omega, phi, kappa (rad) of R(q), as OpkFromRotation.
Eigen::Vector3d OpkFromQuaternion(const Eigen::Vector4d& q);
/// The same, with omega and kappa moved by whole turns to lie within pi of `near_opk` (rad): the
/// angles a file had go back to that file on the same branch (kappa 3.15 stays 3.15, not -3.13).
Eigen::Vector3d OpkFromQuaternionNear(const Eigen::Vector4d& q, const Eigen::Vector3d& near_opk);

/// d(omega, phi, kappa) / d delta (3x3, rad/rad) at R, for the increment R' = Exp(delta) R with
/// delta a rotation vector in OBJECT axes (the tangent of calib/problem/rotation_manifold.h).
///   dphi = dr02 / cos(phi), domega = (r12 dr22 - r22 dr12) / cos^2(phi),
///   dkappa = (r01 dr00 - r00 dr01) / cos^2(phi), dR = [delta]x R.
/// At gimbal lock (|cos phi| <= kGimbalLockCosPhi) the omega and kappa rows are NaN (not
/// separable: their sigmas are unknown, null in files) and the phi row is its limit
/// [0, cos(omega), sin(omega)] with the omega of OpkFromRotation.
Eigen::Matrix3d OpkJacobianOfIncrement(const Eigen::Matrix3d& r);
/// d(omega, phi, kappa) / dq (3x4) at a unit quaternion: OpkJacobianOfIncrement(R(q)) times
/// d delta / dq = 2 [-x w -z y; -y z w -x; -z -y x w] (the increment's inverse Jacobian at 0).
/// The ambient covariance C_q of a rotation block becomes C_opk = J C_q J^T.
Eigen::Matrix<double, 3, 4> OpkJacobianOfQuaternion(const Eigen::Vector4d& q);

}  // namespace aerocal::calib
