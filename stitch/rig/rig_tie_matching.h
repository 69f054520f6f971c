// Tie points of a rig exposure matched on the head images (issue 16 item 2; `aerocal rig stitch
// --match-ties`): with the ground calibration and the POS (no increments, no offsets) every head
// is resampled once onto the level virtual image of the exposure (plane Z = z_ref, the stitched
// image's projection: stitch/rig/stitched_image.h ProjectHeadOntoVirtual); on the virtual grid
// the overlap zones are the pixels covered by the same set of two or more heads ("AB", ...,
// triple zones "ABC"), each shrunk by the LSM template and search margin. Only the windows the
// matching needs are projected (stitch/rig/head_window.h; issue 35): the zones are found on a grid
// of every 4th virtual px (coverage and its distance transform; a point's zone is decided at the
// point, from 17 samples of the disc of the margin), the interest points on the first head's
// projection of each cell grown by the Wallis and Foerstner supports, LSM between windows of a
// few tens of px around the point. `whole_projections` keeps the former path: every head on the
// whole virtual format, Foerstner over each zone's bounding box (the same rule per cell; its
// mean-weight threshold then over the whole box instead of the cell). The matcher of
// `aerocal match` (stitch/matching) then works per zone:
//  1. Foerstner points (interest_operators.h) on the Wallis-filtered projection of the zone's
//     first head (rig order), the strongest one per square cell of the exposure's tie cell
//     (`TieCellPx`: `cell_px`, grown at large formats so the zones hold about `target_ties`
//     cells: the self-calibration's error against the truth does not improve beyond a few
//     hundred ties per exposure, its cost grows with them; stitch/README.md "Tie density");
//  2. least-squares matching (least_squares_matching.h) of its template into the projection of
//     each other head of the zone, starting at the same virtual pixel (the ground calibration
//     leaves ~2 px; LSM's shift bound `lsm.max_shift_px`), both projections low-passed by a
//     Gaussian of `prefilter_sigma_px` (normalised over the head's coverage). Why: the grey-value
//     noise of a head, resampled onto the virtual grid and again by LSM's bicubic interpolation,
//     has a variance that depends on the sub-pixel phase, which pulls the LSM optimum towards
//     certain phases; the phase follows the ~2 px misregistration smoothly over a zone, so the
//     pull is a systematic error per zone (0.02-0.08 px without the prefilter, measured against
//     the simulator's truth; about 0.01 px and below with 1.5 px: stitch/README.md);
//  3. measured back in RAW head pixels through the exact conversion (RigConverter::HeadFromVirtual:
//     plane, the head's full interior model inverted): the first head's point and every matched
//     position; a tie keeps the heads whose match converged (at least two heads).
// Sigma of each observation row: the LSM position sigma (larger axis) / sqrt(2), not below
// `min_sigma_px`, in virtual px, times the head's local scale (head px per virtual px, the larger
// singular value of the conversion's Jacobian); the first head's row takes the largest LSM sigma
// of its tie. Deterministic (fixed order, no random sampling).
#pragma once

#include "calib/camera/rig.h"
#include "stitch/image_io/gray_image.h"
#include "stitch/matching/interest_operators.h"
#include "stitch/matching/least_squares_matching.h"
#include "stitch/rig/rig_conversion.h"
#include "stitch/rig/self_calibration.h"

#include <string>
#include <vector>

namespace aerocal::stitch {

struct RigTieMatchOptions {
  double cell_px = 40.0;            // one tie per cell of this side per zone, virtual px, >= 8:
                                    // the smallest cell (TieCellPx)
  double target_ties = 2000;        // about this many cells over an exposure's zones (the
                                    // cell grows beyond cell_px to keep to it; cells at the
                                    // zones' borders add some); 0: cell_px always
  double min_sigma_px = 0.02;       // floor of the LSM sigma written, virtual px, > 0
  double prefilter_sigma_px = 1.5;  // Gaussian low-pass of the projected heads for LSM (header
                                    // comment), virtual px; 0: none, else 0.3..5
  bool whole_projections = false;   // true: the former path (every head projected onto the whole
                                    // virtual format); false: small windows (header comment)
  LsmOptions lsm;
  WallisOptions wallis;
  FoerstnerOptions foerstner;
  void Validate() const;  // ConfigError naming the field
};

/// Counts of one zone of one exposure.
struct RigZoneMatchReport {
  std::string image, zone;  // "AB", "ABC"
  long pixels = 0;          // zone pixels (after the margin)
  double cell_px = 0;       // the exposure's tie cell, virtual px (TieCellPx)
  int cells = 0;            // cells with a Foerstner point in the zone
  int lsm_tried = 0, lsm_failed = 0;
  int ties = 0;  // ties written (two or more heads)
};

struct RigTieMatches {
  std::vector<RigStitchTie> ties;                  // ids "<image>/<zone>-<n>", fitted ties
  std::vector<RigStitchObservation> observations;  // indices into `ties`, the exposures, the heads
  std::vector<double> lsm_sigma_px;  // per tie: its largest LSM position sigma (larger axis),
                                     // virtual px: the matching noise of the tie's differences
  std::vector<RigZoneMatchReport> zones;
};

/// The tie cell of an exposure whose overlap zones (two or more heads, after the margin) hold
/// `zone_pixels` virtual px: `cell_px`, or the side of `target_ties` square cells covering them,
/// rounded up to a multiple of 8 px (both matching paths estimate the pixels differently; the
/// rounding makes them choose the same cell), whichever is larger.
double TieCellPx(const RigTieMatchOptions& options, double zone_pixels);

/// Matches the ties of exposure `exposure_index` (`exposure`: its POS and z_ref) on `heads` (one
/// image per head of `rig`, rig order, each of its head's format; LogicError otherwise) and
/// appends them to `out` (tie indices continue from out->ties.size()).
void MatchRigExposureTies(const calib::Rig& rig,
                          const RigStitchExposure& exposure,
                          int exposure_index,
                          const std::vector<GrayImage>& heads,
                          const RigTieMatchOptions& options,
                          RigTieMatches* out);

}  // namespace aerocal::stitch
