// The fast resampling path (stitch/resample/fast_strip.h, bilinear_run.h) against the exact
// positions and a double-precision bilinear resampler written here, and against the reference
// path (ResampleOptions::reference): positions within 1e-4 px, values within 0.5 DN before the
// final rounding, the same coverage, and an output independent of threads and strips.
#include "calib/camera/subimage_mapping.h"
#include "stitch/layout/grid_layout.h"
#include "stitch/resample/bilinear_run.h"
#include "stitch/resample/virtual_image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace aerocal::stitch {
namespace {

using internal::FixedRun;
using internal::SampleWindow;
using internal::ToFixed;

// A window whose samples are slope * column (or * row) with the padding the fast path reads.
std::vector<std::uint16_t> Ramp(int w, int h, double slope_col, double slope_row) {
  std::vector<std::uint16_t> data(static_cast<size_t>(w) * (h + 1) + 2, 0);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      data[static_cast<size_t>(r) * w + c] =
          static_cast<std::uint16_t>(slope_col * c + slope_row * r);
  return data;
}

TEST(BilinearRun, PositionsExactTo1e4PxAlongRunsAtAnyScale) {
  // Bilinear interpolation reproduces a linear ramp exactly, so a sample of the ramp 50 u is the
  // position u actually used, to the float's 0.004 DN / 50 = 1e-4 px.
  const int w = 1200, h = 60;
  const auto cols = Ramp(w, h, 50.0, 0.0), rows = Ramp(w, h, 0.0, 1000.0);
  const SampleWindow<std::uint16_t> col_window{cols.data(), w}, row_window{rows.data(), w};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> start(0.0, 40.0), drift(-2e-3, 2e-3);
  double max_error_u = 0, max_error_v = 0;
  for (double scale : {1.0, 0.999, 1.0004, 0.5, 1.7}) {
    for (int trial = 0; trial < 50; ++trial) {
      const double u0 = start(rng), v0 = start(rng), du = scale + drift(rng) * 0.1, dv = drift(rng);
      const double rows_left = dv >= 0 ? (h - 1 - v0) / std::max(dv, 1e-9) : v0 / -dv;
      const int n = static_cast<int>(std::min((w - 1 - u0) / du, rows_left));
      const FixedRun run{ToFixed(u0), ToFixed(v0), ToFixed(du), ToFixed(dv), std::min(n, 1100)};
      std::vector<float> along_u(run.n, 0.0f), along_v(run.n, 0.0f);
      internal::SampleRunAdd(col_window, run, along_u.data());
      internal::SampleRunAdd(row_window, run, along_v.data());
      for (int k = 0; k < run.n; ++k) {
        max_error_u = std::max(max_error_u, std::abs(along_u[k] / 50.0 - (u0 + k * du)));
        max_error_v = std::max(max_error_v, std::abs(along_v[k] / 1000.0 - (v0 + k * dv)));
      }
    }
  }
  std::printf(
      "largest position error along runs: u %.2e px, v %.2e px\n", max_error_u, max_error_v);
  EXPECT_LT(max_error_u, 1e-4);
  EXPECT_LT(max_error_v, 1e-4);
}

TEST(BilinearRun, VectorBlocksEqualSampleBySampleToTheLastBit) {
  // Noise texture: any difference of weights or taps between the two code paths would show.
  const int w = 700, h = 8;
  std::vector<std::uint16_t> data(static_cast<size_t>(w) * (h + 1) + 2, 0);
  std::mt19937 rng(4);
  for (int i = 0; i < w * h; ++i) data[i] = static_cast<std::uint16_t>(rng());
  const SampleWindow<std::uint16_t> window{data.data(), w};
  for (double dv : {0.0, 3e-4, -5e-3}) {
    const FixedRun run{ToFixed(0.25), ToFixed(3.9), ToFixed(1.00013), ToFixed(dv), 640};
    std::vector<std::uint16_t> stored(run.n);
    std::vector<float> added(run.n, 0.0f);
    internal::SampleRunStore(window, run, stored.data());
    internal::SampleRunAdd(window, run, added.data());
    for (int k = 0; k < run.n; ++k) {
      const float one = internal::SampleAt(window, run.u + k * run.du, run.v + k * run.dv);
      ASSERT_EQ(added[k], one) << k;
      ASSERT_EQ(stored[k], static_cast<std::uint16_t>(one + 0.5f)) << k;
    }
  }
}

// 2 x 3 sub-images with sub-pixel affine misplacements, and sub-image VI projective (a tilt of
// 1e-6 / px: about 0.5 px of perspective across it), over a band-limited 16-bit texture.
calib::Camera MisplacedCamera() {
  GridLayoutOptions layout;
  layout.rows = 2, layout.cols = 3;
  layout.virtual_width_px = 1400, layout.virtual_height_px = 1000;
  layout.overlap_px = 60;
  calib::Camera camera = MakeGridCamera(layout);
  std::mt19937 rng(9);
  std::normal_distribution<double> small(0.0, 1e-4), shift(0.0, 0.4);
  for (int k = 0; k < 5; ++k) {
    auto& s = camera.subimages[k];
    Eigen::Matrix3d h = calib::HomographyFromParams(s.model, s.params.data());
    Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
    a << 1 + small(rng), small(rng), shift(rng), small(rng), 1 + small(rng), shift(rng), 0, 0, 1;
    s.model = calib::MappingModel::kAffine;
    s.params = calib::ParamsFromHomography(s.model, a * h);
  }
  auto& p = camera.subimages[5];
  Eigen::Matrix3d h = calib::HomographyFromParams(p.model, p.params.data());
  Eigen::Matrix3d tilt = Eigen::Matrix3d::Identity();
  tilt(2, 0) = 1e-6, tilt(2, 1) = -0.7e-6, tilt(0, 2) = 0.3;
  p.model = calib::MappingModel::kProjective;
  p.params = calib::ParamsFromHomography(p.model, tilt * h);
  return camera;
}

double Texture(double x, double y) {
  return 30000 + 9000 * std::sin(0.37 * x + 0.11 * y) + 7000 * std::cos(0.05 * x - 0.29 * y) +
         4000 * std::sin(0.8 * y + 0.013 * x * 0.1);
}

std::vector<MemoryRaster> SubImages(const calib::Camera& camera) {
  std::vector<MemoryRaster> subs;
  for (const auto& s : camera.subimages) {
    MemoryRaster sub({s.width_px, s.height_px, 1, 16});
    for (int v = 0; v < s.height_px; ++v)
      for (int u = 0; u < s.width_px; ++u) sub.Set(u, v, 0, Texture(u * 1.3, v * 0.7));
    subs.push_back(std::move(sub));
  }
  return subs;
}

// The double-precision resampler: exact inverse mapping, bilinear in double, plain average.
double ExactValue(
    const calib::Camera& camera, const std::vector<MemoryRaster>& subs, int c, int r, int* n) {
  double sum = 0;
  *n = 0;
  for (size_t k = 0; k < subs.size(); ++k) {
    const auto& s = camera.subimages[k];
    const Eigen::Vector3d p = calib::HomographyFromParams(s.model, s.params.data()).inverse() *
                              Eigen::Vector3d(c, r, 1.0);
    const double u = p.x() / p.z(), v = p.y() / p.z();
    if (!(u >= 0 && u <= s.width_px - 1 && v >= 0 && v <= s.height_px - 1)) continue;
    const int iu = std::min(static_cast<int>(u), s.width_px - 2);
    const int iv = std::min(static_cast<int>(v), s.height_px - 2);
    const double fu = u - iu, fv = v - iv;
    const MemoryRaster& m = subs[k];
    const double top = m.At(iu, iv) + fu * (m.At(iu + 1, iv) - m.At(iu, iv));
    const double bottom = m.At(iu, iv + 1) + fu * (m.At(iu + 1, iv + 1) - m.At(iu, iv + 1));
    sum += top + fv * (bottom - top);
    ++*n;
  }
  return *n ? sum / *n : 0.0;
}

MemoryRaster RunResample(const calib::Camera& camera,
                         std::vector<MemoryRaster>& subs,
                         bool reference,
                         int threads,
                         int strip_rows,
                         ResampleReport* report = nullptr) {
  std::vector<RasterSource*> sources;
  for (auto& s : subs) sources.push_back(&s);
  MemoryRaster out({camera.width_px, camera.height_px, 1, 16});
  ResampleOptions options;
  options.reference = reference;
  options.threads = threads;
  options.strip_rows = strip_rows;
  options.fill = 11;
  const ResampleReport r = ResampleVirtualImage(camera, sources, &out, options);
  if (report) *report = r;
  return out;
}

TEST(FastResample, WithinHalfADnOfADoublePrecisionResamplerAndCoveringAsTheReference) {
  const calib::Camera camera = MisplacedCamera();
  std::vector<MemoryRaster> subs = SubImages(camera);
  ResampleReport fast_report, reference_report;
  const MemoryRaster fast = RunResample(camera, subs, false, 1, 256, &fast_report);
  const MemoryRaster reference = RunResample(camera, subs, true, 1, 256, &reference_report);
  EXPECT_EQ(fast_report.covered, reference_report.covered);
  EXPECT_EQ(fast_report.overlap, reference_report.overlap);
  EXPECT_GT(fast_report.overlap, 100000);
  // Rounded output against the unrounded exact value: the rounding's 0.5 DN plus what the fast
  // path adds: on the affine sub-images the float's 0.004 DN, on the projective one the chord's
  // kChordPx = 1e-5 px times the texture's slope (up to 5000 DN/px): 0.05 DN. The reference path
  // (float positions, 2^-12 px near u = 4000) does worse.
  double max_fast = 0, max_reference = 0, sum_fast = 0;
  long differ = 0, n_pixels = 0;
  for (int r = 0; r < camera.height_px; ++r)
    for (int c = 0; c < camera.width_px; ++c) {
      int n = 0;
      const double exact = ExactValue(camera, subs, c, r, &n);
      if (n == 0) {
        ASSERT_EQ(fast.At(c, r), 11) << c << " " << r;
        continue;
      }
      max_fast = std::max(max_fast, std::abs(fast.At(c, r) - exact));
      max_reference = std::max(max_reference, std::abs(reference.At(c, r) - exact));
      sum_fast += std::abs(fast.At(c, r) - exact);
      differ += fast.At(c, r) != reference.At(c, r);
      ++n_pixels;
    }
  std::printf(
      "against exact double bilinear: fast max %.3f DN mean %.3f DN, reference max %.3f DN; "
      "%ld of %ld px differ from the reference by 1 DN\n",
      max_fast,
      sum_fast / n_pixels,
      max_reference,
      differ,
      n_pixels);
  EXPECT_LT(max_fast, 0.5 + 0.05);
  EXPECT_LE(max_fast, max_reference);
  EXPECT_LT(sum_fast / n_pixels, 0.26);
}

TEST(FastResample, BitIdenticalWhateverTheThreadsAndStrips) {
  const calib::Camera camera = MisplacedCamera();
  std::vector<MemoryRaster> subs = SubImages(camera);
  const MemoryRaster one = RunResample(camera, subs, false, 1, 256);
  EXPECT_EQ(one.bytes(), RunResample(camera, subs, false, 2, 256).bytes());
  EXPECT_EQ(one.bytes(), RunResample(camera, subs, false, 0, 17).bytes());
  EXPECT_EQ(one.bytes(), RunResample(camera, subs, false, 2, 1000).bytes());
}

// A correction grid of every sub-image: a smooth field of up to 0.8 px on 64 px nodes.
std::vector<MapCorrectionGrid> SmoothCorrections(const calib::Camera& camera) {
  MapCorrectionGrid g;
  g.step_px = 64;
  g.cols = (camera.width_px - 2) / g.step_px + 2;
  g.rows = (camera.height_px - 2) / g.step_px + 2;
  for (int j = 0; j < g.rows; ++j)
    for (int i = 0; i < g.cols; ++i) {
      g.duv.push_back(static_cast<float>(0.8 * std::sin(0.3 * i + 0.1 * j)));
      g.duv.push_back(static_cast<float>(0.6 * std::cos(0.2 * j - 0.15 * i)));
    }
  g.max_abs_px = 0.8f;
  return std::vector<MapCorrectionGrid>(camera.subimages.size(), g);
}

// A region of the virtual image (ResampleOptions::region) holds the whole format's pixels to the
// last bit, on every path: fast, reference (bilinear and bicubic) and with correction grids; the
// regions start inside strips (strip_rows 100), end at the format's corner, or are one row. The
// coverage output is 255 exactly where a constant 8-bit image of 255 through the same maps gets
// a value above the fill 0, and 0 elsewhere.
TEST(FastResample, ARegionHoldsTheWholeFormatsPixelsBitForBit) {
  const calib::Camera camera = MisplacedCamera();
  std::vector<MemoryRaster> subs = SubImages(camera);
  std::vector<RasterSource*> sources;
  for (auto& sub : subs) sources.push_back(&sub);
  const std::vector<MapCorrectionGrid> grids = SmoothCorrections(camera);
  struct Path {
    const char* name;
    bool reference;
    Interpolation interpolation;
    bool corrected;
  };
  for (const Path& path : {Path{"fast", false, Interpolation::kBilinear, false},
                           Path{"reference", true, Interpolation::kBilinear, false},
                           Path{"bicubic", true, Interpolation::kBicubic, false},
                           Path{"corrected", false, Interpolation::kBilinear, true}}) {
    ResampleOptions options;
    options.reference = path.reference;
    options.interpolation = path.interpolation;
    options.strip_rows = 100;
    options.fill = 11;
    const std::vector<MapCorrectionGrid> corrections =
        path.corrected ? grids : std::vector<MapCorrectionGrid>{};
    MemoryRaster whole({camera.width_px, camera.height_px, 1, 16});
    MemoryRaster coverage({camera.width_px, camera.height_px, 1, 8});
    const ResampleReport all =
        ResampleVirtualImage(camera, sources, &whole, options, corrections, &coverage);
    EXPECT_GT(all.overlap, 50000) << path.name;
    std::vector<MemoryRaster> ones;
    for (const auto& s : camera.subimages) {
      ones.emplace_back(RasterInfo{s.width_px, s.height_px, 1, 8});
      std::fill(ones.back().bytes().begin(), ones.back().bytes().end(), 255);
    }
    std::vector<RasterSource*> one_sources;
    for (auto& o : ones) one_sources.push_back(&o);
    ResampleOptions constant = options;
    constant.fill = 0;
    MemoryRaster constant_out({camera.width_px, camera.height_px, 1, 8});
    ResampleVirtualImage(camera, one_sources, &constant_out, constant, corrections);
    long wrong = 0, covered = 0;
    for (size_t i = 0; i < coverage.bytes().size(); ++i) {
      const std::uint8_t c = coverage.bytes()[i];
      wrong += (c != 0 && c != 255) || (c == 255) != (constant_out.bytes()[i] > 127);
      covered += c == 255;
    }
    EXPECT_EQ(wrong, 0) << path.name;
    EXPECT_EQ(covered, all.covered) << path.name;
    for (const VirtualRegion& region : {VirtualRegion{123, 257, 700, 301},
                                        VirtualRegion{1390, 990, 10, 10},
                                        VirtualRegion{0, 999, 1400, 1},
                                        VirtualRegion{455, 0, 1, 1000}}) {
      options.region = region;
      MemoryRaster part({region.width, region.height, 1, 16});
      ResampleVirtualImage(camera, sources, &part, options, corrections);
      long differ = 0;
      for (int r = 0; r < region.height; ++r)
        for (int c = 0; c < region.width; ++c)
          differ += part.At(c, r) != whole.At(region.x0 + c, region.y0 + r);
      EXPECT_EQ(differ, 0) << path.name << " region at " << region.x0 << " " << region.y0;
    }
  }
}

}  // namespace
}  // namespace aerocal::stitch
