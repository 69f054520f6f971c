// Edge targets of the simulated flight (issue 36, the flight example): square resolution targets
// laid out on the ground, and small patches of the raw sub-images rendered where an exposure sees
// one of their edges, with the virtual image's patch resampled from them by the production
// resampler (bilinear). Whole 14000 x 12000 frames are never made: a patch is the target's
// neighbourhood only.
//
// Each target is a bright square of side `edge_length_m` on a dark ground, turned by `slant_deg`
// about the vertical at the terrain height; its west edge runs nearly north-south (in a kappa 0 /
// 180 deg image nearly along the columns: its MTF along x) and its north edge nearly east-west
// (along y), so one target gives both directions. A patch is centred on an edge's middle, where
// no corner is in view (edge_length_m / 2 from a corner, > half a patch at the flight's GSD).
//
// Rendering, per exposure and edge: the edge's middle +- edge_length_m / 4 projected through the
// true camera (collinearity and distortion, calib::Camera::ProjectToPixel) into the virtual image
// and through the sub-image's true mapping (SubFromVirtual) into the raw sub-image; there the edge
// is the straight line through the two points (distortion bends it by far less than 0.01 px over
// a patch) blurred by the Gaussian PSF of `psf_sigma_px` (raw pixels) and integrated over each
// pixel's area in closed form (stitch/simulation/rendered_edge.h), plus Gaussian noise, rounded to
// 16 bits. The virtual patch: ResampleVirtualImage on a camera of the patch's format whose one
// sub-image is the raw patch, its mapping the true one shifted to the two windows' origins. A
// patch is made only where one sub-image alone covers the virtual window (outside the overlaps,
// where the virtual image averages two sub-images).
#pragma once

#include "stitch/quality/edge_targets.h"
#include "stitch/quality/slanted_edge.h"
#include "triangulation/simulation/flight_simulator.h"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct FlightEdgeTargetOptions {
  int targets_x = 2, targets_y = 2;  // targets on a grid over the block's inner half (>= 1)
  double edge_length_m = 40.0;       // side of the square (m, > 0)
  double slant_deg = 5.0;            // turn of the square about the vertical (deg, 2..10)
  double psf_sigma_px = 1.0;         // Gaussian PSF of the raw sub-images (raw px, 0.3..3)
  double dark_dn = 8000.0, bright_dn = 40000.0;  // 16-bit grey values of ground and target
  double noise_dn = 40.0;                        // Gaussian noise of the raw pixels (DN, >= 0)
  int patch_px = 96;                             // side of a virtual patch (px, >= 48)
  int region_px = 80;      // side of the measured region (px, <= patch_px - 8)
  std::uint64_t seed = 1;  // noise
};

/// The targets' edges (two per target, ids "<target>_x" and "<target>_y" by the axis of their
/// MTF), bright on the left of start -> end seen from above (X east, Y north).
std::vector<stitch::EdgeTarget> LayOutEdgeTargets(const SimulatedFlight& flight,
                                                  const FlightEdgeTargetOptions& options);

struct EdgeTargetPatch {
  std::string target, image, subimage;  // edge id, exposure's image, sub-image id
  stitch::GrayImage raw;                // raw sub-image window, 16-bit DN
  stitch::GrayImage virtual_image;      // virtual image window resampled from it (bilinear)
  Eigen::Vector2i raw_origin_px = Eigen::Vector2i::Zero();      // top-left pixel in the sub-image
  Eigen::Vector2i virtual_origin_px = Eigen::Vector2i::Zero();  // top-left pixel in the virtual
  stitch::PixelRegion raw_region, virtual_region;     // where to measure, in the patches' pixels
  stitch::MtfAxis axis = stitch::MtfAxis::kX;         // the virtual image axis nearer the normal
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();  // unit edge normal in the virtual image
  Eigen::Vector2d raw_normal = Eigen::Vector2d::UnitX();  // and in the raw sub-image
  /// Sub-pixel shifts (dx, dy) in [0, 1) of the virtual region's pixels in the sub-image: what
  /// the bilinear interpolation weighs by (stitch/quality/resampling_mtf.h).
  std::vector<Eigen::Vector2d> shifts;
  double gsd_m = 0.0;  // ground length per virtual pixel along the edge
};

/// The patches of every edge in every true exposure that sees it inside one sub-image, in
/// exposure order then target order. Throws ConfigError naming the option when an option is out
/// of range.
std::vector<EdgeTargetPatch> RenderEdgeTargetPatches(const SimulatedFlight& flight,
                                                     const std::vector<stitch::EdgeTarget>& edges,
                                                     const FlightEdgeTargetOptions& options);

/// Writes the patches into `folder` (created): `raw_<SUB>.tif` per sub-image and `virtual.tif`,
/// 16-bit mosaics of the patches (tiles of patch_px + 16 px, 8 to a row, 0 between them), so that
/// one `aerocal quality mtf --image FILE --roi ...` measures all edges of a file; `patches.csv`
/// (docs/formats.md "Edge target patches": per patch its edge, image, sub-image, axis, the regions
/// to measure in the mosaics, the windows' origins, the mean sub-pixel shift and the GSD); and
/// `targets.csv` (the edges' ground ends). Every text file is written atomically.
void WriteEdgeTargetPatches(const std::vector<EdgeTargetPatch>& patches,
                            const std::vector<stitch::EdgeTarget>& edges,
                            const FlightEdgeTargetOptions& options,
                            const std::string& folder);

}  // namespace aerocal::triangulation
