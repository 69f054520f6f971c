// What resampling does to the MTF (issue 36 item 3: the virtual image's resolution against the raw
// sub-images'). Interpolating a sampled image with a kernel k and sampling it again at phases
// spread over the pixel (a virtual image whose mapping is not a whole-pixel shift) gives, as the
// slanted edge measures it, the raw image's MTF times the kernel's transfer function K(f) along
// each axis (aliasing of the raw image's content above Nyquist neglected):
//   bilinear: k the triangle of half-width 1 px, K(f) = sinc^2(f);
//   bicubic (Keys 1981, a = -0.5): K(f) the kernel's Fourier transform (numerically).
// For an edge normal at angle t to the x axis: MTF_virtual(f) = MTF_raw(f) K(f cos t) K(f sin t).
//
// With the exact shifts of the mapping instead of phases spread over the pixel: bilinear
// interpolation at a sub-pixel shift d (the virtual pixel at u = floor(u) + d) weighs the raw
// samples at offsets -d and 1 - d from it by 1 - d and d, so its transfer along that axis,
// referred to the virtual pixel's position, is
//   H_d(f) = (1 - d) e^{-2 pi i f d} + d e^{2 pi i f (1 - d)},  |H_d(f)| = |(1 - d) + d e^{2 pi i
//   f}|
// (1 at d = 0, |cos(pi f)| at d = 1/2). A slanted edge averages its ESF over the pixels of its
// region, so the transfer it measures is |mean over those pixels of H_dx(f nx) H_dy(f ny)| (the
// bilinear kernel separates per axis); over shifts spread uniformly in [0, 1) this mean is
// sinc^2 per axis, the formula above. A mapping that is nearly a translation (the CCDs of a
// multi-CCD camera) has one shift for the whole region: a CCD at a whole-pixel offset loses
// nothing, one at half a pixel loses most.
#pragma once

#include "stitch/quality/slanted_edge.h"
#include "stitch/resample/virtual_image.h"

#include <Eigen/Core>

#include <vector>

namespace aerocal::stitch {

/// K(f) of the interpolation kernel along one axis, f in cycles/px (>= 0).
double InterpolationTransfer(Interpolation kind, double f_cy_px);

/// The MTF50 an edge measured in a raw image will have after resampling with `kind`, its normal at
/// `normal_angle_rad` to the resampled image's x axis. NaN when the product does not fall to 0.5
/// below 1 cycle/px.
double PredictResampledMtf50(const SlantedEdgeResult& raw,
                             Interpolation kind,
                             double normal_angle_rad);

/// |mean_k H_dx_k(f nx) H_dy_k(f ny)|: bilinear interpolation's transfer at f (cycles/px along the
/// unit normal `normal` = (nx, ny) in the virtual image) over the sub-pixel shifts (dx, dy) in
/// [0, 1) of the virtual pixels measured. Requires at least one shift.
double BilinearTransferAtShifts(const std::vector<Eigen::Vector2d>& shifts,
                                const Eigen::Vector2d& normal,
                                double f_cy_px);

/// The MTF50 of a raw edge after bilinear resampling at the given shifts: the first f (cycles per
/// virtual px) where EdgeMtfAt(raw, f / s) BilinearTransferAtShifts(shifts, normal, f) falls to
/// 0.5, s = `raw_per_virtual_px` the mapping's scale along the normal (a period of P virtual px is
/// P s raw px, f / s cycles per raw px; 1 for a translation); NaN when it does not fall so far
/// below 1 cycle/px.
double PredictResampledMtf50AtShifts(const SlantedEdgeResult& raw,
                                     const std::vector<Eigen::Vector2d>& shifts,
                                     const Eigen::Vector2d& normal,
                                     double raw_per_virtual_px = 1.0);

}  // namespace aerocal::stitch
