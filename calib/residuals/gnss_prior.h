// GNSS antenna prior on an exposure with lever arm and time offset (triangulation/README.md
// "GNSS/IMU priors on the platform"):
//   r = (X0 + R a + v dt - X_gnss) / sigma      [3, unitless]
// X0 the projection centre (m, object frame), R = R(q) object_from_image (quaternion block,
// calib/camera/rotation.h), a the lever arm from the projection centre to the antenna phase centre
// in the image-space (camera) frame (m), v the platform velocity at the exposure (m/s, object
// frame, data: exposures.csv vX, vY, vZ), dt the GNSS time offset (s: the recorded position is the
// antenna's at exposure time + dt), X_gnss the recorded position and sigma its sigmas (m).
// With a = 0 and dt = 0 this is the plain centre prior.
// blocks: rotation[4], center[3] (m), lever_arm[3] (m), time_offset[1] (s).
#pragma once

#include "calib/camera/rotation.h"
#include "calib/residuals/autodiff_residual.h"

#include <Eigen/Core>

namespace aerocal::calib {

struct GnssPriorResidual : AutoDiffResidual<GnssPriorResidual, 3, 4, 3, 3, 1> {
  /// gnss_m: recorded antenna position (m); sigma_m: its sigmas (> 0, m); velocity_mps (m/s).
  GnssPriorResidual(const Eigen::Vector3d& gnss_m,
                    const Eigen::Vector3d& sigma_m,
                    const Eigen::Vector3d& velocity_mps)
      : gnss_{gnss_m.x(), gnss_m.y(), gnss_m.z()},
        inverse_sigma_{1.0 / sigma_m.x(), 1.0 / sigma_m.y(), 1.0 / sigma_m.z()},
        velocity_{velocity_mps.x(), velocity_mps.y(), velocity_mps.z()} {}
  template <typename T>
  bool operator()(const T* rotation,
                  const T* center,
                  const T* lever_arm,
                  const T* time_offset,
                  T* residual) const {
    T r[9];
    ObjectFromImageRotationOfQuaternion(rotation, r);
    for (int i = 0; i < 3; ++i) {
      const T antenna = center[i] + r[3 * i] * lever_arm[0] + r[3 * i + 1] * lever_arm[1] +
                        r[3 * i + 2] * lever_arm[2] + T(velocity_[i]) * time_offset[0];
      residual[i] = (antenna - T(gnss_[i])) * T(inverse_sigma_[i]);
    }
    return true;
  }

 private:
  double gnss_[3];
  double inverse_sigma_[3];
  double velocity_[3];
};

}  // namespace aerocal::calib
