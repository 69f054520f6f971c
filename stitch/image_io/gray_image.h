// Grey-value images of the stitching code: row-major float matrices, element (row, col) is the
// grey value of pixel (col, row) in the pixel frame of CONVENTIONS.md (centre of the top-left pixel
// at (0, 0)). Values keep the file's digital numbers (0..255 for 8-bit, 0..65535 for 16-bit).
// Public headers use this Eigen type; OpenCV stays inside the .cc files (STYLE.md section 1).
#pragma once

#include <Eigen/Core>

namespace aerocal::stitch {

using GrayImage = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace aerocal::stitch
