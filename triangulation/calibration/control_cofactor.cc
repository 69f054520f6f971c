#include "triangulation/calibration/control_cofactor.h"

#include "triangulation/adjustment/block_adjustment.h"

namespace aerocal::triangulation {

Eigen::MatrixXd ControlCofactor(BlockAdjustment& adjustment,
                                calib::BlockId block,
                                int size,
                                double sigma0,
                                const Eigen::MatrixXd& covariance) {
  adjustment.ScaleControlWeights(1.0 - kControlWeightStep);
  const calib::CovarianceReport step = adjustment.builder().EstimateCovariance({block}, 1.0);
  adjustment.ScaleControlWeights(1.0);
  if (!step.ok) return {};
  return (step.BlockCovariance(block, size) - covariance / (sigma0 * sigma0)) / kControlWeightStep;
}

}  // namespace aerocal::triangulation
