// Options of the overlap matcher (overlap_matcher.h): how tie candidates are found in a strip
// (`Search`), the interest points, the gates, the grid thinning and least-squares matching.
#pragma once

#include "stitch/matching/interest_operators.h"
#include "stitch/matching/least_squares_matching.h"
#include "stitch/matching/local_mapping.h"

#include <string>

namespace aerocal::stitch {

enum class Detector { kSift, kFoerstner };
/// "sift" | "foerstner"; ConfigError otherwise.
Detector ParseDetector(const std::string& name);

// How a strip's candidates are found (strip_candidates.h):
//  - kDescriptors: keypoints in both search windows (`detector`), descriptor matching with Lowe's
//    ratio test, candidates farther than `margin_px` from their nominal prediction dropped;
//  - kPredicted: Foerstner points of sub-image a only, each found in b by normalised
//    cross-correlation within `margin_px` of the position the nominal mappings predict.
enum class Search { kDescriptors, kPredicted };
/// "descriptors" | "predicted"; ConfigError otherwise.
Search ParseSearch(const std::string& name);

struct MatchOptions {
  Search search = Search::kPredicted;
  Detector detector = Detector::kSift;  // kDescriptors only (kPredicted uses Foerstner points)
  bool use_lsm = true;
  double margin_px = 20.0;  // search margin around the nominal strip and prediction, px, >= 0
  double min_strip_width_px = 30.0;  // narrower predicted overlaps are not matched, px
  double sift_contrast = 0.01;  // SIFT contrast threshold on the stretched window, > 0 (OpenCV's
                                // 0.04 leaves low-contrast fields of an overlap empty)
  int max_keypoints = 5000;     // per search window, strongest kept, > 0
  double ratio = 0.8;           // Lowe ratio test: best / second-best distance < ratio, (0, 1]
  double cell_px = 100.0;       // grid cell side along the strips, virtual px, > 0
  int points_per_cell = 1;      // accepted tie points per cell, >= 1
  int candidates_per_cell = 3;  // kPredicted: strongest Foerstner points searched per cell, >= 1
  double min_ncc = 0.7;         // kPredicted: correlation peak kept from this, (0, 1]
  double sigma_px = 0.3;        // sigma written without LSM, px, > 0
  double min_sigma_px = 0.02;   // floor of the LSM sigma written, px, > 0 (unmodelled errors)
  int descriptor_size_px = 16;  // support of the SIFT descriptor at Foerstner points, px
  RansacOptions ransac;
  LsmOptions lsm;
  WallisOptions wallis;
  FoerstnerOptions foerstner;
  void Validate() const;  // throws ConfigError naming the field
};

}  // namespace aerocal::stitch
