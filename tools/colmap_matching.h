// COLMAP's feature extraction, matching and sparse reconstruction driven for `aerocal import images
// DIR --match colmap` (issue 34 item 3). COLMAP (the Debian package, CPU only) runs as a program;
// its databases and models stay in `work_dir` (OUT/colmap) for inspection, each step's output in
// <step>.log there. The steps (COLMAP 3.8 command line):
//   feature_extractor   SIFT on every image of DIR (one camera per folder; --colmap-max-image-px)
//   exhaustive_matcher  every pair (default), or spatial_matcher: pairs near in the EXIF GPS
//   mapper              incremental SfM; of several models the one with most images is used
//   model_aligner       the model onto the import's GNSS centres in ECEF (a similarity, RANSAC
//                       with --colmap-align-error-m as inlier bound)
//   model_converter     the aligned model as text for `import colmap`
#pragma once

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace aerocal::tools {

struct ColmapMatchingOptions {
  std::string program = "colmap";      // the COLMAP executable (PATH searched)
  std::string matcher = "exhaustive";  // exhaustive | spatial
  std::string work_dir;                // created; COLMAP's files and logs
  int max_image_px = 3200;             // SIFT on images downscaled to this longer side, > 0
  double align_error_m = 10;           // model_aligner inlier bound, m, > 0
};

/// Runs the steps above on `images_dir` with `ecef_centres` (image file name -> X, Y, Z m) as the
/// aligner's references; returns the folder of the aligned text model. ConfigError when the
/// program cannot be started, InputError naming the step and its log when a step fails or
/// COLMAP registers fewer than 3 images with a reference.
std::string RunColmapMatching(
    const std::string& images_dir,
    const std::vector<std::pair<std::string, Eigen::Vector3d>>& ecef_centres,
    const ColmapMatchingOptions& options);

}  // namespace aerocal::tools
