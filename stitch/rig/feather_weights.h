// Feather weights of one head's coverage for the stitched image (stitched_image.h): per pixel
// w = 0 where not covered, else clamp(round(d), 1, feather_px), d the distance to the nearest
// uncovered pixel by OpenCV's 3 x 3 L2 chamfer transform (cv::distanceTransform(DIST_L2, 3):
// horizontal/vertical step a = 0.955, diagonal step b = 1.3693; pixels outside the raster are not
// uncovered, so the raster's own edge is no border).
//
// Only a band of the coverage border is transformed (issue 35): d <= feather_px + 0.5 needs an
// uncovered pixel q within Chebyshev distance (feather_px + 0.5) / a of the pixel p (every chamfer
// step moves at most one Chebyshev unit and costs at least a), and the shortest chamfer path from
// q to p stays inside their bounding box. So a crop holding every pixel within that reach of a
// tile gives the tile's d exactly where round(d) <= feather_px, and d_crop >= d_full elsewhere
// (fewer uncovered pixels), which clamps to feather_px as well. Tiles that are uncovered
// throughout get 0, tiles with no uncovered pixel within the reach get feather_px, without a
// transform. The weights are those of the transform over the whole raster, bit for bit (tested
// against it in rig_stitched_image_test.cc).
#pragma once

#include <cstdint>
#include <vector>

namespace aerocal::stitch {

// `covered`: width x height bytes, row-major, non-zero where covered. feather_px in 1..255.
std::vector<std::uint8_t> FeatherWeights(const std::uint8_t* covered,
                                         int width,
                                         int height,
                                         int feather_px);

// The same from cv::distanceTransform over the whole raster (the reference; tests only).
std::vector<std::uint8_t> FeatherWeightsWhole(const std::uint8_t* covered,
                                              int width,
                                              int height,
                                              int feather_px);

}  // namespace aerocal::stitch
