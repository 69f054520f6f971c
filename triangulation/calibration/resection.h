// Starting exterior orientation of calibration images without any approximate orientation: space
// resection from points of known coordinates, computed in closed form (no iteration), for
// `aerocal calibrate`. The adjustment (block_adjustment.h) then refines everything.
//
// Measured pixels are reduced with the camera file's interior (c, x0, y0; distortion ignored) to
// the normalised coordinates of the "forward" camera frame F = Rx(pi) * image space (x right,
// y down, z along the viewing direction, CONVENTIONS.md: image space looks along -z):
//   u = (x - x0) / c,  v = -(y - y0) / c,  [u v 1]^T ~ R_F (X - X0),  R_F = D R^T,
// with D = diag(1, -1, -1) and R = Rx(omega) Ry(phi) Rz(kappa) (object_from_image).
// - Planar points (the smallest principal extent below 2 % of the largest, or fewer than six):
//   plane frame (centroid m, principal axes e1, e2, n = e1 x e2), homography
//   [u v 1]^T ~ H [a b 1]^T (normalised DLT, Hartley), then as Zhang (2000):
//   R_F [e1 e2 n] = orthonormalised [h1 h2 h1 x h2] / |h1|, R_F (m - X0) = h3 / |h1|.
// - Non-planar points (>= 6): the calibrated DLT [u v 1]^T ~ P [X 1]^T, R_F the rotation
//   nearest to P's left 3x3 block (SVD), X0 = -M^-1 p4.
// Images that see too few known points are resected after tie points seen from two started
// images are intersected (forward_intersection.h), repeatedly.
//
// Zhang's closed form of the principal distance (square pixels, principal point at (x0, y0), no
// skew): with H' the homography into (x - x0, -(y - y0)) mm and w = 1 / c^2, every planar view
// gives the two linear equations w (h11 h12 + h21 h22) + h31 h32 = 0 and
// w (h11^2 + h21^2 - h12^2 - h22^2) + h31^2 - h32^2 = 0 (Zhang 2000, eq. 3-4, with the known
// principal point removed); least squares over all views. Views parallel to the target give no
// information (h31 = h32 = 0).
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// One image resected from points of known coordinates.
struct ResectionStart {
  Exposure exposure;
  std::string method;  // "homography" | "dlt"
  int n_points = 0;
  double rms_px = 0;  // reprojection RMS of its points with the camera file's interior, px
};

/// Pose from >= 4 (planar) or >= 6 (general) points; nullopt with `why` when the geometry does not
/// allow it (too few points, degenerate configuration, points behind the camera).
std::optional<ResectionStart> ResectImage(const calib::Camera& camera,
                                          const std::vector<Eigen::Vector2d>& pixels,
                                          const std::vector<Eigen::Vector3d>& points_m,
                                          std::string* why);

/// Starting orientation of every observed image of `project` (camera `camera_id`): resections
/// from the control points, then from tie points intersected from started images, until nothing
/// changes. Throws InputError naming the images that cannot be started.
std::vector<ResectionStart> StartFromResections(const Project& project,
                                                const std::string& camera_id);

/// Zhang's closed-form principal distance (mm) from the images' views of the PLANAR control
/// points (>= 4 per image); nullopt when the points are not planar or the views give no
/// information (w <= 0, fronto-parallel views).
std::optional<double> ClosedFormPrincipalDistance(const Project& project,
                                                  const std::string& camera_id);

}  // namespace aerocal::triangulation
