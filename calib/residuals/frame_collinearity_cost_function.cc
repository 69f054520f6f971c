#include "calib/residuals/frame_collinearity_cost_function.h"

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/rotation.h"
#include "calib/residuals/collinearity.h"

#include <type_traits>

namespace aerocal::calib {

namespace {

using Model = BrownFraser10Model;

// dr / d interior (2 x 10, row-major) at the measured xy (mm); uvw the point in image space.
void InteriorJacobian(const double* a, const double* xy, const double* uvw, double s, double* j) {
  const double xb = xy[0] - a[Model::kX0], yb = xy[1] - a[Model::kY0];
  const double r2 = xb * xb + yb * yb;
  const double k1 = a[Model::kK1], k2 = a[Model::kK2], k3 = a[Model::kK3];
  const double p1 = a[Model::kP1], p2 = a[Model::kP2];
  const double radial = r2 * (k1 + r2 * (k2 + r2 * k3));
  const double radial_r2 = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
  // d dxy / d xb (the correction's own Jacobian; d xb / d(x0, y0) = -I).
  const double cross = 2.0 * xb * yb * radial_r2 + 2.0 * p1 * yb + 2.0 * p2 * xb;
  const double dxx =
      radial + 2.0 * xb * xb * radial_r2 + 6.0 * p1 * xb + 2.0 * p2 * yb + a[Model::kB1];
  const double dxy = cross + a[Model::kB2];
  const double dyx = cross;
  const double dyy = radial + 2.0 * yb * yb * radial_r2 + 2.0 * p1 * xb + 6.0 * p2 * yb;
  double* jx = j;
  double* jy = j + Model::kNumParams;
  jx[Model::kC] = s * uvw[0] / uvw[2];
  jy[Model::kC] = s * uvw[1] / uvw[2];
  jx[Model::kX0] = -s * (1.0 + dxx);
  jy[Model::kX0] = -s * dyx;
  jx[Model::kY0] = -s * dxy;
  jy[Model::kY0] = -s * (1.0 + dyy);
  const double r4 = r2 * r2, r6 = r4 * r2;
  jx[Model::kK1] = s * xb * r2;
  jy[Model::kK1] = s * yb * r2;
  jx[Model::kK2] = s * xb * r4;
  jy[Model::kK2] = s * yb * r4;
  jx[Model::kK3] = s * xb * r6;
  jy[Model::kK3] = s * yb * r6;
  jx[Model::kP1] = s * (r2 + 2.0 * xb * xb);
  jy[Model::kP1] = s * 2.0 * xb * yb;
  jx[Model::kP2] = s * 2.0 * xb * yb;
  jy[Model::kP2] = s * (r2 + 2.0 * yb * yb);
  jx[Model::kB1] = s * xb;
  jy[Model::kB1] = 0.0;
  jx[Model::kB2] = s * yb;
  jy[Model::kB2] = 0.0;
}

// dr / dq (2 x 4, row-major) from dr / d(U, V, W) (2 x 3), d = X - X0.
void RotationJacobian(
    const double* q, const double* d, const double* uvw, const double dr[2][3], double* j) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double n = 1.0 / (w * w + x * x + y * y + z * z);
  // Half of d(M^T d) / dq: rows U, V, W; columns w, x, y, z.
  const double m[3][4] = {{w * d[0] + z * d[1] - y * d[2],
                           x * d[0] + y * d[1] + z * d[2],
                           -y * d[0] + x * d[1] - w * d[2],
                           -z * d[0] + w * d[1] + x * d[2]},
                          {-z * d[0] + w * d[1] + x * d[2],
                           y * d[0] - x * d[1] + w * d[2],
                           x * d[0] + y * d[1] + z * d[2],
                           -w * d[0] - z * d[1] + y * d[2]},
                          {y * d[0] - x * d[1] + w * d[2],
                           z * d[0] - w * d[1] - x * d[2],
                           w * d[0] + z * d[1] - y * d[2],
                           x * d[0] + y * d[1] + z * d[2]}};
  for (int k = 0; k < 4; ++k) {
    double duvw[3];
    for (int i = 0; i < 3; ++i) duvw[i] = 2.0 * n * (m[i][k] - q[k] * uvw[i]);
    for (int row = 0; row < 2; ++row)
      j[4 * row + k] = dr[row][0] * duvw[0] + dr[row][1] * duvw[1] + dr[row][2] * duvw[2];
  }
}

}  // namespace

FrameCollinearityCostFunction::FrameCollinearityCostFunction(const PixelFrame& frame,
                                                             const Eigen::Vector2d& pixel,
                                                             double sigma_px)
    : frame_(frame), inverse_sigma_mm_(1.0 / (sigma_px * frame.pixel_size_mm)) {
  frame.PhotoFromPixel(pixel.data(), xy_mm_);
}

bool FrameCollinearityCostFunction::Evaluate(double const* const* parameters,
                                             double* residuals,
                                             double** jacobians) const {
  const double* interior = parameters[0];
  const double* q = parameters[1];
  const double* center = parameters[2];
  const double* point = parameters[3];
  // The values by the autodiff twin's functions (ImageSpaceFromObjectByQuaternion, then the model).
  double r[9], uvw[3];
  ObjectFromImageRotationOfQuaternion(q, r);
  ImageSpaceFromObjectByMatrix(r, center, point, uvw);
  if (!internal::CollinearityErrorFromImageSpace<Model>(
          interior, frame_, uvw, xy_mm_, inverse_sigma_mm_, residuals))
    return false;
  if (jacobians == nullptr) return true;
  const double s = inverse_sigma_mm_;
  const double a = s * interior[Model::kC] / uvw[2];
  const double dr[2][3] = {{a, 0.0, -a * uvw[0] / uvw[2]}, {0.0, a, -a * uvw[1] / uvw[2]}};
  if (jacobians[0] != nullptr) InteriorJacobian(interior, xy_mm_, uvw, s, jacobians[0]);
  if (jacobians[1] != nullptr) {
    const double d[3] = {point[0] - center[0], point[1] - center[1], point[2] - center[2]};
    RotationJacobian(q, d, uvw, dr, jacobians[1]);
  }
  // d(U, V, W) / dX = R^T: dr/dX[row][k] = sum_i dr[row][i] R[k][i]; the centre with minus.
  for (int row = 0; row < 2; ++row)
    for (int k = 0; k < 3; ++k) {
      const double v =
          dr[row][0] * r[3 * k] + dr[row][1] * r[3 * k + 1] + dr[row][2] * r[3 * k + 2];
      if (jacobians[2] != nullptr) jacobians[2][3 * row + k] = -v;
      if (jacobians[3] != nullptr) jacobians[3][3 * row + k] = v;
    }
  return true;
}

std::unique_ptr<ceres::CostFunction> MakeFrameCollinearityResidual(CameraModelId model,
                                                                   const PixelFrame& frame,
                                                                   const Eigen::Vector2d& pixel,
                                                                   double sigma_px) {
  return VisitCameraModel(model, [&](auto m) -> std::unique_ptr<ceres::CostFunction> {
    if constexpr (std::is_same_v<decltype(m), BrownFraser10Model>)
      return std::make_unique<FrameCollinearityCostFunction>(frame, pixel, sigma_px);
    else
      return MakeCollinearityResidual(model, frame, pixel, sigma_px);
  });
}

}  // namespace aerocal::calib
