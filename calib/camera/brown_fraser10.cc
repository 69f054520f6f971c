#include "calib/camera/brown_fraser10.h"

namespace aerocal::calib {

bool BrownFraser10Model::MeasuredFromIdeal(const double* params,
                                           const Eigen::Vector2d& ideal_mm,
                                           Eigen::Vector2d* measured_mm,
                                           double tolerance_mm) {
  return MeasuredFromIdeal(params, ideal_mm.data(), measured_mm->data(), tolerance_mm);
}

bool BrownFraser10Model::ToOpenCv(const double* p, const PixelFrame& frame, OpenCvParams* cv) {
  cv->fill(0.0);
  const double pixel = frame.pixel_size_mm;
  (*cv)[0] = p[kC] / ((1.0 + p[kB1]) * pixel);               // fx
  (*cv)[1] = p[kC] / pixel;                                  // fy
  (*cv)[2] = p[kX0] / pixel + 0.5 * (frame.width_px - 1);    // cx
  (*cv)[3] = -p[kY0] / pixel + 0.5 * (frame.height_px - 1);  // cy
  return p[kK1] == 0.0 && p[kK2] == 0.0 && p[kK3] == 0.0 && p[kP1] == 0.0 && p[kP2] == 0.0 &&
         p[kB2] == 0.0;
}

bool BrownFraser10Model::FromOpenCv(const OpenCvParams& cv, const PixelFrame& frame, double* p) {
  const double pixel = frame.pixel_size_mm;
  for (int i = 0; i < kNumParams; ++i) p[i] = 0.0;
  p[kC] = cv[1] * pixel;
  p[kX0] = (cv[2] - 0.5 * (frame.width_px - 1)) * pixel;
  p[kY0] = -(cv[3] - 0.5 * (frame.height_px - 1)) * pixel;
  p[kB1] = cv[1] / cv[0] - 1.0;
  for (int i = 4; i < 12; ++i)
    if (cv[i] != 0.0) return false;
  return true;
}

}  // namespace aerocal::calib
