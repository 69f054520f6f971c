#include "calib/problem/rotation_manifold.h"

#include <cmath>

namespace aerocal::calib {
namespace {

// c = a (x) b, Hamilton product of [w, x, y, z] quaternions.
void Multiply(const double* a, const double* b, double* c) {
  c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  c[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  c[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  c[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

}  // namespace

bool ScaledRotationManifold::Plus(const double* q,
                                  const double* delta,
                                  double* q_plus_delta) const {
  const double v[3] = {scales_[0] * delta[0], scales_[1] * delta[1], scales_[2] * delta[2]};
  const double angle = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (angle == 0.0) {
    for (int i = 0; i < 4; ++i) q_plus_delta[i] = q[i];
    return true;
  }
  const double k = std::sin(0.5 * angle) / angle;
  const double exp[4] = {std::cos(0.5 * angle), k * v[0], k * v[1], k * v[2]};
  Multiply(exp, q, q_plus_delta);
  return true;
}

bool ScaledRotationManifold::PlusJacobian(const double* q, double* jacobian) const {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double rows[4][3] = {{-x, -y, -z}, {w, z, -y}, {-z, w, x}, {y, -x, w}};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) jacobian[3 * i + k] = 0.5 * rows[i][k] * scales_[k];
  return true;
}

bool ScaledRotationManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const double x_inverse[4] = {x[0], -x[1], -x[2], -x[3]};
  double d[4];
  Multiply(y, x_inverse, d);
  if (d[0] < 0)
    for (double& e : d) e = -e;
  const double s = std::sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]);
  const double angle = 2.0 * std::atan2(s, d[0]);
  const double k = s > 0 ? angle / s : 2.0;
  for (int i = 0; i < 3; ++i) y_minus_x[i] = k * d[i + 1] / scales_[i];
  return true;
}

bool ScaledRotationManifold::MinusJacobian(const double* q, double* jacobian) const {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double rows[3][4] = {{-x, w, -z, y}, {-y, z, w, -x}, {-z, -y, x, w}};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 4; ++i) jacobian[4 * k + i] = 2.0 * rows[k][i] / scales_[k];
  return true;
}

}  // namespace aerocal::calib
