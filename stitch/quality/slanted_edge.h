// Slanted-edge MTF (ISO 12233:2017 e-SFR) of one edge region of a grey-value image, with a GUM
// uncertainty budget of its MTF50.
//
// Steps (ISO 12233:2017 clause 6.3 / annex D, as in Burns' sfrmat):
//  1. linearise the digital numbers (OECF; here a power law DN^gamma, gamma = 1 for linear data);
//  2. orient the region so that the edge runs along the rows (a near-horizontal edge is transposed:
//     its MTF is the one along the image's y axis);
//  3. per row, the centroid of the [-1/2, 0, 1/2] derivative, first plain, then within a Hamming
//     window centred on the first line fit; a least-squares line col = a + b (row - mean row);
//  4. every pixel projected onto the edge normal (perpendicular distance to the fitted line) and
//     averaged into bins of 1/oversampling px (4x: 1/4 px) -> the oversampled edge spread
//     function (ESF); empty bins are interpolated from their neighbours;
//  5. the line spread function (LSF) by the centred difference of the ESF, multiplied by a Hamming
//     window centred on the edge;
//  6. MTF(f) = |DTFT(LSF)(f)| / |DTFT(LSF)(0)|, f in cycles per pixel along the edge normal,
//  divided
//     by the transfer functions of the centred difference, sinc(2 f D), and of the bin average,
//     sinc(f D) (D the bin width in px; ISO 12233 corrects the derivative, the bin average is the
//     same kind of correction). The DTFT is evaluated at any frequency, so MTF50 is found by
//     bisection rather than by interpolation in an FFT grid.
// The result is the system MTF of the image along the edge normal, the pixel aperture included
// (a perfect optics gives sinc(f cos t) sinc(f sin t) for an edge at t to a pixel axis).
//
// Uncertainty of MTF50 (GUM, JCGM 100:2008): type B components from the image noise (Monte-Carlo
// of the ESF bins with the noise measured on the flat sides, GUM Supplement 1), the edge angle
// (the line fit's slope +- its sigma), the oversampling (the bins shifted by half a bin) and the
// method (a rectangular half-width from the validation on rendered edges,
// stitch/quality/README.md); type A from repeated edges in CombineEdgeMeasurements. U = k u_c with
// k = 2.
//
// Frames: pixel (col, row) of CONVENTIONS.md; frequencies in cycles per pixel (Nyquist 0.5).
#pragma once

