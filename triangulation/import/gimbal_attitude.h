// The attitude of a camera on a drone's gimbal, from the angles DJI (and most drone makers) write
// (drone-dji:GimbalYawDegree / GimbalPitchDegree / GimbalRollDegree), as aerocal's rotation
// object_from_image (docs/conventions.md section 4) in the east-north-up axes at the exposure.
//
// The gimbal angles are Tait-Bryan angles z-y'-x'' in the local north-east-down frame, applied to
// the camera body (x forward along the optical axis, y right, z down):
//   R_ned_from_body = Rz(yaw) Ry(pitch) Rx(roll)
// yaw clockwise from north, pitch 0 looking at the horizon and -90 straight down, roll about the
// optical axis. Our image frame has photo x = body y (right), photo y = -body z (up in the image)
// and looks along -W, so W = -body x:
//   R_body_from_image = [0 0 -1; 1 0 0; 0 -1 0]   (columns: x, y, W of the image in the body)
// and east-north-up is NED with the first two axes swapped and the third negated:
//   R_object_from_image = R_enu_from_ned Rz(yaw) Ry(pitch) Rx(roll) R_body_from_image.
// Consequences (tested): pitch -90, yaw 0 is the identity (nadir, image top to the north, photo x
// to the east); at nadir kappa = -yaw; pitch -90 + t tilts the view forward along the heading.
#pragma once

#include <Eigen/Core>

namespace aerocal::triangulation {

/// object_from_image (east, north, up at the exposure) of gimbal angles in degrees.
Eigen::Matrix3d ObjectFromImageOfGimbal(double yaw_deg, double pitch_deg, double roll_deg);

/// omega, phi, kappa (radians, docs/conventions.md section 4) of the same rotation.
Eigen::Vector3d OpkOfGimbal(double yaw_deg, double pitch_deg, double roll_deg);

}  // namespace aerocal::triangulation
