// The part of an adjusted block's cofactor matrix that the control coordinates' survey sigmas
// give, Q N_control Q (the type-B component "control coordinates" of uncertainty_budget.h), at
// the adjustment's solution. With control weights t N_control at one linearisation,
// Q(t) = (N_image + t N_control)^-1 and dQ/dt = -Q N_control Q, so
// Q N_control Q = (Q(1 - d) - Q(1)) / d + O(d): the control weights times 1 - d
// (kControlWeightStep), the block's covariance again, the weights restored. No second solve.
// Used by the test field's calibration (calibration.cc) and the flight's joint adjustment.
#pragma once

#include "calib/problem/problem_builder.h"

#include <Eigen/Core>

namespace aerocal::triangulation {

class BlockAdjustment;

/// Relative step of the control weights. The relative error of the difference quotient is below
/// d (Q^1/2 N_control Q^1/2 <= I) and far above the covariance's rounding at d = 1e-3.
inline constexpr double kControlWeightStep = 1e-3;

/// Q N_control Q of `block` (its `size` entries, in its parameter order; not scaled by sigma0)
/// of a solved `adjustment`; `covariance` is the block's covariance at the solution
/// (sigma0^2 Q, sigma0 > 0). Empty when the stepped covariance cannot be computed. The control
/// weights are restored before it returns.
Eigen::MatrixXd ControlCofactor(BlockAdjustment& adjustment,
                                calib::BlockId block,
                                int size,
                                double sigma0,
                                const Eigen::MatrixXd& covariance);

}  // namespace aerocal::triangulation
