// Resampling sub-images into the virtual image (virtual_image.h): analytic cases and the real
// aerial photograph cut into misplaced sub-images and resampled back.
#include "stitch/resample/virtual_image.h"

#include "stitch/layout/grid_layout.h"
#include "stitch/resample/tiff_raster.h"
#include "stitch/simulation/stitch_simulator.h"
#include "tests/support/cubic_sample.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace aerocal::stitch {
namespace {

using testing::SampleCubic;

// Sub-images of `truth` cut from `frame`: pixel (u, v) takes the frame at VirtualFromSub(u, v).
std::vector<MemoryRaster> Cut(const MemoryRaster& frame, const calib::Camera& truth) {
  std::vector<MemoryRaster> out;
  const RasterInfo info = frame.Info();
  for (const auto& s : truth.subimages) {
    MemoryRaster sub({s.width_px, s.height_px, info.bands, info.bits});
    for (int v = 0; v < s.height_px; ++v)
      for (int u = 0; u < s.width_px; ++u) {
        const Eigen::Vector2d p = s.VirtualFromSub({u, v});
        for (int b = 0; b < info.bands; ++b) sub.Set(u, v, b, SampleCubic(frame, p.x(), p.y(), b));
      }
    out.push_back(std::move(sub));
  }
  return out;
}

std::vector<RasterSource*> Pointers(std::vector<MemoryRaster>& rasters) {
  std::vector<RasterSource*> out;
  for (auto& r : rasters) out.push_back(&r);
  return out;
}

calib::Camera TwoByThree(int width, int height, int overlap) {
  GridLayoutOptions layout;
  layout.rows = 2;
  layout.cols = 3;
  layout.virtual_width_px = width;
  layout.virtual_height_px = height;
  layout.overlap_px = overlap;
  return MakeGridCamera(layout);
}

TEST(ResampleVirtualImage, ReproducesALinearRampExactlyAndFillsUncoveredPixels) {
  // A ramp is reproduced exactly by bilinear and (away from the edges) bicubic interpolation.
  calib::Camera camera = TwoByThree(300, 200, 20);
  camera.subimages[5].params[2] += 0.37;  // shift VI by a fraction of a pixel
  camera.subimages[5].params[5] -= 0.21;
  MemoryRaster frame({300, 200, 3, 16});
  for (int r = 0; r < 200; ++r)
    for (int c = 0; c < 300; ++c)
      for (int b = 0; b < 3; ++b) frame.Set(c, r, b, 1000 + 50.0 * c + 20.0 * r + 7000 * b);
  for (Interpolation interpolation : {Interpolation::kBilinear, Interpolation::kBicubic}) {
    // Sub-image samples of the ramp at the exact mapped positions.
    std::vector<MemoryRaster> subs;
    for (const auto& s : camera.subimages) {
      MemoryRaster sub({s.width_px, s.height_px, 3, 16});
      for (int v = 0; v < s.height_px; ++v)
        for (int u = 0; u < s.width_px; ++u) {
          const Eigen::Vector2d p = s.VirtualFromSub({u, v});
          for (int b = 0; b < 3; ++b)
            sub.Set(u, v, b, 1000 + 50.0 * p.x() + 20.0 * p.y() + 7000 * b);
        }
      subs.push_back(std::move(sub));
    }
    MemoryRaster out({300, 200, 3, 16});
    ResampleOptions options;
    options.interpolation = interpolation;
    options.fill = 7;
    options.strip_rows = 37;  // strips that do not divide the height
    const ResampleReport report = ResampleVirtualImage(camera, Pointers(subs), &out, options);
    EXPECT_GT(report.overlap, 0);
    double max_error = 0;
    long uncovered = 0;
    for (int r = 0; r < 200; ++r)
      for (int c = 0; c < 300; ++c) {
        // VI moved by (+0.37, -0.21): its last row no longer reaches the bottom edge.
        bool covered = false, near_edge = false;
        for (const auto& s : camera.subimages) {
          const Eigen::Vector2d uv = s.SubFromVirtual({c, r});
          covered = covered || s.Contains(uv);
          near_edge = near_edge || (s.Contains(uv) && !s.Contains(uv, -1.0));
        }
        if (!covered) {
          ++uncovered;
          EXPECT_EQ(out.At(c, r, 0), 7) << c << " " << r;
          continue;
        }
        // Bicubic repeats edge samples: within 1 px of a sub-image edge a ramp is not reproduced.
        if (near_edge && interpolation == Interpolation::kBicubic) continue;
        for (int b = 0; b < 3; ++b)
          max_error = std::max(max_error,
                               std::abs(out.At(c, r, b) - (1000 + 50.0 * c + 20.0 * r + 7000 * b)));
      }
    EXPECT_EQ(uncovered, report.filled);
    EXPECT_GT(uncovered, 80);   // the bottom row right of V
    EXPECT_LE(max_error, 1.0);  // rounding to integers (ramp values are not integers everywhere)
  }
}

TEST(ResampleVirtualImage, RealAerialImageResampledBackWithoutSeams) {
  const std::string dir = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const std::string path = dir + "/images/img_4880.jpg";
  const MemoryRaster full = ReadImageFile(path, /*gray=*/true);
  // A 1600 x 1200 px window of the photograph keeps the test fast (full resolution, no blur).
  const int width = 1600, height = 1200;
  const int x_off = (full.Info().width - width) / 2, y_off = (full.Info().height - height) / 2;
  MemoryRaster original({width, height, 1, 8});
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) original.Set(c, r, 0, full.At(c + x_off, r + y_off));

