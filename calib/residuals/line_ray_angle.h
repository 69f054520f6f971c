// The angular misclosure of a line (pushbroom) camera detector (issue 28; triangulation/pushbroom
// README "Datum"): the direction of the ray to the ground point seen from the detector's observed
// ray, in a frame attached to the detector table itself.
//
//   d = (x_i, y_i, -c)             the detector's ray in the camera frame (table + c), mm
//   l = dd/di = (x_i', y_i', 0)    the table's line direction at the detector, mm / detector
//   g = (U, V, W)                  camera-frame vector to the ground point (any length)
//   e = d / |d|,   u1 = (l - (l.e) e) / |l - (l.e) e|,   u2 = e x u1
//   a = [u1.g, u2.g] / (e.g)       [2, rad: tangents of g's angle from d along u1 and u2]
//
// Why this frame: a rotation R of the camera that the table follows (a free boresight or a
// trajectory's attitude against the table's gauge functions) maps d, l and g to R d, R l, R g, and
// e, u1, u2 to R e, R u1, R u2: every dot product, so a, is unchanged. A scale s of the focal plane
// with c (d, l -> s d, s l) leaves e, u1, u2 unchanged. So those gauges are exact null directions
// of the residual, not null only up to a term of the residuals' size as with the focal-plane
// difference (x - (-c U / W)), which a rotation b changes by about 2 b x e / c and a scale s by s
// e. A frame from the camera's fixed axes (x, y) would turn with the camera but not with the
// table's rotation gauge (which moves the table, not the axes): it leaves a b |a| term.
//
// Whitening (LineRayAngleWhitening): pixels at the nominal ray (the start value of c and of the
// table); LineCollinearityResidual then rescales each component to the CURRENT angle per detector
// (LineAnglePerIndex) and per line (line_collinearity.h: why). Moving the ground
// ray's focal-plane intersection by delta = (dx, dy) gives a = A delta + O(delta^2), A = [u1_xy;
// u2_xy] / |d|, while the focal-plane residual (observed - projected) is -delta; so
// r = S a with S = -diag(1 / sigma_xy_mm) A^-1 equals the whitened focal-plane residual to first
// order at the nominal ray, and that residual divided by c times the nominal c elsewhere (at the
// principal point; off-axis the ratio also depends on the detector's angle).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>

namespace aerocal::calib {

namespace internal {
template <typename T>
T Dot3(const T* a, const T* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
}  // namespace internal

/// a = [u1.g, u2.g] / (e.g) as above (rad). ray d, line_direction l, to_point g: camera frame,
/// d and l in the same length unit. False where it is undefined: g not in front of the
/// detector's ray (e.g <= 0), or l parallel to d (within 1e-10 rad).
template <typename T>
bool LineRayAngle(const T* ray, const T* line_direction, const T* to_point, T* angle) {
  using std::sqrt;
  const T ray_norm = sqrt(internal::Dot3(ray, ray));
  const T e[3] = {ray[0] / ray_norm, ray[1] / ray_norm, ray[2] / ray_norm};
  const T along = internal::Dot3(line_direction, e);
  T u1[3];
  for (int k = 0; k < 3; ++k) u1[k] = line_direction[k] - along * e[k];
  const T u1_norm_sq = internal::Dot3(u1, u1);
  const T depth = internal::Dot3(e, to_point);
  // l within 1e-10 rad of d leaves no direction for u1 (rounding would pick one at random).
  if (!(u1_norm_sq > 1e-20 * internal::Dot3(line_direction, line_direction)) || !(depth > T(0.0)))
    return false;
  const T u1_norm = sqrt(u1_norm_sq);
  for (T& v : u1) v /= u1_norm;
  const T u2[3] = {
      e[1] * u1[2] - e[2] * u1[1], e[2] * u1[0] - e[0] * u1[2], e[0] * u1[1] - e[1] * u1[0]};
  angle[0] = internal::Dot3(u1, to_point) / depth;
  angle[1] = internal::Dot3(u2, to_point) / depth;
  return true;
}

/// The angle (rad) one detector index subtends across the line at this table: |l_perp| / |d|,
/// l_perp = l - (l.e) e. Invariant under a rotation of d and l together and under a scale of both
/// (the gauges); it follows a scale of the table alone (a table shrunk with a raised camera makes
/// every detector a smaller angle). ray and line_direction as in LineRayAngle.
template <typename T>
T LineAnglePerIndex(const T* ray, const T* line_direction) {
  using std::sqrt;
  const T ray_norm_sq = internal::Dot3(ray, ray);
  const T along = internal::Dot3(line_direction, ray) / ray_norm_sq;
  T perp[3];
  for (int k = 0; k < 3; ++k) perp[k] = line_direction[k] - along * ray[k];
  return sqrt(internal::Dot3(perp, perp) / ray_norm_sq);
}

/// S (2 x 2, 1 / rad) with r = S a equal to the focal-plane residual (observed - projected) / sigma
/// per axis to first order at the nominal ray (header comment). nominal_ray = (x, y, -c) and
/// nominal_line_direction = (x', y', 0) at the start values, mm and mm / detector; sigma_xy_mm > 0.
inline Eigen::Matrix2d LineRayAngleWhitening(const Eigen::Vector3d& nominal_ray,
                                             const Eigen::Vector3d& nominal_line_direction,
                                             const Eigen::Vector2d& sigma_xy_mm) {
  const Eigen::Vector3d e = nominal_ray.normalized();
  const Eigen::Vector3d u1 =
      (nominal_line_direction - nominal_line_direction.dot(e) * e).normalized();
  const Eigen::Vector3d u2 = e.cross(u1);
  Eigen::Matrix2d a;
  a << u1.x(), u1.y(), u2.x(), u2.y();
  a /= nominal_ray.norm();
  const Eigen::Matrix2d inverse_sigma = sigma_xy_mm.cwiseInverse().asDiagonal();
  return -inverse_sigma * a.inverse();
}

}  // namespace aerocal::calib
