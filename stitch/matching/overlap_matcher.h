// Tie points of one multi-CCD frame, measured on the pixels of its sub-images:
//  1. overlap strips and search windows from the camera's nominal mappings (overlap_strips.h);
//  2./3. candidates (strip_candidates.h, MatchOptions::search): keypoints in both windows (SIFT,
//     Lowe 2004, or the Foerstner operator on the Wallis-filtered window with upright SIFT
//     descriptors) matched with Lowe's ratio test and gated by the nominal prediction; or the
//     strongest Foerstner points of a per cell, found in b by normalised cross-correlation
//     around the nominal prediction;
//  4. RANSAC on the local affine mapping b <- a of the strip (local_mapping.h);
//  5. even distribution: a grid of square cells (virtual px) over the strip; in each cell the best
//     candidates (lowest ratio) are tried in turn until `points_per_cell` are accepted;
//  6. least-squares matching (least_squares_matching.h) refines each tried candidate; a template
//     centred on an integer pixel of a is matched into b. Failed LSM drops the candidate (counted).
// Output rows follow FORMATS.md "Stitching measurements"; point ids are "<strip>_<k>" (e.g.
// "I-II_7"), unique within the frame. With LSM, sigma_px of each of the two rows is the LSM
// position sigma (larger axis) / sqrt(2), so the tie's difference carries the LSM sigma, but not
// below `min_sigma_px`; without LSM every row gets `sigma_px`.
// Deterministic: fixed seeds, keypoints sorted, strips processed in parallel into fixed slots.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/image_io/gray_image.h"
#include "stitch/matching/match_options.h"
#include "stitch/simulation/stitch_simulator.h"

#include <string>
#include <vector>

namespace aerocal::stitch {

/// Counts of one overlap strip.
struct StripReport {
  std::string name;  // "I-II"
  int keypoints_a = 0, keypoints_b = 0;
  int ratio_matches = 0;  // candidates: after the ratio test and prediction gate, or NCC peaks
  int ransac_inliers = 0;
  int lsm_tried = 0;
  int lsm_not_converged = 0;   // includes leaving the image and drifting off
  int lsm_poor_precision = 0;  // sigma > lsm.max_sigma_px or correlation < lsm.min_correlation
  int points = 0;              // tie points written
  int cells = 0, covered_cells = 0;
  double Coverage() const { return cells > 0 ? static_cast<double>(covered_cells) / cells : 0.0; }
};

struct FrameMatches {
  std::vector<StitchObservation> observations;  // two rows per tie point, strip order
  std::vector<StripReport> strips;
};

/// Matches all predicted overlap strips of one frame. `images[k]` is sub-image k of `camera`
/// (its format is checked: LogicError when it differs; readers check files first).
FrameMatches MatchFrame(const calib::Camera& camera,
                        const std::vector<GrayImage>& images,
                        const std::string& frame,
                        const MatchOptions& options);

/// Writes `observations` as stitch_obs.csv, atomically. With `append` and an existing file, its
/// rows are kept (rows without sigma_px get `default_sigma_px`) and the new frames added; a frame
/// already in the file is an InputError naming the file and the frame.
void WriteMatchedObservations(const std::string& path,
                              const std::vector<StitchObservation>& observations,
                              bool append,
                              double default_sigma_px);

}  // namespace aerocal::stitch
