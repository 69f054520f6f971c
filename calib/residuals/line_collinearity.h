// Collinearity of a line (pushbroom) camera measurement (CONVENTIONS.md "Line (pushbroom)
// cameras"; model calib/camera/line_camera.h).
//
// A measurement is a detector position i (fractional allowed) on scan line t. Its line's body pose
// is the POS pose interpolated to t (constant here: opk_pos, O_pos) plus a smooth correction: a
// uniform cubic B-spline in the line index with nodes every N lines (CubicBSplineWeights), whose
// four node blocks hold [dX, dY, dZ (m), domega, dphi, dkappa (rad)], added to the position and
// the angles, and a time offset dt (s; the line's true time minus its pos.csv time: shutter / POS
// latency) to first order through the POS velocity and attitude rate at the line:
//   opk(t) = opk_pos + dt opk_rate + sum_m w_m node_m[3..5],
//   O(t) = O_pos + dt velocity + sum_m w_m node_m[0..2]
//   R = Rx Ry Rz(opk(t))   (body -> object),   camera centre C = O(t) + R t_lever
//   g = [U V W]^T = M^T R^T (X - C),   M = Rx Ry Rz(mount) (camera -> body)
// The detector's focal-plane position is its design position plus the calibration polynomial of
// its sub-camera in the normalised index u (line_camera.h), and the table's line direction there
// its derivative in the detector index:
//   x = x_design + sum_k a_k u^k,   y = y_design + sum_k b_k u^k,
//   x' = x_design' + du/di sum_k k a_k u^(k-1),   y' likewise
// The residual is the ANGLE between the detector's ray d = (x, y, -c) and g in a frame attached to
// the table (u1 along its line direction, u2 = e x u1; line_ray_angle.h), so that it is invariant
// under a rotation of camera + table and under a scale of c with the table (issue 28: the gauges
// are then exact), whitened in pixels at the nominal ray (c and the table at their start values):
//   r = S a,   S = -diag(1 / sigma_xy_mm) A^-1   (LineRayAngleWhitening)              [2, unitless]
// which equals ((x - (-c U / W)) / sigma_x_mm, (y - (-c V / W)) / sigma_y_mm), the focal-plane
// residual of the one collinearity condition, to first order at the nominal ray; then each
// component is put into the units of the measurement at the CURRENT values, a detector index
// across and a scan line along (sigma_px is a sigma in those units):
//   r_x *= rho_0 / rho,   rho = |l_perp| / |d|   (the angle per detector; LineAnglePerIndex)
//   r_y *= |g| / |g_0|                           (a line is the platform's motion per line seen
//                                                 from the range |g|: an angle ~ 1 / |g|)
// with rho_0, |g_0| at the start values (both factors 1 there). Both are invariant under the
// gauges (a rotation of camera + table, a scale of c with the table). Why (issue 28; module README
// "Datum", "The free lever arm"): with the weight fixed at the start's angles, a raised camera
// (lever arm z, height) with the table shrunk by H / (H + dz) sees the ground through the same
// rays but every measured detector and line as a smaller angle: the whole noise part E of
// v^T P v shrank by 2 E dz / H, and the free lever arm's z went to dz ~ sigma_z^2 E / H (+32.8 m,
// 6 sigma, on every one of 25 flights).
// sigma_x_mm = sigma_px |d x_design / d i| (the local detector spacing in the virtual focal plane:
// up to 1 / cos^2 of the look angle times the pitch for a tilted sub-camera), sigma_y_mm =
// sigma_px |d y / d t| (the image motion of one scan line), so that a measurement's sigma in
// detectors and lines is whitened correctly for every sub-camera.
//
// blocks: node0..node3 [6] (m, rad), detector [2 kLineMaxTerms] = a_0..a_5, b_0..b_5 (mm),
//         c [1] (mm), mount [3] (rad), lever_arm [3] (m), time_offset [1] (s), point [3] (m).
// Returns false when the point is not in front of the detector's ray (e.g <= 0).
#pragma once

#include "calib/camera/line_camera.h"
#include "calib/camera/rotation.h"
#include "calib/residuals/autodiff_residual.h"
#include "calib/residuals/line_ray_angle.h"

