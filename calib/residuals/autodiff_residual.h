// CRTP base that declares a residual's sizes once and provides Create() (STYLE.md section 5).
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <memory>
#include <utility>

namespace aerocal::calib {

template <typename Derived, int kNumResiduals, int... kBlockSizes>
struct AutoDiffResidual {
  template <typename... Args>
  static std::unique_ptr<ceres::CostFunction> Create(Args&&... args) {
    return std::make_unique<ceres::AutoDiffCostFunction<Derived, kNumResiduals, kBlockSizes...>>(
        new Derived(std::forward<Args>(args)...));
  }
};

}  // namespace aerocal::calib
