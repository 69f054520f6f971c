// Exterior-orientation rotation of CONVENTIONS.md: R = Rx(omega) Ry(phi) Rz(kappa) rotates image
// space into object space (object_from_image). Angles in radians in memory. Templated for Jets.
#pragma once

#include <cmath>

#include <Eigen/Core>

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

/// [U V W] = R^T (X - X0): the object point in the image-space frame of the exposure.
template <typename T>
void ImageSpaceFromObject(const T* opk, const T* center, const T* point, T* uvw) {
  T r[9];
  ObjectFromImageRotation(opk, r);
  const T d[3] = {point[0] - center[0], point[1] - center[1], point[2] - center[2]};
  for (int i = 0; i < 3; ++i) uvw[i] = r[0 + i] * d[0] + r[3 + i] * d[1] + r[6 + i] * d[2];
}

/// omega, phi, kappa (rad) of a rotation matrix R = Rx Ry Rz (phi in [-pi/2, pi/2]).
inline Eigen::Vector3d OpkFromRotation(const Eigen::Matrix3d& r) {
  const double phi = std::asin(std::max(-1.0, std::min(1.0, r(0, 2))));
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

}  // namespace aerocal::calib
