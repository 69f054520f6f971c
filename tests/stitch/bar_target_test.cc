// Bar targets rendered exactly (tests/support/rendered_targets.h) at frequencies one USAF step
// (2^(1/6)) apart through a Gaussian PSF: the limiting frequency at 10 % contrast transfer lies
// within one step of the analytic one, Coltman's square-wave response of the PSF times the
// pixel's width (sinc), solved for 0.1.
#include "stitch/quality/bar_target.h"

#include "calib/core/error.h"
#include "tests/support/rendered_targets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace aerocal::stitch {
namespace {

const double kStep = std::pow(2.0, 1.0 / 6.0);  // one USAF 1951 element
constexpr int kWidth = 160, kBlockRows = 24;
constexpr double kDark = 30.0, kBright = 220.0;

struct RenderedTarget {
  GrayImage image;
  std::vector<BarGroup> groups;
  PixelRegion bright, dark;
};

// One block of rows per group (vertical bars across the width; or, transposed, horizontal bars),
// then a bright and a dark block; bar phase random, noise of `noise_dn` DN rounded to 8 bit.
RenderedTarget RenderTarget(double s,
                            const std::vector<double>& frequencies,
                            bool transpose,
                            double noise_dn,
                            std::mt19937_64* rng) {
  const int blocks = static_cast<int>(frequencies.size()) + 2;
  GrayImage image(blocks * kBlockRows, kWidth);
  RenderedTarget target;
  std::uniform_real_distribution<double> phase(0.0, 10.0);
  for (size_t g = 0; g < frequencies.size(); ++g) {
    const double x0 = phase(*rng);
    for (int c = 0; c < kWidth; ++c) {
      const double v =
          kDark + (kBright - kDark) * testing::BarPixelFraction(c, 1.0 / frequencies[g], x0, s);
      for (int r = 0; r < kBlockRows; ++r) image(g * kBlockRows + r, c) = static_cast<float>(v);
    }
    target.groups.push_back({frequencies[g],
                             {4, static_cast<int>(g) * kBlockRows + 2, kWidth - 8, kBlockRows - 4},
                             MtfAxis::kX});
  }
  const int bright_row = frequencies.size() * kBlockRows, dark_row = bright_row + kBlockRows;
  image.block(bright_row, 0, kBlockRows, kWidth).setConstant(kBright);
  image.block(dark_row, 0, kBlockRows, kWidth).setConstant(kDark);
  target.bright = {4, bright_row + 2, kWidth - 8, kBlockRows - 4};
  target.dark = {4, dark_row + 2, kWidth - 8, kBlockRows - 4};
  if (noise_dn > 0.0) {
    std::normal_distribution<double> normal(0.0, noise_dn);
    for (int i = 0; i < image.size(); ++i)
      image.data()[i] =
          static_cast<float>(std::clamp(std::round(image.data()[i] + normal(*rng)), 0.0, 255.0));
  }
  if (transpose) {
    image = GrayImage(image.transpose());
    for (auto& g : target.groups)
      g.region = {g.region.row, g.region.col, g.region.height, g.region.width},
      g.axis = MtfAxis::kY;
    for (PixelRegion* r : {&target.bright, &target.dark})
      *r = {r->row, r->col, r->height, r->width};
  }
  target.image = std::move(image);
  return target;
}

std::vector<double> UsafFrequencies() {  // 0.08 .. 0.5 cycles/px in steps of 2^(1/6)
  std::vector<double> f;
  for (double v = 0.08; v <= 0.5; v *= kStep) f.push_back(v);
  return f;
}

TEST(BarTarget, LimitingFrequencyAtTenPercentWithinOneStepOfTheAnalyticValue) {
  std::mt19937_64 rng(361);
  int index = 0;
  for (double noise : {0.0, 1.0})
    for (double s : {0.75, 1.0, 1.25, 1.5, 2.0, 2.5}) {
      const RenderedTarget t = RenderTarget(s, UsafFrequencies(), index++ % 2 == 1, noise, &rng);
      const BarTargetResult r = MeasureBarTarget(t.image, t.groups, t.bright, t.dark);
      const double truth =
          testing::FirstCrossing([&](double f) { return testing::RenderedBarContrast(f, s); }, 0.1);
      const double steps = std::log(r.limiting_frequency_cy_px / truth) / std::log(kStep);
      std::printf("noise %.0f DN s %.2f: limiting frequency %.4f, analytic %.4f (%+.2f steps)\n",
                  noise,
                  s,
                  r.limiting_frequency_cy_px,
                  truth,
                  steps);
      EXPECT_TRUE(r.limit_in_range) << "s " << s;
      EXPECT_LE(std::abs(steps), 1.0) << "noise " << noise << " s " << s;
      // The reference modulation (220 - 30) / (220 + 30) within the 8-bit rounding.
      EXPECT_NEAR(r.reference_modulation, 190.0 / 250.0, 0.005);
      // At low frequency the contrast transfer is Coltman's response within 0.03.
      EXPECT_NEAR(r.groups.front().contrast_transfer,
                  testing::RenderedBarContrast(r.groups.front().frequency_cy_px, s),
                  0.03)
          << "s " << s;
    }
}

TEST(BarTarget, RefusesBadGroupsAndReferences) {
  std::mt19937_64 rng(5);
  const RenderedTarget t = RenderTarget(1.0, {0.1, 0.2}, false, 0.0, &rng);
  EXPECT_THROW(MeasureBarTarget(t.image, t.groups, t.dark, t.bright),
               InputError);  // swapped references
  auto groups = t.groups;
  groups[0].region.width = 12;  // one period of 10 px only
  EXPECT_THROW(MeasureBarTarget(t.image, groups, t.bright, t.dark), InputError);
  groups = t.groups;
  groups[1].region.col = kWidth;  // outside
  EXPECT_THROW(MeasureBarTarget(t.image, groups, t.bright, t.dark), InputError);
  BarTargetOptions bad;
  bad.threshold = 1.5;
  EXPECT_THROW(MeasureBarTarget(t.image, t.groups, t.bright, t.dark, bad), ConfigError);
}

}  // namespace
}  // namespace aerocal::stitch