#include "stitch/image_io/gray_image.h"

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace aerocal::stitch {

/// A rectangle of pixels: the top-left pixel (col, row) and its size, in px.
struct PixelRegion {
  int col = 0, row = 0, width = 0, height = 0;
};

/// The image axis along which an edge's MTF is measured (the edge normal's nearer axis).
enum class MtfAxis { kX, kY };
std::string_view MtfAxisName(MtfAxis axis);  // "x" | "y"

struct SlantedEdgeOptions {
  double gamma = 1.0;      // linearisation: value = DN^gamma (> 0; 1: linear data, 2.2: sRGB-like)
  int oversampling = 4;    // ESF bins per pixel, 2..16 (ISO 12233: 4)
  int noise_samples = 64;  // Monte-Carlo repeats for the noise component, >= 8
  double min_angle_deg =
      1.0;  // edges closer than this to a pixel axis are refused (phase sampling)
  double max_angle_deg = 35.0;  // and farther than this
  // Relative half-width (of MTF50) of the method's remaining systematic error, rectangular; from
  // the validation on rendered edges (README "Measured"): a type-B component, >= 0.
  double method_relative_half_width = 0.01;
  void Validate() const;  // throws ConfigError naming the field
};

/// One component of an uncertainty budget: its name, GUM type ("A" or "B"), distribution and the
/// standard uncertainty it contributes to the measurand (same unit as the measurand).
struct UncertaintyComponent {
  std::string name, type, distribution;
  double u = 0.0;
};

struct SlantedEdgeResult {
  MtfAxis axis = MtfAxis::kX;   // image axis of the edge normal
  double angle_deg = 0.0;       // edge slant to the nearer pixel axis, signed (col per row)
  double edge_offset_px = 0.0;  // edge position across the region, px from its first col/row
  double slope_sigma = 0.0;     // sigma of the fitted slope (col per row)
  double contrast = 0.0;        // ESF step (linearised units), > 0
  double noise_sigma = 0.0;     // pixel noise on the flat sides (linearised units)
  int empty_bins = 0;           // ESF bins interpolated because no pixel fell into them
  std::vector<double> frequency_cy_px;       // 0 .. 1 cycles/px in steps of 1/64
  std::vector<double> mtf;                   // MTF at those frequencies (1 at 0)
  std::vector<double> esf_distance_px, esf;  // the oversampled ESF (bin centres, values)
  double mtf50_cy_px = 0.0;  // first frequency where the MTF falls to 0.5; NaN if not <= 1
  double mtf10_cy_px = 0.0;  // the same at 0.1
  double mtf_nyquist = 0.0;  // MTF at 0.5 cycles/px
  std::vector<UncertaintyComponent> budget;  // components of MTF50's uncertainty (cy/px)
  double mtf50_u_cy_px = 0.0;                // combined standard uncertainty u_c
  double mtf50_expanded_cy_px = 0.0;         // U = k u_c
  double coverage_factor = 2.0;              // k
};

/// Measures the slanted edge inside `region` of `image` (grey values as read, any bit depth).
/// Throws InputError("region (col, row, w, h): ...") when the region leaves the image, is smaller
/// than 16 x 16 px, holds no edge (step below 10 noise sigmas), or the edge's angle is outside
/// [min_angle_deg, max_angle_deg].
SlantedEdgeResult MeasureSlantedEdge(const GrayImage& image,
                                     const PixelRegion& region,
                                     const SlantedEdgeOptions& options = {});

/// MTF of a measured edge at any frequency (cycles/px along its normal), from its ESF: the same
/// LSF, window and corrections as its curve.
double EdgeMtfAt(const SlantedEdgeResult& edge, double f_cy_px);

/// First frequency in (0, 1] cycles/px where `mtf` falls to `level`: a scan in steps of 1/256, then
/// bisection to 1e-7 cycles/px. NaN when it does not fall so far.
double FirstCrossingFrequency(const std::function<double(double)>& mtf, double level);

/// The MTF50 of repeated edges combined.
struct EdgeMtfCombination {
  int count = 0;
  double mtf50_cy_px = 0.0;     // mean of the repeats
  double type_a_u_cy_px = 0.0;  // s / sqrt(n)
  double type_b_u_cy_px = 0.0;  // systematic part (method, oversampling), from the repeats' budgets
  double mtf50_u_cy_px = 0.0;   // sqrt(u_A^2 + u_B^2)
  double mtf50_expanded_cy_px = 0.0;  // k = 2
};

/// Mean MTF50 of repeated measurements of the same resolution (several targets or frames): type A
/// from their scatter (s / sqrt(n), n >= 2), type B the components that do not average out (the
/// method's and the oversampling's, root-mean-square over the repeats). Requires n >= 2.
EdgeMtfCombination CombineEdgeMeasurements(const std::vector<SlantedEdgeResult>& results);

/// A resolution in the units of the report: cycles/px -> line pairs per mm in the focal plane
/// (pixel size in mm) and the ground resolved distance, the width of one bar (half a cycle):
/// GRD = GSD / (2 f). u from u(f) and u(GSD) (uncorrelated, first order).
struct GroundResolution {
  double lp_per_mm = 0.0, lp_per_mm_u = 0.0;                      // 0 when no pixel size is given
  double resolved_distance_m = 0.0, resolved_distance_u_m = 0.0;  // 0 when no GSD is given
};
GroundResolution ToGroundResolution(
    double f_cy_px, double u_f_cy_px, double pixel_size_mm, double gsd_m, double u_gsd_m);

}  // namespace aerocal::stitch
