// Cloud control on real pixels (issue 17, `aerocal pushbroom control`, module README "Image mode"):
// 1. the line image is rectified onto the plane Z = mean terrain height with the POS and the
//    nominal camera (the "L1" image, line_rectification.h);
// 2. Foerstner interest points (stitch/matching/interest_operators.h) on the L1 image;
// 3. each point's ground position on the plane is projected into every oriented reference frame
//    image; a normalised cross-correlation search (+- search_px L1 cells, the reference image
//    resampled through the local affine ground -> reference pixel) absorbs the relief displacement,
//    then least-squares matching (Gruen 1985, stitch/matching/least_squares_matching.h) refines
//    the position to sub-pixel with its covariance;
// 4. the rays of >= 2 reference images are forward-intersected (weighted by the matching
//    covariances, floored at min_match_sigma_px) into a ground point with its covariance N^-1;
// 5. gross errors: a point whose weighted reprojection misclosure v^T P v exceeds the chi-square
//    quantile (1 - gross_error_alpha, 2n - 3) loses its worst ray and is intersected again (it is
//    dropped below two rays); points with a sigma above max_point_sigma_m are dropped; on the
//    line-image side, the misclosure against the nominal camera and the POS is smooth in the
//    detector index (calibration, POS error): per sub-camera and axis a robust degree-5 fit drops
//    points off it by more than line_outlier_k x 1.4826 MAD (and line_outlier_min_px).
// 3b. the match is then refined from the line image itself: the template centred on the integer
//    line-image pixel q nearest to the L1 cell's position (moved inside its sub-camera so that it
//    does not cross a seam) is matched by least squares into the reference image, starting from
//    the L1 match, with the local affine line pixel -> plane -> reference pixel. The line-image
//    observation of the point is q itself (no interpolated line-image grey value enters it).
//    Why: an L1 grey value is interpolated at a fractional line-image position whose fraction
//    drifts slowly over the L1 grid (L1 cells are not the detectors), and interpolation shifts
//    fine texture towards the nearest sample, so the L1 template's content is off its map position
//    by a smooth function of the detector: measured, a 0.08 px across-track table bias.
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/line_camera.h"
#include "stitch/image_io/gray_image.h"
#include "stitch/matching/interest_operators.h"
#include "stitch/matching/least_squares_matching.h"
#include "triangulation/block/block.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_rectification.h"
#include "triangulation/pushbroom/pos_trajectory.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct CloudControlOptions {
  double mean_height_m = 0.0;  // height of the L1 rectification plane, m
  double gsd_m = 0.0;          // L1 cell size, m; 0: the POS line spacing
  int map_step_px = 8;         // exact inverse every N cells, bilinear between, 1 .. 64
  stitch::FoerstnerOptions foerstner = {5, 0.5, 0.5, 9, 5000};  // window, q_min, w factor, NMS, max
  int template_half_px = 7;      // correlation and LSM template (2h+1)^2, 3 .. 30
  int search_px = 15;            // correlation search +- L1 cells (relief displacement), 0 .. 100
  double min_correlation = 0.7;  // of the correlation peak, 0 .. 1
  stitch::LsmOptions lsm;        // half_size_px is set to template_half_px
  double min_match_sigma_px = 0.05;  // floor of the LSM position sigma, px, > 0
  double line_sigma_px = 0.05;       // sigma written for the line-image observations, px, > 0
  double gross_error_alpha = 0.001;  // of the misclosure test, (0, 0.5)
  double max_point_sigma_m = 1.0;    // drop points less precise than this (largest axis), m, > 0
  double line_outlier_k = 5.0;       // line-side gross errors: |v| > k 1.4826 MAD of the smooth fit
  double line_outlier_min_px = 0.25;  // ... and above this, px, > 0
  void Validate() const;              // ConfigError naming the option
};

/// One oriented reference frame image (the block result of `aerocal adjust`).
struct ReferenceFrame {
  std::string id;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d opk_rad = Eigen::Vector3d::Zero();
  stitch::GrayImage image;
};

struct CloudControlResult {
  L1Image l1;
  std::vector<LineObservation> observations;  // col = detector, row = line
  std::vector<GroundPoint> points;            // control points with their intersection sigmas
  int n_interest = 0;                         // Foerstner points on the L1 image
  int n_rays = 0;                             // successful matches into reference images
  int n_no_match = 0;                         // fewer than two reference images matched
  int n_gross = 0;                            // dropped by the misclosure test
  int n_imprecise = 0;                        // dropped by max_point_sigma_m
  int n_rays_removed = 0;                     // single rays removed as gross errors (point kept)
  int n_line_outliers = 0;  // dropped by the smooth-misclosure test of the line image
  double median_match_sigma_px = 0.0;
};

CloudControlResult MakeCloudControl(const calib::LineCamera& camera,
                                    const PosTrajectory& pos,
                                    const stitch::GrayImage& line_image,
                                    const calib::Camera& reference_camera,
                                    const std::vector<ReferenceFrame>& references,
                                    const CloudControlOptions& options);

/// control.json (kind "pushbroom_control", written by WriteResult): the counts above, the L1 grid
/// and the options used.
nlohmann::json CloudControlToJson(const CloudControlResult& result,
                                  const CloudControlOptions& options);

}  // namespace aerocal::triangulation
