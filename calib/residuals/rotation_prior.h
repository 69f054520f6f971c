// IMU attitude prior on a rotation block (a unit quaternion q = [w, x, y, z], object_from_image,
// calib/camera/rotation.h) with the boresight misalignment M (imu_from_image, omega-phi-kappa b),
// in the omega-phi-kappa of the IMU record and its sigmas:
//   r_k = wrap(opk(R(q) M(b)^T)_k - opk0_k) / sigma_k   [3, unitless],  wrap to (-pi, pi]
// with phi = atan2(r02, sqrt(r12^2 + r22^2)), omega = atan2(-r12, r22), kappa = atan2(-r01, r00)
// of that matrix (CONVENTIONS.md "Exterior orientation"). With b = 0 it is the old per-angle
// prior of the omega-phi-kappa block, so figures are unchanged; at phi = +-90 deg omega and kappa
// are not defined and neither is this prior (the residual returns false within kGimbalLockCosPhi).
// blocks: rotation[4], boresight[3] (rad).
#pragma once

#include "calib/camera/rotation.h"
#include "calib/residuals/autodiff_residual.h"

#include <Eigen/Core>
#include <ceres/jet.h>

#include <cmath>

namespace aerocal::calib {

namespace internal {
inline double ScalarPart(double x) { return x; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& x) {
  return x.a;
}
}  // namespace internal

struct OpkPriorResidual : AutoDiffResidual<OpkPriorResidual, 3, 4, 3> {
  /// opk_rad: the IMU's omega, phi, kappa (rad); sigma_rad: their sigmas (> 0, rad).
  OpkPriorResidual(const Eigen::Vector3d& opk_rad, const Eigen::Vector3d& sigma_rad)
      : opk_{opk_rad.x(), opk_rad.y(), opk_rad.z()},
        inverse_sigma_{1.0 / sigma_rad.x(), 1.0 / sigma_rad.y(), 1.0 / sigma_rad.z()} {}
  template <typename T>
  bool operator()(const T* rotation, const T* boresight, T* residual) const {
    using std::atan2;
    using std::sqrt;
    T camera[9], m[9], r[9];  // r = R M^T: the IMU body's attitude
    ObjectFromImageRotationOfQuaternion(rotation, camera);
    ObjectFromImageRotation(boresight, m);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r[3 * i + j] = camera[3 * i] * m[3 * j] + camera[3 * i + 1] * m[3 * j + 1] +
                       camera[3 * i + 2] * m[3 * j + 2];
    const T cos_phi2 = r[5] * r[5] + r[8] * r[8];
    if (!(internal::ScalarPart(cos_phi2) > kGimbalLockCosPhi * kGimbalLockCosPhi)) return false;
    const T opk[3] = {atan2(-r[5], r[8]), atan2(r[2], sqrt(cos_phi2)), atan2(-r[1], r[0])};
    constexpr double kTwoPi = 2.0 * M_PI;
    for (int k = 0; k < 3; ++k) {
      const T d = opk[k] - T(opk_[k]);
      const double turns = std::round(internal::ScalarPart(d) / kTwoPi);
      residual[k] = (d - T(turns * kTwoPi)) * T(inverse_sigma_[k]);
    }
    return true;
  }

 private:
  double opk_[3];
  double inverse_sigma_[3];
};

}  // namespace aerocal::calib
