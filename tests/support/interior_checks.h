// The self-calibration checks the calibration tests share: every interior parameter the test field
// determines within 3 sigma of the simulated truth.
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "triangulation/adjustment/adjustment_result.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace aerocal::testing {

/// |estimate - truth| <= 3 sigma for c, x0, y0, K1, K2, P1, P2 (10-parameter model).
inline void ExpectInteriorWithinThreeSigma(const triangulation::CameraEstimate& c,
                                           const calib::InteriorParams& truth) {
  using Model = calib::BrownFraser10Model;
  for (int k :
       {Model::kC, Model::kX0, Model::kY0, Model::kK1, Model::kK2, Model::kP1, Model::kP2}) {
    SCOPED_TRACE(std::string(Model::kParams[k].name));
    EXPECT_LE(std::abs(c.estimated[k] - truth[k]), 3.0 * c.sigma[k])
        << c.estimated[k] << " sigma " << c.sigma[k];
  }
}

}  // namespace aerocal::testing
