// A straight edge blurred by a Gaussian PSF of sigma s px and integrated over each pixel's area in
// closed form, so that a rendering adds no error to what a measurement of it is compared with
// (the simulated resolution targets: tests/support/rendered_targets.h and the flight's edge
// targets, triangulation/simulation/flight_edge_targets.h). With Phi the standard normal CDF and
// phi its density, F1(u) = u Phi(u) + phi(u) and F2(u) = ((u^2 + 1) Phi(u) + u phi(u)) / 2 are its
// first and second antiderivatives; the area integral of Phi((n . p - o) / s) over the pixel
// square is s^2 / (nx ny) times the second difference of F2 over the square's corners.
//
// The rendered image's MTF along the edge normal n = (cos t, sin t) is that of the PSF times the
// pixel square's projection onto n: exp(-2 pi^2 s^2 f^2) sinc(f cos t) sinc(f sin t).
#pragma once

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {

inline constexpr double kRenderPi = 3.14159265358979323846;

inline double NormalCdf(double u) { return 0.5 * std::erfc(-u / std::sqrt(2.0)); }
inline double NormalPdf(double u) { return std::exp(-0.5 * u * u) / std::sqrt(2.0 * kRenderPi); }
inline double NormalCdfIntegral(double u) { return u * NormalCdf(u) + NormalPdf(u); }  // F1
inline double NormalCdfIntegral2(double u) {                                           // F2
  return 0.5 * ((u * u + 1.0) * NormalCdf(u) + u * NormalPdf(u));
}

/// Fraction (0..1) of the bright side in pixel (col, row) for the blurred edge n . p = offset,
/// n = (cos t, sin t) the unit normal pointing to the bright side, p = (col, row) px.
inline double EdgePixelFraction(
    double col, double row, double angle_rad, double offset_px, double s_px) {
  const double nx = std::cos(angle_rad), ny = std::sin(angle_rad);
  auto u = [&](double x, double y) { return (nx * x + ny * y - offset_px) / s_px; };
  const double x0 = col - 0.5, x1 = col + 0.5, y0 = row - 0.5, y1 = row + 0.5;
  const double corners[4] = {u(x0, y0), u(x1, y0), u(x0, y1), u(x1, y1)};
  if (*std::min_element(corners, corners + 4) > 9.0) return 1.0;
  if (*std::max_element(corners, corners + 4) < -9.0) return 0.0;
  if (std::abs(ny) < 1e-9)  // an axis-aligned edge: one antiderivative, along x
    return s_px / nx * (NormalCdfIntegral(u(x1, 0.0)) - NormalCdfIntegral(u(x0, 0.0)));
  if (std::abs(nx) < 1e-9)
    return s_px / ny * (NormalCdfIntegral(u(0.0, y1)) - NormalCdfIntegral(u(0.0, y0)));
  return s_px * s_px / (nx * ny) *
         (NormalCdfIntegral2(corners[3]) - NormalCdfIntegral2(corners[2]) -
          NormalCdfIntegral2(corners[1]) + NormalCdfIntegral2(corners[0]));
}

}  // namespace aerocal::stitch
