#include "calib/camera/brown_fraser10.h"

#include <cmath>

#include <Eigen/LU>
#include <ceres/jet.h>

namespace aerocal::calib {

bool BrownFraser10Model::MeasuredFromIdeal(const double* params, const Eigen::Vector2d& ideal_mm,
                                           Eigen::Vector2d* measured_mm, double tolerance_mm) {
  using Jet2 = ceres::Jet<double, 2>;
  Jet2 p[kNumParams];
  for (int i = 0; i < kNumParams; ++i) p[i] = Jet2(params[i]);
  Eigen::Vector2d xb = ideal_mm;  // start: no distortion
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Jet2 x[2] = {Jet2(xb.x(), 0), Jet2(xb.y(), 1)};
    Jet2 d[2];
    CorrectionReduced(p, x, d);
    const Eigen::Vector2d f(xb.x() + d[0].a - ideal_mm.x(), xb.y() + d[1].a - ideal_mm.y());
    Eigen::Matrix2d jacobian;
    jacobian << 1.0 + d[0].v[0], d[0].v[1], d[1].v[0], 1.0 + d[1].v[1];
    const Eigen::Vector2d step = jacobian.partialPivLu().solve(f);
    if (!step.allFinite()) return false;
    xb -= step;
    if (step.norm() < tolerance_mm) {
      *measured_mm = xb + Eigen::Vector2d(params[kX0], params[kY0]);
      return true;
    }
  }
  return false;
}

}  // namespace aerocal::calib