  // Sub-pixel affine misplacements of every CCD (shift 0.4 px, rotation/scale/shear 1e-4).
  const calib::Camera nominal = TwoByThree(width, height, 100);
  MisplacementOptions misplacement;
  misplacement.shift_sigma_px = 0.4;
  misplacement.shear = 1e-4;
  std::mt19937_64 rng(5);
  const calib::Camera truth = MakeMisplacedCamera(nominal, {}, misplacement, rng);
  std::vector<MemoryRaster> subs = Cut(original, truth);

  testing::TempDir tmp;
  MemoryRaster back({width, height, 1, 8});
  const ResampleReport report = ResampleVirtualImage(truth, Pointers(subs), &back, {});
  // Interior: 4 px from the border (misplaced CCDs need not reach the very edge).
  double sum2 = 0, overlap_sum = 0, single_sum = 0, overlap2 = 0, single2 = 0, edge_sum = 0,
         edge2 = 0;
  long n = 0, n_overlap = 0, n_single = 0, n_edge = 0;
  for (int r = 4; r < height - 4; ++r)
    for (int c = 4; c < width - 4; ++c) {
      const double d = back.At(c, r) - original.At(c, r);
      sum2 += d * d;
      ++n;
      int cover = 0;
      bool edge = false;  // within 1.5 px of a sub-image's edge: where a seam would show
      for (const auto& s : truth.subimages) {
        const Eigen::Vector2d uv = s.SubFromVirtual({c, r});
        cover += s.Contains(uv);
        edge = edge || (s.Contains(uv) && !s.Contains(uv, -1.5));
      }
      if (edge) {
        edge_sum += d;
        edge2 += d * d;
        ++n_edge;
      }
      (cover > 1 ? overlap_sum : single_sum) += d;
      (cover > 1 ? overlap2 : single2) += d * d;
      (cover > 1 ? n_overlap : n_single)++;
    }
  const double rms = std::sqrt(sum2 / n);
  const double rms_overlap = std::sqrt(overlap2 / n_overlap),
               rms_single = std::sqrt(single2 / n_single);
  std::printf(
      "real image %d x %d: RMS %.3f DN (overlaps %.3f, single coverage %.3f); mean "
      "difference overlaps %.3f, single %.3f; %ld overlap px\n",
      width,
      height,
      rms,
      rms_overlap,
      rms_single,
      overlap_sum / n_overlap,
      single_sum / n_single,
      report.overlap);
  EXPECT_LT(rms, 1.0);
  // No seam: the overlaps (averages of two or four sub-images) are no worse than single coverage
  // and carry no grey-level step.
  EXPECT_LT(rms_overlap, rms_single * 1.1);
  EXPECT_LT(std::abs(overlap_sum / n_overlap - single_sum / n_single), 0.1);
  // Nor along the CCD edges themselves, where one sub-image starts or stops contributing.
  const double rms_edge = std::sqrt(edge2 / n_edge);
  std::printf("along the sub-image edges (1.5 px band, %ld px): RMS %.3f DN, mean %.3f DN\n",
              n_edge,
              rms_edge,
              edge_sum / n_edge);
  ASSERT_GT(n_edge, 5000);
  EXPECT_LT(rms_edge, rms_single * 1.1);
  EXPECT_LT(std::abs(edge_sum / n_edge - single_sum / n_single), 0.1);
}

}  // namespace
}  // namespace aerocal::stitch
