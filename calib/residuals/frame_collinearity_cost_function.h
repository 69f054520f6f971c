// The frame camera's collinearity residual in the 10-parameter model with a hand-written Jacobian
// (issue 31): the same residual as CollinearityResidual (collinearity.h, its autodiff twin; the
// values come from the same templated functions in doubles, equal to the Jets' values to rounding,
// as Jets divide by multiplying with the reciprocal), the Jacobian by the chain rule instead of
// 20-dimensional Jets.
//
// r = (ideal(a, xy) + c (U, V) / W) / sigma_mm,  [U V W] = R(q)^T (X - X0),  R(q) = M(q) / |q|^2
// (calib/camera/rotation.h), ideal = xb + dxy(xb), xb = xy - (x0, y0) (brown_fraser10.h). With
// s = 1 / sigma_mm:
//   dr/d(U, V, W) = s c / W [1 0 -U/W; 0 1 -V/W]            (the projection)
//   dr/dc = s (U, V) / W;  dr/dx0 = -s (I + d dxy/d xb) e_x; dr/dy0 likewise with e_y;
//   dr/dK1..K3 = s xb r2^(1..3);  dr/dP1 = s (r2 + 2 xb^2, 2 xb yb);  dr/dP2 = s (2 xb yb,
//   r2 + 2 yb^2);  dr/dB1 = s (xb, 0);  dr/dB2 = s (yb, 0)      (the correction, linear in them)
//   d(U, V, W)/dX = R^T = -d(U, V, W)/dX0
//   d(U, V, W)/dq_k = (dM^T/dq_k (X - X0) - 2 q_k (U, V, W)) / |q|^2   (the normalisation of q).
// Blocks: interior[10] (table units), rotation[4] (quaternion [w, x, y, z]), center[3] (m),
// point[3] (m); Jacobians in these ambient coordinates (the builder's manifolds map them).
// Measured (tests/bench/solver_benchmark.cc BM_CollinearityJacobian): see calib/README.md.
#pragma once

#include "calib/camera/camera_model.h"
#include "calib/camera/pixel_frame.h"

#include <Eigen/Core>
#include <ceres/sized_cost_function.h>

#include <memory>

namespace aerocal::calib {

class FrameCollinearityCostFunction : public ceres::SizedCostFunction<2, 10, 4, 3, 3> {
 public:
  /// Observation (col, row) in the pixel frame of `frame`, sigma in px (> 0).
  FrameCollinearityCostFunction(const PixelFrame& frame,
                                const Eigen::Vector2d& pixel,
                                double sigma_px);
  /// False behind the projection plane (as the autodiff twin).
  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

 private:
  PixelFrame frame_;
  double xy_mm_[2];
  double inverse_sigma_mm_;
};

/// The frame camera's residual factory (triangulation's FrameCamera): this hand-written Jacobian
/// for the 10-parameter model, MakeCollinearityResidual (collinearity.h, autodiff) for every other
/// registered model. Blocks interior[CameraModelParamCount(model)], rotation[4], center[3],
/// point[3].
std::unique_ptr<ceres::CostFunction> MakeFrameCollinearityResidual(CameraModelId model,
                                                                   const PixelFrame& frame,
                                                                   const Eigen::Vector2d& pixel,
                                                                   double sigma_px);

}  // namespace aerocal::calib
