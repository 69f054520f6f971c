// Siemens stars rendered through a Gaussian PSF of sigma s (4 x 4 supersampled: the binary star at
// the sub-pixels' centres, blurred by s, averaged over each pixel), with 1 DN noise rounded to 8
// bit: the limiting frequency at 10 % modulation transfer lies within one step of the radii
// (2^(1/12)) of the analytic one, where exp(-2 pi^2 s^2 f^2) times the pixel's box averaged over
// the tangential directions round the circle, mean_t sinc(f cos t) sinc(f sin t), falls to 0.1.
#include "stitch/quality/siemens_star.h"

#include "calib/core/error.h"
#include "tests/support/rendered_targets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace aerocal::stitch {
namespace {

constexpr int kSize = 420, kCycles = 24;
constexpr double kOuter = 200.0, kDark = 30.0, kBright = 220.0;
constexpr double kPi = 3.14159265358979323846;

// The star centred at `centre` (px), phase `phase` (rad), blurred by s px, 1 DN noise, 8 bit.
GrayImage RenderStar(const Eigen::Vector2d& centre, double phase, double s, std::mt19937_64* rng) {
  GrayImage image = testing::RenderSiemensStar(kSize, kCycles, centre, phase, s, kDark, kBright);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c)
      image(r, c) =
          static_cast<float>(std::clamp(std::round(image(r, c) + noise(*rng)), 0.0, 255.0));
  return image;
}

double AnalyticTransfer(double f, double s) { return testing::RenderedStarTransfer(f, s); }

TEST(SiemensStar, LimitingFrequencyWithinOneStepOfTheAnalyticOne) {
  std::mt19937_64 rng(3620);
  std::uniform_real_distribution<double> offset(-0.5, 0.5), phase(0.0, 2 * kPi);
  for (double s : {0.8, 1.0, 1.5, 2.0}) {
    const Eigen::Vector2d centre(209.5 + offset(rng), 209.5 + offset(rng));
    const GrayImage image = RenderStar(centre, phase(rng), s, &rng);
    SiemensStar star;
    star.centre_px = centre;
    star.cycles = kCycles;
    star.outer_radius_px = kOuter;
    const SiemensStarResult r = MeasureSiemensStar(image, star);
    const double truth =
        testing::FirstCrossing([&](double f) { return AnalyticTransfer(f, s); }, 0.1);
    const double steps = std::log(r.limiting_frequency_cy_px / truth) / std::log(r.step_ratio);
    std::printf(
        "s %.1f px: limit %.4f cycles/px, analytic %.4f (%+.2f steps), M0 %.4f, %zu rings\n",
        s,
        r.limiting_frequency_cy_px,
        truth,
        steps,
        r.reference_modulation,
        r.rings.size());
    EXPECT_TRUE(r.limit_in_range);
    EXPECT_LE(std::abs(steps), 1.0) << "s " << s;
    EXPECT_NEAR(r.reference_modulation, (kBright - kDark) / (kBright + kDark), 0.01);
    // The outermost ring passes the star unchanged: transfer 1 within the noise.
    EXPECT_NEAR(r.rings.front().contrast_transfer,
                AnalyticTransfer(r.rings.front().frequency_cy_px, s),
                0.02);
  }
}

TEST(SiemensStar, ASharpStarIsResolvedToTheInnerRadius) {
  std::mt19937_64 rng(3621);
  const Eigen::Vector2d centre(210.2, 209.7);
  const GrayImage image = RenderStar(centre, 0.3, 0.3, &rng);
  SiemensStar star{centre, kCycles, kOuter, 20.0};
  const SiemensStarResult r = MeasureSiemensStar(image, star);
  EXPECT_FALSE(r.limit_in_range);
  EXPECT_NEAR(r.rings.back().radius_px, 20.0, 20.0 * (r.step_ratio - 1));
}

TEST(SiemensStar, RefusesAStarOutsideTheImageOrWithTooNarrowSectors) {
  std::mt19937_64 rng(3622);
  const GrayImage image = RenderStar({209.5, 209.5}, 0.0, 1.0, &rng);
  EXPECT_THROW(MeasureSiemensStar(image, {{209.5, 209.5}, kCycles, 215.0, 0.0}), InputError);
  EXPECT_THROW(MeasureSiemensStar(image, {{209.5, 209.5}, kCycles, 60.0, 0.0}),
               InputError);  // 7.9 px/sector
  EXPECT_THROW(MeasureSiemensStar(image, {{209.5, 209.5}, 2, 150.0, 0.0}), InputError);
  GrayImage flat = GrayImage::Constant(kSize, kSize, 100.0f);
  EXPECT_THROW(MeasureSiemensStar(flat, {{209.5, 209.5}, kCycles, kOuter, 0.0}), InputError);
}

}  // namespace
}  // namespace aerocal::stitch
