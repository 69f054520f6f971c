#include "triangulation/import/gimbal_attitude.h"

#include "calib/camera/rotation.h"

#include <Eigen/Geometry>

#include <cmath>

namespace aerocal::triangulation {

Eigen::Matrix3d ObjectFromImageOfGimbal(double yaw_deg, double pitch_deg, double roll_deg) {
  constexpr double kDeg = M_PI / 180.0;
  const Eigen::Matrix3d ned_from_body =
      (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  Eigen::Matrix3d body_from_image;
  body_from_image << 0, 0, -1, 1, 0, 0, 0, -1, 0;
  Eigen::Matrix3d enu_from_ned;
  enu_from_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  return enu_from_ned * ned_from_body * body_from_image;
}

Eigen::Vector3d OpkOfGimbal(double yaw_deg, double pitch_deg, double roll_deg) {
  return calib::OpkFromRotation(ObjectFromImageOfGimbal(yaw_deg, pitch_deg, roll_deg));
}

}  // namespace aerocal::triangulation
