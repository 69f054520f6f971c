// The rotation-increment manifold of every rotation block (an exposure's object_from_image, as a
// unit quaternion q = [w, x, y, z], calib/camera/rotation.h):
//   q [+] delta = Exp(s * delta) (x) q,   Exp(v) = [cos(|v|/2), sin(|v|/2) v / |v|],
// i.e. R' = Exp([s delta]x) R: delta is a rotation vector in OBJECT axes (rad), one scale s_k per
// axis (the builder sets s_k = 1 / norm of the tangent Jacobian column, as ScaledSubsetManifold
// does for the other blocks). Unlike omega-phi-kappa, this has no singularity: phi = +-90 deg
// (a vertical wall seen horizontally, a test-field station, an oblique head) adjusts like nadir.
// Why a quaternion (4 numbers, 3 tangent) rather than a 3x3 matrix on SO(3): the residuals need
// R, which the quaternion gives in 13 products without trigonometry, the block stays small in the
// Schur complement bookkeeping, and Ceres' own QuaternionManifold uses the same [w, x, y, z] order
// (ours differs by using the full rotation angle |delta| and a scale per axis).
#pragma once

#include <ceres/manifold.h>

#include <array>

namespace aerocal::calib {

class ScaledRotationManifold : public ceres::Manifold {
 public:
  explicit ScaledRotationManifold(std::array<double, 3> scales = {1.0, 1.0, 1.0})
      : scales_(scales) {}
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* q, const double* delta, double* q_plus_delta) const override;
  /// 4x3 row-major: 0.5 [-v^T; w I - [v]x] diag(s), v = (x, y, z).
  bool PlusJacobian(const double* q, double* jacobian) const override;
  /// delta with Exp(s delta) (x) x = y (the shorter way round).
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  /// 3x4 row-major: diag(1/s) 2 [-v | w I + [v]x].
  bool MinusJacobian(const double* q, double* jacobian) const override;
  void SetScales(const std::array<double, 3>& scales) { scales_ = scales; }

 private:
  std::array<double, 3> scales_;
};

}  // namespace aerocal::calib
