#include "calib/camera/rotation.h"

#include <Eigen/Geometry>

namespace aerocal::calib {

Eigen::Vector4d QuaternionFromRotation(const Eigen::Matrix3d& r) {
  Eigen::Quaterniond q(r);
  q.normalize();
  Eigen::Vector4d out(q.w(), q.x(), q.y(), q.z());
  return out(0) < 0 ? Eigen::Vector4d(-out) : out;
}

Eigen::Matrix3d RotationFromQuaternion(const Eigen::Vector4d& q) {
  double r[9];
  ObjectFromImageRotationOfQuaternion(q.data(), r);
  Eigen::Matrix3d m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  return m;
}

Eigen::Vector4d QuaternionFromOpk(const Eigen::Vector3d& opk) {
  return QuaternionFromRotation(RotationFromOpk(opk));
}

Eigen::Vector3d OpkFromQuaternion(const Eigen::Vector4d& q) {
  return OpkFromRotation(RotationFromQuaternion(q));
}

Eigen::Vector3d OpkFromQuaternionNear(const Eigen::Vector4d& q, const Eigen::Vector3d& near_opk) {
  Eigen::Vector3d opk = OpkFromQuaternion(q);
  for (int k : {0, 2}) opk(k) -= 2.0 * M_PI * std::round((opk(k) - near_opk(k)) / (2.0 * M_PI));
  return opk;
}

Eigen::Matrix3d OpkJacobianOfIncrement(const Eigen::Matrix3d& r) {
  const double c2 = r(1, 2) * r(1, 2) + r(2, 2) * r(2, 2);  // cos^2 phi
  Eigen::Matrix3d j;
  if (std::sqrt(c2) <= kGimbalLockCosPhi) {
    const double omega = OpkFromRotation(r)(0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    j << nan, nan, nan, 0.0, std::cos(omega), std::sin(omega), nan, nan, nan;
    return j;
  }
  const double c = std::sqrt(c2);
  // Rows of d(omega, phi, kappa) over (delta_x, delta_y, delta_z); dR = [delta]x R.
  j.row(0) << 1.0, -r(1, 2) * r(0, 2) / c2, -r(2, 2) * r(0, 2) / c2;
  j.row(1) << 0.0, r(2, 2) / c, -r(1, 2) / c;
  j.row(2) << 0.0, (r(0, 1) * r(2, 0) - r(0, 0) * r(2, 1)) / c2,
      (r(0, 0) * r(1, 1) - r(0, 1) * r(1, 0)) / c2;
  return j;
}

Eigen::Matrix<double, 3, 4> OpkJacobianOfQuaternion(const Eigen::Vector4d& q) {
  const Eigen::Vector4d u = q.normalized();
  const double w = u(0), x = u(1), y = u(2), z = u(3);
  Eigen::Matrix<double, 3, 4> delta_of_q;
  delta_of_q << -x, w, -z, y,  //
      -y, z, w, -x,            //
      -z, -y, x, w;
  delta_of_q *= 2.0 / q.norm();  // R(q) = R(q / |q|): the radial direction does not rotate
  return OpkJacobianOfIncrement(RotationFromQuaternion(u)) * delta_of_q;
}

}  // namespace aerocal::calib
