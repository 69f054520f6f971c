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
//   [U V W]^T = M^T R^T (X - C),   M = Rx Ry Rz(mount) (camera -> body)
// The detector's focal-plane position is its design position plus the calibration polynomial of
// its sub-camera in the normalised index u (line_camera.h):
//   x = x_design + sum_k a_k u^k,   y = y_design + sum_k b_k u^k
//   r = ((x - (-c U / W)) / sigma_x_mm, (y - (-c V / W)) / sigma_y_mm)            [2, unitless]
// computed by the one collinearity condition of aerocal (internal::CollinearityErrorFromImageSpace
// with LineFocalPlaneModel, unit sigma) and then whitened per axis.
// sigma_x_mm = sigma_px |d x_design / d i| (the local detector spacing in the virtual focal plane:
// up to 1 / cos^2 of the look angle times the pitch for a tilted sub-camera), sigma_y_mm =
// sigma_px |d y / d t| (the image motion of one scan line), so that a measurement's sigma in
// detectors and lines is whitened correctly for every sub-camera.
//
// blocks: node0..node3 [6] (m, rad), detector [2 kLineMaxTerms] = a_0..a_5, b_0..b_5 (mm),
//         c [1] (mm), mount [3] (rad), lever_arm [3] (m), time_offset [1] (s), point [3] (m).
// Returns false when the point is on or behind the camera (W >= 0).
#pragma once

#include "calib/camera/line_camera.h"
#include "calib/camera/rotation.h"
#include "calib/residuals/autodiff_residual.h"
#include "calib/residuals/collinearity.h"

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

/// The line camera's focal plane as a camera model of the one collinearity condition
/// (internal::CollinearityErrorFromImageSpace, collinearity.h): interior [c] (mm); the detector's
/// calibrated focal-plane position (design + polynomial) is the ideal position itself (the
/// detector calibration sits in the residual's detector block, not in a distortion model).
struct LineFocalPlaneModel {
  static constexpr bool kCorrectionForm = true;
  template <typename T>
  static T PrincipalDistanceMm(const T* c, const PixelFrame&) {
    return c[0];
  }
  template <typename T>
  static bool IdealFromMeasured(const T*, const PixelFrame&, const T* measured_mm, T* ideal_mm) {
    ideal_mm[0] = measured_mm[0];
    ideal_mm[1] = measured_mm[1];
    return true;
  }
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
  /// design_xy_mm: design focal-plane position of the measured detector position; u: its
  /// normalised index in its sub-camera; span: spline weights of its line; pos_opk_rad,
  /// pos_center_m: the POS pose interpolated to its line; sigma_xy_mm > 0 (see above);
  /// pos_velocity_m_s, pos_opk_rate_rad_s: the POS's time derivatives at the line (the time
  /// offset's lever).
  LineCollinearityResidual(const Eigen::Vector2d& design_xy_mm,
                           double u,
                           const SplineSpan& span,
                           const Eigen::Vector3d& pos_opk_rad,
                           const Eigen::Vector3d& pos_center_m,
                           const Eigen::Vector2d& sigma_xy_mm,
                           const Eigen::Vector3d& pos_velocity_m_s = Eigen::Vector3d::Zero(),
                           const Eigen::Vector3d& pos_opk_rate_rad_s = Eigen::Vector3d::Zero())
      : design_{design_xy_mm.x(), design_xy_mm.y()},
        u_(u),
        weights_(span.weights),
        opk_{pos_opk_rad.x(), pos_opk_rad.y(), pos_opk_rad.z()},
        center_{pos_center_m.x(), pos_center_m.y(), pos_center_m.z()},
        velocity_{pos_velocity_m_s.x(), pos_velocity_m_s.y(), pos_velocity_m_s.z()},
        opk_rate_{pos_opk_rate_rad_s.x(), pos_opk_rate_rad_s.y(), pos_opk_rate_rad_s.z()},
        inverse_sigma_mm_{1.0 / sigma_xy_mm.x(), 1.0 / sigma_xy_mm.y()} {}

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
    const T xy[2] = {
        T(design_[0]) + EvaluatePolynomial(detector, kLineMaxTerms, u),
        T(design_[1]) + EvaluatePolynomial(detector + kLineMaxTerms, kLineMaxTerms, u)};
    // The one collinearity condition (unit sigma), then the per-axis whitening.
    T unit[2];
    if (!internal::CollinearityErrorFromImageSpace<LineFocalPlaneModel>(
            c, PixelFrame{}, v, xy, 1.0, unit))
      return false;
    r[0] = unit[0] * T(inverse_sigma_mm_[0]);
    r[1] = unit[1] * T(inverse_sigma_mm_[1]);
    return true;
  }

 private:
  double design_[2];
  double u_;
  std::array<double, 4> weights_;
  double opk_[3], center_[3];
  double velocity_[3], opk_rate_[3];
  double inverse_sigma_mm_[2];
};

}  // namespace aerocal::calib
