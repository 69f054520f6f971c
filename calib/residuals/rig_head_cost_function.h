// The rig-head residual (ModelRigHeadCollinearityResidual, collinearity.h) differentiated over the
// blocks that vary in a per-exposure self-calibration only (issue 35): there the heads' interior,
// mounts and lever arms and the rig's attitude and centre are held, and only the increment E_k
// (3), the time offset dT_k (1) and the tie point (3) adjust. Ceres's autodiff carries Jets as wide
// as all blocks together (kNumParams + 20, 30 for the 10-parameter model) whichever Jacobians are
// asked for; this cost function evaluates the SAME templated functor on 7-wide Jets when Ceres
// asks for no Jacobian of a held block, and falls back to the full autodiff otherwise (a block
// that adjusts in another problem, or a caller asking for every Jacobian). The scalar parts and the
// derivatives are computed by the same operations as the 30-wide Jets', so residuals and
// Jacobians equal the autodiff's (tests/calib/residuals_test.cc checks 1e-10 relative on random
// states).
#pragma once

#include "calib/residuals/collinearity.h"

#include <ceres/jet.h>
#include <ceres/sized_cost_function.h>

#include <memory>

namespace aerocal::calib {

template <typename Model>
class RigHeadReducedJetCostFunction
    : public ceres::SizedCostFunction<2, Model::kNumParams, 4, 3, 3, 3, 3, 1, 3> {
 public:
  // Blocks in the functor's order; the first five are the held ones (interior .. lever_arm).
  static constexpr int kHeldBlocks = 5;
  static constexpr int kVaryingWidth = 7;  // increment[3], dt[1], point[3]

  RigHeadReducedJetCostFunction(const PixelFrame& head_frame,
                                const Eigen::Vector2d& pixel,
                                double sigma_px,
                                const Eigen::Vector3d& velocity_mps)
      : functor_(head_frame, pixel, sigma_px, velocity_mps),
        full_(ModelRigHeadCollinearityResidual<Model>::Create(
            head_frame, pixel, sigma_px, velocity_mps)) {}

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override {
    bool held_asked = false;
    for (int b = 0; jacobians != nullptr && b < kHeldBlocks; ++b)
      held_asked |= jacobians[b] != nullptr;
    if (jacobians == nullptr || held_asked)
      return full_->Evaluate(parameters, residuals, jacobians);
    return EvaluateVarying(parameters, residuals, jacobians);
  }

 private:
  using Jet = ceres::Jet<double, kVaryingWidth>;

  // Held blocks become constant Jets; the 7 varying parameters get unit derivatives in the order
  // increment, dt, point.
  bool EvaluateVarying(double const* const* p, double* residuals, double** jacobians) const {
    static constexpr int kSizes[8] = {Model::kNumParams, 4, 3, 3, 3, 3, 1, 3};
    Jet interior[Model::kNumParams], rotation[4], center[3], mount[3], lever[3], increment[3],
        dt[1], point[3];
    Jet* blocks[8] = {interior, rotation, center, mount, lever, increment, dt, point};
    int column = 0;
    for (int b = 0; b < 8; ++b)
      for (int j = 0; j < kSizes[b]; ++j)
        blocks[b][j] = b < kHeldBlocks ? Jet(p[b][j]) : Jet(p[b][j], column++);
    Jet r[2];
    if (!functor_(interior, rotation, center, mount, lever, increment, dt, point, r)) return false;
    for (int row = 0; row < 2; ++row) residuals[row] = r[row].a;
    int first = 0;
    for (int b = kHeldBlocks; b < 8; first += kSizes[b], ++b) {
      if (jacobians[b] == nullptr) continue;
      for (int row = 0; row < 2; ++row)
        for (int j = 0; j < kSizes[b]; ++j) jacobians[b][row * kSizes[b] + j] = r[row].v[first + j];
    }
    return true;
  }

  ModelRigHeadCollinearityResidual<Model> functor_;
  std::unique_ptr<ceres::CostFunction> full_;
};

}  // namespace aerocal::calib
