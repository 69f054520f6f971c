// What resampling does to the MTF (issue 36 item 3: the virtual image's resolution against the raw
// sub-images'). Interpolating a sampled image with a kernel k and sampling it again at phases
// spread over the pixel (a virtual image whose mapping is not a whole-pixel shift) gives, as the
// slanted edge measures it, the raw image's MTF times the kernel's transfer function K(f) along
// each axis (aliasing of the raw image's content above Nyquist neglected):
//   bilinear: k the triangle of half-width 1 px, K(f) = sinc^2(f);
//   bicubic (Keys 1981, a = -0.5): K(f) the kernel's Fourier transform (numerically).
// For an edge normal at angle t to the x axis: MTF_virtual(f) = MTF_raw(f) K(f cos t) K(f sin t).
#pragma once

#include "stitch/quality/slanted_edge.h"
#include "stitch/resample/virtual_image.h"

namespace aerocal::stitch {

/// K(f) of the interpolation kernel along one axis, f in cycles/px (>= 0).
double InterpolationTransfer(Interpolation kind, double f_cy_px);

/// The MTF50 an edge measured in a raw image will have after resampling with `kind`, its normal at
/// `normal_angle_rad` to the resampled image's x axis. NaN when the product does not fall to 0.5
/// below 1 cycle/px.
double PredictResampledMtf50(const SlantedEdgeResult& raw,
                             Interpolation kind,
                             double normal_angle_rad);

}  // namespace aerocal::stitch
