// Resolution targets rendered exactly: a straight edge (stitch/simulation/rendered_edge.h: a
// Gaussian PSF of sigma s px integrated over each pixel's area in closed form) or a bar pattern
// through the same blur, so the rendering adds no error to what a measurement of it is compared
// with.
//
// The rendered image's MTF along the edge normal n = (cos t, sin t) is that of the PSF times the
// pixel square's projection onto n: exp(-2 pi^2 s^2 f^2) sinc(f cos t) sinc(f sin t).
#pragma once

#include "stitch/simulation/rendered_edge.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace aerocal::testing {

using RenderedImage = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

using stitch::EdgePixelFraction;
using stitch::kRenderPi;
using stitch::NormalCdf;
using stitch::NormalCdfIntegral;
using stitch::NormalCdfIntegral2;
using stitch::NormalPdf;

inline double Sinc(double x) {
  return std::abs(x) < 1e-12 ? 1.0 : std::sin(kRenderPi * x) / (kRenderPi * x);
}

/// A width x height image of an edge through the image centre shifted by `offset_px`, its normal
/// at `angle_rad` from +x, dark `low` and bright `high` (floating point, no noise).
inline RenderedImage RenderEdge(int width,
                                int height,
                                double angle_rad,
                                double s_px,
                                double low,
                                double high,
                                double offset_px = 0.0) {
  RenderedImage image(height, width);
  const double nx = std::cos(angle_rad), ny = std::sin(angle_rad);
  const double centre = nx * 0.5 * (width - 1) + ny * 0.5 * (height - 1) + offset_px;
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c)
      image(r, c) =
          static_cast<float>(low + (high - low) * EdgePixelFraction(c, r, angle_rad, centre, s_px));
  return image;
}

/// Vertical bars (grey value a function of the column): bright on [x0 + k P, x0 + k P + P/2) for
/// every integer k, period P px, blurred by s and integrated over each pixel's column extent.
inline double BarPixelFraction(double col, double period_px, double x0_px, double s_px) {
  double fraction = 0.0;
  const int k_first =
      static_cast<int>(std::floor((col - 0.5 - 10.0 * s_px - x0_px) / period_px)) - 1;
  const int k_last = static_cast<int>(std::ceil((col + 0.5 + 10.0 * s_px - x0_px) / period_px)) + 1;
  for (int k = k_first; k <= k_last; ++k) {
    const double a = x0_px + k * period_px, b = a + 0.5 * period_px;  // one bright bar [a, b)
    auto bar = [&](double x) {  // integral of Phi((x - a)/s) - Phi((x - b)/s) dx
      return s_px * (NormalCdfIntegral((x - a) / s_px) - NormalCdfIntegral((x - b) / s_px));
    };
    fraction += bar(col + 0.5) - bar(col - 0.5);
  }
  return fraction;
}

/// MTF of the rendered edge along its normal: PSF times the projected pixel square.
inline double RenderedEdgeMtf(double f, double s_px, double angle_rad) {
  return std::exp(-2.0 * kRenderPi * kRenderPi * s_px * s_px * f * f) *
         Sinc(f * std::cos(angle_rad)) * Sinc(f * std::sin(angle_rad));
}

/// Coltman's square-wave response of vertical bars of frequency f (cycles/px) through the PSF and
/// the pixel's column extent: (4/pi) sum over odd k of (-1)^((k-1)/2) M(k f) / k.
inline double RenderedBarContrast(double f, double s_px) {
  double sum = 0.0;
  for (int k = 1; k < 200; k += 2)
    sum += ((k / 2) % 2 == 0 ? 1.0 : -1.0) * RenderedEdgeMtf(k * f, s_px, 0.0) / k;
  return 4.0 / kRenderPi * sum;
}

/// First f in (0, 1] where `curve(f)` falls to `level` (scan then bisection); NaN if none.
template <typename Curve>
double FirstCrossing(const Curve& curve, double level) {
  double f0 = 0.0;
  for (double f1 = 1.0 / 512; f1 <= 1.0; f1 += 1.0 / 512) {
    if (curve(f1) <= level) {
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (f0 + f1);
        (curve(mid) > level ? f0 : f1) = mid;
      }
      return 0.5 * (f0 + f1);
    }
    f0 = f1;
  }
  return std::nan("");
}

/// One pass of a Gaussian of sigma `s` (samples) over an n x n row-major array, along rows
/// (`along_rows`) or columns, the border value repeated.
inline void GaussianPass(std::vector<float>* image, int n, double s, bool along_rows) {
  const int radius = static_cast<int>(std::ceil(4 * s));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k)
    sum += kernel[k + radius] = std::exp(-0.5 * k * k / (s * s));
  for (double& k : kernel) k /= sum;
  std::vector<float> out(image->size());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double v = 0;
      for (int k = -radius; k <= radius; ++k) {
        const int jj = std::clamp(j + k, 0, n - 1);
        v += kernel[k + radius] * (*image)[along_rows ? i * n + jj : jj * n + i];
      }
      out[along_rows ? i * n + j : j * n + i] = static_cast<float>(v);
    }
  *image = std::move(out);
}

/// A size x size Siemens star of `cycles` bright / dark sector pairs (bright where
/// cos(cycles theta + phase) >= 0) centred at `centre` (px), blurred by a Gaussian of s px: the
/// binary star at the centres of 4 x 4 sub-pixels, blurred there, averaged over each pixel (no
/// noise). Its modulation transfer is RenderedStarTransfer.
inline RenderedImage RenderSiemensStar(int size,
                                       int cycles,
                                       const Eigen::Vector2d& centre,
                                       double phase,
                                       double s_px,
                                       double low,
                                       double high) {
  constexpr int kSuper = 4;
  const int n = size * kSuper;
  std::vector<float> fine(static_cast<size_t>(n) * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = (j + 0.5) / kSuper - 0.5 - centre.x(),
                   y = (i + 0.5) / kSuper - 0.5 - centre.y();
      fine[static_cast<size_t>(i) * n + j] =
          static_cast<float>(std::cos(cycles * std::atan2(y, x) + phase) >= 0 ? high : low);
    }
  GaussianPass(&fine, n, s_px * kSuper, true);
  GaussianPass(&fine, n, s_px * kSuper, false);
  RenderedImage image(size, size);
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c) {
      double sum = 0;
      for (int a = 0; a < kSuper; ++a)
        for (int b = 0; b < kSuper; ++b)
          sum += fine[static_cast<size_t>(r * kSuper + a) * n + c * kSuper + b];
      image(r, c) = static_cast<float>(sum / (kSuper * kSuper));
    }
  return image;
}

/// The rendered star's modulation transfer at f (cycles/px): the PSF times the pixel's box
/// averaged over the tangential directions round the circle, mean_t sinc(f cos t) sinc(f sin t).
inline double RenderedStarTransfer(double f, double s_px) {
  constexpr int kAngles = 360;
  double box = 0;
  for (int k = 0; k < kAngles; ++k) {
    const double t = 2 * kRenderPi * (k + 0.5) / kAngles;
    box += Sinc(f * std::cos(t)) * Sinc(f * std::sin(t)) / kAngles;
  }
  return std::exp(-2.0 * kRenderPi * kRenderPi * s_px * s_px * f * f) * box;
}

}  // namespace aerocal::testing
