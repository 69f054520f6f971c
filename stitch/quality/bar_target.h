// Bar targets: the contrast modulation of bar groups of known frequency and the limiting frequency
// at a stated modulation threshold (e.g. 10 %), as for a USAF 1951 / ISO 12233 hyperbolic-wedge
// reading, but measured instead of judged by eye.
//
// Per group (bars of one frequency, their direction given by the axis across which the grey value
// varies): the region's grey values are linearised (DN^gamma), averaged along the bars into one
// profile across them, cut into windows of one period each; the mean of the windows' maxima and
// minima gives Imax and Imin, the modulation M = (Imax - Imin) / (Imax + Imin). The large-area
// modulation M0 = (B - D) / (B + D) of a bright and a dark reference region normalises it: the
// contrast transfer CT = M / M0 (1 at low frequencies; Coltman's square-wave response for
// periodic bars). The limiting frequency is where CT falls to the threshold: linear in
// log(frequency) between the last group at or above it and the first group below.
// Units: frequencies in cycles per pixel of this image; ToGroundResolution (slanted_edge.h) gives
// lp/mm and the ground resolved distance.
#pragma once

#include "stitch/image_io/gray_image.h"
#include "stitch/quality/slanted_edge.h"

#include <vector>

namespace aerocal::stitch {

struct BarGroup {
  double frequency_cy_px = 0.0;  // bar frequency in the image, cycles/px, within (0, 0.5]
  PixelRegion region;            // the bars (at least two periods across, 4 px along)
  MtfAxis axis = MtfAxis::kX;    // axis across the bars (x: vertical bars, grey value by column)
};

struct BarTargetOptions {
  double gamma = 1.0;      // linearisation: value = DN^gamma, (0, 10]
  double threshold = 0.1;  // contrast transfer defining the limiting frequency, (0, 1)
  void Validate() const;   // throws ConfigError naming the field
};

struct BarGroupModulation {
  double frequency_cy_px = 0.0;
  double modulation = 0.0;         // (Imax - Imin) / (Imax + Imin)
  double contrast_transfer = 0.0;  // modulation / reference modulation
};

struct BarTargetResult {
  double reference_modulation = 0.0;       // (B - D) / (B + D) of the large areas
  std::vector<BarGroupModulation> groups;  // by increasing frequency
  // Frequency (cycles/px) where the contrast transfer falls to the threshold; NaN when already the
  // lowest group is below it. When no group falls below it, the highest group's frequency with
  // limit_in_range = false (the limit lies beyond the target).
  double limiting_frequency_cy_px = 0.0;
  bool limit_in_range = true;
};

/// Measures the groups against the bright and dark reference regions. InputError naming the group
/// (by frequency) or the reference when a region leaves the image or is too small, when a group
/// holds fewer than two periods, or when the references have no contrast.
BarTargetResult MeasureBarTarget(const GrayImage& image,
                                 const std::vector<BarGroup>& groups,
                                 const PixelRegion& bright,
                                 const PixelRegion& dark,
                                 const BarTargetOptions& options = {});

}  // namespace aerocal::stitch
