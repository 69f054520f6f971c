// Overlap strips of a multi-CCD camera predicted from the camera file's NOMINAL mappings: for every
// pair of sub-images whose footprints on the virtual image intersect, the intersection rectangle
// (virtual px, axis-aligned bounding boxes of the mapped sub-image corners) and, per sub-image, the
// search window: the strip grown by a margin that absorbs the misplacement of the true mappings,
// taken back into that sub-image's pixels and clipped to its format. Matching searches only there.
#pragma once

#include "calib/camera/camera.h"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace aerocal::stitch {

struct OverlapStrip {
  int a = 0, b = 0;                 // sub-image indices in the camera, a < b
  std::string name;                 // "ID_A-ID_B", e.g. "I-II"
  Eigen::AlignedBox2d in_virtual;   // predicted overlap, virtual px (no margin)
  Eigen::AlignedBox2d window_in_a;  // search window, sub-image a px (margin, clipped)
  Eigen::AlignedBox2d window_in_b;  // search window, sub-image b px (margin, clipped)
};

/// Strips in pair order (a, b) of the camera's sub-images; overlaps narrower than `min_width_px`
/// in either direction are skipped. `margin_px` >= 0 grows the search windows.
std::vector<OverlapStrip> PredictOverlapStrips(const calib::Camera& camera,
                                               double margin_px,
                                               double min_width_px);

}  // namespace aerocal::stitch
