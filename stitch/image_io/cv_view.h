// An OpenCV header over a GrayImage's pixels (no copy): row-major float, as GrayImage is. The
// image must outlive the view; OpenCV functions that only read it take it as input.
#pragma once

#include "stitch/image_io/gray_image.h"

#include <opencv2/core.hpp>

namespace aerocal::stitch {

inline cv::Mat CvView(const GrayImage& image) {
  return cv::Mat(static_cast<int>(image.rows()),
                 static_cast<int>(image.cols()),
                 CV_32F,
                 const_cast<float*>(image.data()));
}

}  // namespace aerocal::stitch
