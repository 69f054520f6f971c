#include "stitch/quality/resampling_mtf.h"

#include "calib/core/error.h"

#include <cmath>
#include <complex>

namespace aerocal::stitch {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Sinc(double x) { return std::abs(x) < 1e-12 ? 1.0 : std::sin(kPi * x) / (kPi * x); }

// Keys' cubic convolution kernel with a = -0.5 (the resampler's bicubic, virtual_image.h).
double KeysKernel(double x) {
  constexpr double a = -0.5;
  x = std::abs(x);
  if (x <= 1.0) return (a + 2.0) * x * x * x - (a + 3.0) * x * x + 1.0;
  if (x < 2.0) return a * x * x * x - 5.0 * a * x * x + 8.0 * a * x - 4.0 * a;
  return 0.0;
}

// 2 * integral over [0, 2] of k(x) cos(2 pi f x) (the kernel is even), Simpson's rule on 2000
// intervals: exact to ~1e-12 for a piecewise cubic times a cosine of at most 2 cycles per px.
double KeysTransfer(double f) {
  constexpr int kIntervals = 2000;
  const double h = 2.0 / kIntervals;
  double sum = 0.0;
  for (int i = 0; i <= kIntervals; ++i) {
    const double x = i * h;
    const double w = (i == 0 || i == kIntervals) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    sum += w * KeysKernel(x) * std::cos(2.0 * kPi * f * x);
  }
  return 2.0 * sum * h / 3.0;
}

// Bilinear interpolation's transfer along one axis at shift d, referred to the output pixel.
std::complex<double> BilinearShiftTransfer(double d, double f) {
  const double w = 2.0 * kPi * f;
  return (1.0 - d) * std::polar(1.0, -w * d) + d * std::polar(1.0, w * (1.0 - d));
}

}  // namespace

double InterpolationTransfer(Interpolation kind, double f_cy_px) {
  AEROCAL_CHECK(f_cy_px >= 0.0) << "frequency must be >= 0, got " << f_cy_px;
  if (kind == Interpolation::kBilinear) return Sinc(f_cy_px) * Sinc(f_cy_px);
  return KeysTransfer(f_cy_px);
}

double PredictResampledMtf50(const SlantedEdgeResult& raw,
                             Interpolation kind,
                             double normal_angle_rad) {
  const double cx = std::abs(std::cos(normal_angle_rad)), cy = std::abs(std::sin(normal_angle_rad));
  return FirstCrossingFrequency(
      [&](double f) {
        return EdgeMtfAt(raw, f) * InterpolationTransfer(kind, f * cx) *
               InterpolationTransfer(kind, f * cy);
      },
      0.5);
}

double BilinearTransferAtShifts(const std::vector<Eigen::Vector2d>& shifts,
                                const Eigen::Vector2d& normal,
                                double f_cy_px) {
  AEROCAL_CHECK(!shifts.empty()) << "no shifts";
  std::complex<double> sum = 0.0;
  for (const Eigen::Vector2d& d : shifts)
    sum += BilinearShiftTransfer(d.x(), f_cy_px * normal.x()) *
           BilinearShiftTransfer(d.y(), f_cy_px * normal.y());
  return std::abs(sum) / static_cast<double>(shifts.size());
}

double PredictResampledMtf50AtShifts(const SlantedEdgeResult& raw,
                                     const std::vector<Eigen::Vector2d>& shifts,
                                     const Eigen::Vector2d& normal,
                                     double raw_per_virtual_px) {
  AEROCAL_CHECK(raw_per_virtual_px > 0.0) << "scale must be > 0, got " << raw_per_virtual_px;
  return FirstCrossingFrequency(
      [&](double f) {
        return EdgeMtfAt(raw, f / raw_per_virtual_px) * BilinearTransferAtShifts(shifts, normal, f);
      },
      0.5);
}

}  // namespace aerocal::stitch
