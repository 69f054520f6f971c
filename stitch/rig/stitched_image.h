// The horizontal stitched image of one rig exposure (issue 16 item 6; `aerocal rig stitch
// --images DIR --stitched-out DIR`): every head image resampled ONCE from its raw pixels onto the
// level virtual image of the exposure (the rig convert resampling: plane homography plus the
// head's correction grid, stitch/rig/rig_convert.h), with the exposure's refined increments E_k and
// offsets dT_k in the converter (no intermediate image, so no double resampling); then, per
// virtual pixel, only linear combinations of those values:
//
// - radiometric balance ("dodging"): per non-reference head a gain g_k and offset o_k (the
//   reference head holds g = 1, o = 0), fitted by least squares to the overlaps: for every sampled
//   virtual pixel seen by heads j and k, (g_j I_j + o_j) - (g_k I_k + o_k) = 0 (unit weight);
// - blending: a feathered mean of the balanced values, weight w_k = min(distance to the border of
//   head k's coverage, feather_px) (OpenCV L2 distance transform, px), so every head fades out
//   towards its border: no seam where the number of heads changes;
// - valid-area mask: 255 where at least one head covers the pixel, 0 elsewhere (value 0 there).
//
// Overlap disagreement (the seamlessness figure): at every virtual pixel seen by two heads j < k,
// d = (g_j I_j + o_j) - (g_k I_k + o_k) BEFORE blending; per head pair ("AB": the pair, also
// inside triple zones) and over all pairs: RMS and mean of d (DN). With correct geometry and
// balance it is the grey-value noise of the two interpolated heads; misregistration adds
// |grad I| x the misregistration.
//
// Precision: 8-bit heads are resampled as 16-bit (x 256), so the interpolated values keep 1/256 DN;
// the output has the heads' depth (rounded).
//
// Cost: each head is resampled, and its distance transform taken, over its footprint's box only
// (HeadFootprintBox: its format's border through the exact map, plus a margin), not over the
// whole virtual format; the box's pixels are the whole format's bit for bit (VirtualRegion in
// virtual_image.h; the distance transform's too, since the box keeps a ring of uncovered pixels
// or the format's own edge around the coverage, checked). Memory: 3 bytes per head and pixel of
// its box, plus the output strip.
#pragma once

#include "calib/core/finding.h"
#include "stitch/resample/raster.h"
#include "stitch/resample/virtual_image.h"
#include "stitch/rig/rig_conversion.h"

#include <cstdint>
#include <string>
#include <vector>

namespace aerocal::stitch {

struct StitchedImageOptions {
  Interpolation interpolation = Interpolation::kBilinear;
  bool balance = true;     // dodging; false: every head g = 1, o = 0
  int sample_step_px = 2;  // overlap pixels sampled for the balance every this many px, 1..64
  int feather_px = 64;     // blending ramp (px), 1..255
  int strip_rows = 256;    // resampling strips, > 0
  void Validate() const;   // ConfigError naming the field
};

struct HeadRadiometry {
  std::string head;
  double gain = 1.0, offset_dn = 0.0;
  long samples = 0;        // overlap samples that involve the head
  bool reference = false;  // held at g = 1, o = 0
};

struct OverlapDisagreement {
  std::string zone;  // head pair "AB", or "all"
  long pixels = 0;
  double rms_dn = 0.0, mean_dn = 0.0;
};

struct StitchedImageReport {
  int width_px = 0, height_px = 0, bits = 8;
  long valid_pixels = 0;
  std::vector<HeadRadiometry> heads;
  std::vector<OverlapDisagreement> zones;  // per head pair with overlap
  OverlapDisagreement overall;             // zone "all"
  std::vector<Finding> warnings;  // e.g. a head without overlap (held); calib/core/finding.h
};

/// One head's pixels resampled alone onto the converter's virtual grid through the `rig convert`
/// map (plane homography plus `grid`, stitch/rig/rig_convert.h): `values` (virtual format, one
/// band, the source's depth) and `covered` (row-major virtual format: 255 where the resampler puts
/// the virtual pixel inside the head's format, 0 elsewhere; its own rule: the coverage output of
/// the same resampling pass, the set a constant image through the same map covers). Shared by the
/// stitched image and the tie matching (rig_tie_matching.h). With `resample.region` set, only that
/// box of the virtual image (values and covered are region-sized; `region` says which pixels they
/// hold), each pixel equal to the whole format's.
struct HeadProjection {
  VirtualRegion region;  // the virtual pixels held (the whole format when the request had none)
  MemoryRaster values;
  std::vector<std::uint8_t> covered;
};
HeadProjection ProjectHeadOntoVirtual(const RigConverter& converter,
                                      int head,
                                      const MapCorrectionGrid& grid,
                                      RasterSource* source,
                                      const ResampleOptions& resample = {});

/// The box of the virtual image holding head `head`'s coverage: its format's border (every 16 px
/// and the corners) through the converter's exact map, widened by `margin_px` and cut to the
/// format; empty (the whole format) when a border pixel has no virtual image (beyond the
/// horizon of the rectification plane).
VirtualRegion HeadFootprintBox(const RigConverter& converter, int head, int margin_px = 8);

/// ProjectHeadOntoVirtual over the head's footprint box; the whole format instead when the
/// coverage reaches the box's border anywhere but at the format's edge (then the box would cut
/// it, or the distance transform at its border would differ from the whole format's).
HeadProjection ProjectHeadFootprint(const RigConverter& converter,
                                    int head,
                                    const MapCorrectionGrid& grid,
                                    RasterSource* source,
                                    const ResampleOptions& resample = {});

/// Makes the stitched image of the converter's exposure from `sources` (one per head, rig order,
/// each of its head's format, one band, 8 or 16 bit) into `image` (virtual format, one band, the
/// sources' depth) and `mask` (virtual format, 8 bit). InputError naming the head when a source
/// does not fit.
StitchedImageReport MakeStitchedImage(const RigConverter& converter,
                                      const std::vector<RasterSource*>& sources,
                                      const StitchedImageOptions& options,
                                      RasterSink* image,
                                      RasterSink* mask);

}  // namespace aerocal::stitch