#include <Eigen/Core>

#include <array>
#include <cmath>

namespace aerocal::calib {

/// Terms of a detector polynomial block per axis (degree <= 5); unused terms are fixed at 0.
inline constexpr int kLineMaxTerms = 6;
inline constexpr int kLineNodeSize = 6;

/// Uniform cubic B-spline with nodes every `spacing` lines: line t lies in segment
/// k = floor(t / spacing) and depends on nodes k .. k+3 with these weights (they sum to 1).
/// Node j is centred on line (j - 1) * spacing. t >= 0.
struct SplineSpan {
  int first_node = 0;
  std::array<double, 4> weights{};
};
inline SplineSpan CubicBSplineWeights(double t, int spacing) {
  const double s = t / spacing;
  SplineSpan span;
  span.first_node = int(std::floor(s));
  const double f = s - span.first_node;
  const double f2 = f * f, f3 = f2 * f;
  span.weights = {(1 - f) * (1 - f) * (1 - f) / 6.0,
                  (3 * f3 - 6 * f2 + 4) / 6.0,
                  (-3 * f3 + 3 * f2 + 3 * f + 1) / 6.0,
                  f3 / 6.0};
  return span;
}
/// Nodes a spline over lines 0 .. last_line needs.
inline int SplineNodeCount(double last_line, int spacing) {
  return int(std::floor(last_line / spacing)) + 4;
}

/// Where a measured detector position lies on the table (start values) and the principal distance
/// its residual is weighted at.
struct LineDetectorGeometry {
  // The range (m) from the camera to the point at the start values; 0: the along-track residual
  // is not rescaled to the current range (header comment).
  double nominal_range_m = 0.0;
  Eigen::Vector2d xy_mm = Eigen::Vector2d::Zero();     // design (+ the file's calibration), mm
  Eigen::Vector2d slope_mm = Eigen::Vector2d::Zero();  // its derivative in the index, mm / detector
  double u = 0.0;                                      // normalised index in its sub-camera
  double du_di = 0.0;         // 2 / (last - first) of its sub-camera (0: one detector)
  double nominal_c_mm = 0.0;  // the start value of c, > 0: the weight's principal distance
};

struct LineCollinearityResidual : AutoDiffResidual<LineCollinearityResidual,
                                                   2,
                                                   kLineNodeSize,
                                                   kLineNodeSize,
                                                   kLineNodeSize,
                                                   kLineNodeSize,
                                                   2 * kLineMaxTerms,
                                                   1,
                                                   3,
                                                   3,
                                                   1,
                                                   3> {
  /// detector: the measured position on the table and its nominal principal distance; span:
  /// spline weights of its line; pos_opk_rad, pos_center_m: the POS pose interpolated to its line;
  /// sigma_xy_mm > 0 (see above); pos_velocity_m_s, pos_opk_rate_rad_s: the POS's time
  /// derivatives at the line (the time offset's lever).
  LineCollinearityResidual(const LineDetectorGeometry& detector,
                           const SplineSpan& span,
                           const Eigen::Vector3d& pos_opk_rad,
                           const Eigen::Vector3d& pos_center_m,
                           const Eigen::Vector2d& sigma_xy_mm,
                           const Eigen::Vector3d& pos_velocity_m_s = Eigen::Vector3d::Zero(),
                           const Eigen::Vector3d& pos_opk_rate_rad_s = Eigen::Vector3d::Zero())
      : design_{detector.xy_mm.x(), detector.xy_mm.y()},
        slope_{detector.slope_mm.x(), detector.slope_mm.y()},
        u_(detector.u),
        du_di_(detector.du_di),
        weights_(span.weights),
        opk_{pos_opk_rad.x(), pos_opk_rad.y(), pos_opk_rad.z()},
        center_{pos_center_m.x(), pos_center_m.y(), pos_center_m.z()},
        velocity_{pos_velocity_m_s.x(), pos_velocity_m_s.y(), pos_velocity_m_s.z()},
        opk_rate_{pos_opk_rate_rad_s.x(), pos_opk_rate_rad_s.y(), pos_opk_rate_rad_s.z()},
        nominal_range_m_(detector.nominal_range_m) {
    const double nominal_ray[3] = {detector.xy_mm.x(), detector.xy_mm.y(), -detector.nominal_c_mm};
    const double nominal_line[3] = {detector.slope_mm.x(), detector.slope_mm.y(), 0.0};
    nominal_angle_per_detector_ = LineAnglePerIndex(nominal_ray, nominal_line);
    const Eigen::Matrix2d s = LineRayAngleWhitening(
        Eigen::Vector3d(detector.xy_mm.x(), detector.xy_mm.y(), -detector.nominal_c_mm),
        Eigen::Vector3d(detector.slope_mm.x(), detector.slope_mm.y(), 0.0),
        sigma_xy_mm);
    whitening_ = {s(0, 0), s(0, 1), s(1, 0), s(1, 1)};  // row-major
  }

  template <typename T>
  bool operator()(const T* n0,
                  const T* n1,
                  const T* n2,
                  const T* n3,
                  const T* detector,
                  const T* c,
                  const T* mount,
                  const T* lever,
                  const T* time_offset,
                  const T* point,
                  T* r) const {
    const T* nodes[4] = {n0, n1, n2, n3};
    T opk[3], center[3];
    for (int a = 0; a < 3; ++a) {
      opk[a] = T(opk_[a]) + time_offset[0] * opk_rate_[a];
      center[a] = T(center_[a]) + time_offset[0] * velocity_[a];
      for (int m = 0; m < 4; ++m) {
        center[a] += T(weights_[m]) * nodes[m][a];
        opk[a] += T(weights_[m]) * nodes[m][3 + a];
      }
    }
    T body[9], cam[9];
    ObjectFromImageRotation(opk, body);   // body -> object, row-major
    ObjectFromImageRotation(mount, cam);  // camera -> body
    // C = O + R lever;  b = R^T (X - C);  v = M^T b
    T d[3];
    for (int a = 0; a < 3; ++a)
      d[a] = point[a] - center[a] -
             (body[3 * a] * lever[0] + body[3 * a + 1] * lever[1] + body[3 * a + 2] * lever[2]);
    T b[3], v[3];
    for (int a = 0; a < 3; ++a) b[a] = body[a] * d[0] + body[3 + a] * d[1] + body[6 + a] * d[2];
    for (int a = 0; a < 3; ++a) v[a] = cam[a] * b[0] + cam[3 + a] * b[1] + cam[6 + a] * b[2];
    const T u(u_);
    const T* dx = detector;
    const T* dy = detector + kLineMaxTerms;
    const T ray[3] = {T(design_[0]) + EvaluatePolynomial(dx, kLineMaxTerms, u),
                      T(design_[1]) + EvaluatePolynomial(dy, kLineMaxTerms, u),
                      -c[0]};
    const T line_direction[3] = {
        T(slope_[0]) + du_di_ * EvaluatePolynomialDerivative(dx, kLineMaxTerms, u),
        T(slope_[1]) + du_di_ * EvaluatePolynomialDerivative(dy, kLineMaxTerms, u),
        T(0.0)};
    T angle[2];
    if (!LineRayAngle(ray, line_direction, v, angle)) return false;
    // In detector indices and lines at the current values (header comment).
    const T across = nominal_angle_per_detector_ / LineAnglePerIndex(ray, line_direction);
    using std::sqrt;
    const T along = nominal_range_m_ > 0.0
                        ? sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / nominal_range_m_
                        : T(1.0);
    r[0] = across * (whitening_[0] * angle[0] + whitening_[1] * angle[1]);
    r[1] = along * (whitening_[2] * angle[0] + whitening_[3] * angle[1]);
    return true;
  }

 private:
  double design_[2], slope_[2];
  double u_, du_di_;
  std::array<double, 4> weights_;
  double opk_[3], center_[3];
  double velocity_[3], opk_rate_[3];
  std::array<double, 4> whitening_;          // S, row-major (line_ray_angle.h)
  double nominal_range_m_;                   // |g_0|, m (0: along not rescaled)
  double nominal_angle_per_detector_ = 0.0;  // rho_0 (rad per detector index)
};

}  // namespace aerocal::calib
