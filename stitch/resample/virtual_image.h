// Resampling the sub-images of a multi-CCD frame into the virtual image
// (CONVENTIONS.md "Sub-image to virtual image").
//
// For every virtual pixel (U, V), each sub-image k gives (u, v) = Map_k^-1(U, V) (the exact
// inverse of the projectivity). Sub-image k covers the pixel when (u, v) lies within its pixel
// centres, 0 <= u <= W-1 and 0 <= v <= H-1; its grey value is interpolated there (bilinear, or
// bicubic convolution with a = -0.5, Keys 1981, edge samples repeated). A pixel covered by no
// sub-image gets the fill value; a pixel covered by several gets the plain (equal-weight) average
// of their values: after radiometric equalisation the sub-images agree in the overlaps to the
// interpolation error, so the average halves the noise there without a weighting ramp.
//
// Memory stays bounded: the virtual image is made in strips of `strip_rows` rows; for each strip
// only the window of each sub-image that the strip needs is read. Rows of a strip are resampled in
// parallel (TBB). Column ranges covered by a sub-image are solved per row in closed form (each
// bound u >= 0, u <= W-1, ... is linear in U for a projectivity with positive denominator), so the
// inner loop has no coverage tests.
//
// Two paths give the same coverage and the same values to well below 0.5 DN (tested):
// - fast (fast_strip.h; bilinear, one band, no correction grid, the default there): each row is
//   cut into intervals seen by the same sub-images, single coverage is written straight to the
//   output and only overlap bands are averaged; positions are 32.32 fixed point stepped along the
//   row (exact for an affine mapping, chords within 1e-5 px of a projectivity) and a sub-image at
//   about the virtual scale is interpolated 16 columns at a time by a vectorised loop
//   (bilinear_run.h); a source held in memory (RasterSource::Samples) is read in place;
// - reference (everything else, or ResampleOptions::reference): per pixel, (u, v) from the exact
//   projectivity in double, then float; bicubic, 3 bands and correction grids go this way.
// The fast path's output is bit-identical whatever the thread count and strip height (tested),
// the reference path's whatever the thread count.
//
// A region (ResampleOptions::region) makes only a rectangle of the virtual image, each of its
// pixels bit-identical to the whole format's: the same strips (aligned to strip_rows from row 0),
// the same sub-image windows, and every row's positions stepped from the same column as in the
// whole row; only the pixels outside the rectangle are not computed. One sub-image's footprint
// (the rig's stitched image) then costs its footprint, not the format.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/resample/raster.h"

#include <string>
#include <vector>

namespace aerocal::stitch {

enum class Interpolation { kBilinear, kBicubic };

/// A rectangle of the virtual image (virtual px: columns x0 .. x0 + width - 1, rows y0 ..
/// y0 + height - 1). Width 0: the whole format.
struct VirtualRegion {
  int x0 = 0, y0 = 0, width = 0, height = 0;
  bool Empty() const { return width <= 0; }
  bool operator==(const VirtualRegion& o) const {
    return x0 == o.x0 && y0 == o.y0 && width == o.width && height == o.height;
  }
};

struct ResampleOptions {
  Interpolation interpolation = Interpolation::kBilinear;
  double fill = 0.0;       // value of uncovered pixels, in the output's range
  int strip_rows = 256;    // rows per strip, > 0 (memory ~ strip_rows x (virtual width + sources))
  int threads = 0;         // 0: all cores
  bool reference = false;  // true: the per-pixel reference path even where the fast one applies
  /// Only this rectangle (inside the format) is made: the sink receives region.height rows of
  /// region.width pixels, equal bit for bit to the whole format's there. Empty: the whole format.
  VirtualRegion region;
};

struct ResampleReport {  // counts over the region made (the whole format by default)
  long covered = 0;      // virtual pixels covered by at least one sub-image
  long overlap = 0;      // covered by two or more
  long filled = 0;       // covered by none
  double seconds = 0;
};

/// A smooth correction of one source's map beyond its projectivity (lens distortion of a rig
/// head, relief parallax over a DEM): (du, dv) source pixels added to Map_k^-1(U, V), given on a
/// grid of virtual pixels (nodes at U = i step, V = j step, i < cols, j < rows; row-major,
/// interleaved du, dv) and interpolated bilinearly in between (clamped at the last node). With a
/// correction, coverage is decided per pixel on the corrected (u, v).
struct MapCorrectionGrid {
  int step_px = 0;          // > 0
  int cols = 0, rows = 0;   // nodes; (cols - 1) step >= virtual width - 1, likewise rows
  std::vector<float> duv;   // 2 cols rows values
  float max_abs_px = 0.0f;  // largest |du|, |dv| (window margins)
};

/// Writes the virtual image of `camera` (format camera.width_px x height_px, mappings of
/// camera.subimages) from `sources` (one per sub-image, camera order, each of its sub-image's
/// format; all of one bit depth and band count) to `sink`, with the sources' depth and bands.
/// Throws InputError naming the sub-image when a source's format, depth or bands do not match.
/// `corrections`: empty, or one per sub-image (a grid with step 0 = none for that sub-image).
/// `coverage` (optional; one band, 8 bit, the sink's format): 255 where at least one sub-image
/// covers the pixel (the pixels that get a value, not the fill), 0 elsewhere.
ResampleReport ResampleVirtualImage(const calib::Camera& camera,
                                    const std::vector<RasterSource*>& sources,
                                    RasterSink* sink,
                                    const ResampleOptions& options,
                                    const std::vector<MapCorrectionGrid>& corrections = {},
                                    RasterSink* coverage = nullptr);

Interpolation ParseInterpolation(const std::string& name);  // ConfigError when unknown

/// Text of the mappings for the output's metadata: a first line naming the format, then one line
/// per sub-image "ID MODEL W H p1 p2 ..." (plain parameters, FORMATS.md order, 17 digits).
std::string MappingDescription(const calib::Camera& camera, const std::string& source);

}  // namespace aerocal::stitch
