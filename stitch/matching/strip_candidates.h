// Tie candidates of one overlap strip, before the geometric check (RANSAC), the grid thinning and
// least-squares matching that overlap_matcher.cc applies to either kind (match_options.h Search).
#pragma once

#include "calib/camera/camera.h"
#include "stitch/image_io/gray_image.h"
#include "stitch/matching/match_options.h"
#include "stitch/matching/overlap_strips.h"

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

namespace aerocal::stitch {

struct StripCandidates {
  std::vector<Eigen::Vector2d> in_a, in_b;  // positions, sub-image a and b px
  std::vector<double> score;                // lower is better: Lowe's ratio, or 1 - NCC
  int keypoints_a = 0, keypoints_b = 0;     // interest points found (kPredicted: none in b)
};

/// Integer pixel rectangle [x0, x1) x [y0, y1) covering a window box.
cv::Rect PixelRect(const Eigen::AlignedBox2d& box);

/// Nominal prediction of a's pixel in b: b <- virtual <- a.
Eigen::Vector2d PredictInB(const calib::SubimageMapping& sa,
                           const calib::SubimageMapping& sb,
                           const Eigen::Vector2d& uv_a);

/// Keypoints of both windows, descriptor matching, ratio test, prediction gate
/// (Search::kDescriptors).
StripCandidates DescriptorCandidates(const calib::Camera& camera,
                                     const std::vector<GrayImage>& images,
                                     const OverlapStrip& strip,
                                     const MatchOptions& options);

/// Foerstner points of a, the strongest `candidates_per_cell` per grid cell, each found in b by
/// normalised cross-correlation around its prediction (Search::kPredicted).
StripCandidates PredictedCandidates(const calib::Camera& camera,
                                    const std::vector<GrayImage>& images,
                                    const OverlapStrip& strip,
                                    const MatchOptions& options);

}  // namespace aerocal::stitch
