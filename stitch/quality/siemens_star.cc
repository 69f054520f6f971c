#include "stitch/quality/siemens_star.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "stitch/quality/limiting_frequency.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <string>

namespace aerocal::stitch {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Linear(float dn, double gamma) {
  const double v = std::max(0.0, static_cast<double>(dn));
  return gamma == 1.0 ? v : std::pow(v, gamma);
}

// The ring of pixels whose centres lie within half a pixel of radius r: the least-squares fit
// v = m + a cos(n theta) + b sin(n theta), and (with `bright_dark`) the means of the middle thirds
// of the bright and dark sectors of a fitted phase.
struct RingFit {
  double m = 0, a = 0, b = 0;
  int pixels = 0;
};

template <typename Visit>
void ForRingPixels(
    const GrayImage& image, const SiemensStar& star, double r, double gamma, Visit&& visit) {
  const double cx = star.centre_px.x(), cy = star.centre_px.y();
  const int row0 = std::max(0, static_cast<int>(std::floor(cy - r - 1))),
            row1 = std::min<int>(image.rows() - 1, static_cast<int>(std::ceil(cy + r + 1)));
  const int col0 = std::max(0, static_cast<int>(std::floor(cx - r - 1))),
            col1 = std::min<int>(image.cols() - 1, static_cast<int>(std::ceil(cx + r + 1)));
  for (int row = row0; row <= row1; ++row)
    for (int col = col0; col <= col1; ++col) {
      const double dx = col - cx, dy = row - cy;
      if (std::abs(std::hypot(dx, dy) - r) > 0.5) continue;
      visit(star.cycles * std::atan2(dy, dx), Linear(image(row, col), gamma));
    }
}

RingFit FitRing(const GrayImage& image, const SiemensStar& star, double r, double gamma) {
  Eigen::Matrix3d n = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  RingFit fit;
  ForRingPixels(image, star, r, gamma, [&](double phase, double v) {
    const Eigen::Vector3d row(1.0, std::cos(phase), std::sin(phase));
    n += row * row.transpose();
    rhs += row * v;
    ++fit.pixels;
  });
  const Eigen::Vector3d x = n.ldlt().solve(rhs);
  fit.m = x[0];
  fit.a = x[1];
  fit.b = x[2];
  return fit;
}

// (B - D) / (B + D) from the middle thirds of the sectors of the outer ring.
double ReferenceModulation(const GrayImage& image,
                           const SiemensStar& star,
                           const RingFit& outer,
                           double gamma) {
  const double phase0 = std::atan2(outer.b, outer.a);  // v ~ m + A cos(n theta - phase0)
  double bright = 0, dark = 0;
  int n_bright = 0, n_dark = 0;
  ForRingPixels(image, star, star.outer_radius_px, gamma, [&](double phase, double v) {
    const double psi = std::remainder(phase - phase0, 2.0 * kPi);  // (-pi, pi]
    if (std::abs(psi) <= kPi / 3) {
      bright += v;
      ++n_bright;
    } else if (std::abs(psi) >= 2 * kPi / 3) {
      dark += v;
      ++n_dark;
    }
  });
  if (n_bright == 0 || n_dark == 0) return 0.0;
  bright /= n_bright;
  dark /= n_dark;
  return bright + dark > 0 ? (bright - dark) / (bright + dark) : 0.0;
}

std::string StarText(const SiemensStar& s) {
  return StringPrintf("Siemens star at (%.1f, %.1f)", s.centre_px.x(), s.centre_px.y());
}

}  // namespace

void SiemensStarOptions::Validate() const {
  if (!(gamma > 0.0 && gamma <= 10.0))
    throw ConfigError("gamma must be within (0, 10] (got " + std::to_string(gamma) + ")");
  if (!(threshold > 0.0 && threshold < 1.0))
    throw ConfigError("threshold must be within (0, 1) (got " + std::to_string(threshold) + ")");
  if (steps_per_octave < 2 || steps_per_octave > 96)
    throw ConfigError("steps_per_octave must be within [2, 96] (got " +
                      std::to_string(steps_per_octave) + ")");
}

SiemensStarResult MeasureSiemensStar(const GrayImage& image,
                                     const SiemensStar& star,
                                     const SiemensStarOptions& options) {
  options.Validate();
  const std::string what = StarText(star);
  const double r_out = star.outer_radius_px, cx = star.centre_px.x(), cy = star.centre_px.y();
  if (star.cycles < 4)
    throw InputError(what + ": cycles must be >= 4 (got " + std::to_string(star.cycles) + ")");
  if (!(r_out > 0) || !(cx - r_out - 1 >= 0 && cy - r_out - 1 >= 0 &&
                        cx + r_out + 1 <= image.cols() - 1 && cy + r_out + 1 <= image.rows() - 1))
    throw InputError(what +
                     StringPrintf(": the outer radius %.1f px must lie inside the image", r_out));
  if (kPi * r_out / star.cycles < kMinSectorPx)
    throw InputError(
        what +
        StringPrintf(": %.1f px per sector on the outer radius (pi r / cycles); the reference "
                     "modulation needs %.0f px or more",
                     kPi * r_out / star.cycles,
                     kMinSectorPx));
  if (!(star.inner_radius_px >= 0 && star.inner_radius_px < r_out))
    throw InputError(what + ": the inner radius must be within [0, outer radius)");

  SiemensStarResult result;
  const RingFit outer = FitRing(image, star, r_out, options.gamma);
  result.reference_modulation = ReferenceModulation(image, star, outer, options.gamma);
  if (!(result.reference_modulation > 0))
    throw InputError(what + ": no contrast between the bright and dark sectors of the outer ring");
  result.step_ratio = std::pow(2.0, 1.0 / options.steps_per_octave);
  const double r_min = std::max({2.0, star.inner_radius_px, star.cycles / (2 * kPi * 0.5)});
  const double f_outer = star.cycles / (2 * kPi * r_out);
  for (int k = 0;; ++k) {
    const double f = f_outer * std::pow(result.step_ratio, k), r = star.cycles / (2 * kPi * f);
    if (r < r_min * (1 - 1e-12)) break;
    const RingFit fit = k == 0 ? outer : FitRing(image, star, r, options.gamma);
    StarRing ring;
    ring.radius_px = r;
    ring.frequency_cy_px = f;
    ring.pixels = fit.pixels;
    ring.modulation = fit.m > 0 ? std::hypot(fit.a, fit.b) / fit.m : 0.0;
    ring.contrast_transfer = ring.modulation / (4.0 / kPi * result.reference_modulation);
    result.rings.push_back(ring);
  }
  const LimitingFrequency limit = FindLimitingFrequencyOf(result.rings, options.threshold);
  result.limiting_frequency_cy_px = limit.frequency_cy_px;
  result.limit_in_range = limit.in_range;
  return result;
}

}  // namespace aerocal::stitch
